// One OBJ `v` line, as the whole reader (obj_reader.cpp) and the stream (obj_stream.cpp) both
// parse it (private to io).
#pragma once

#include <array>
#include <cmath>
#include <string>

#include "text_numbers.hpp"

namespace pointillist::io_detail {

// The numbers of a `v` line after its keyword, [p, le): 3 (x y z), 4 (x y z w) or 6
// (x y z r g b); returns how many. Anything else calls fail(position, message), which must
// throw.
template <class Fail>
int parse_obj_vertex(const char* p, const char* le, double (&values)[7], Fail&& fail) {
  int count = 0;
  const char* first_token = nullptr;
  const auto fail_count = [&](const char* pos, int found) {
    fail(pos, "v: expected 3, 4 or 6 numbers (x y z, x y z w, or x y z r g b), found " +
                  std::to_string(found) + (found > 7 ? " or more" : ""));
  };
  for (;;) {
    p = skip_blanks(p, le);
    if (p == le) break;
    if (count == 7) fail_count(first_token, count + 1);
    const char* q = parse_real(p, le, values[count]);
    if (!q) {
      fail(p, "v: value " + std::to_string(count + 1) + ": expected a number, found " +
                  quote_token(p, le));
    }
    if (count < 3 && !std::isfinite(values[count])) {
      fail(p, "v: coordinate " + std::to_string(count + 1) + " is not a finite number (found " +
                  quote_token(p, le) + ")");
    }
    if (!first_token) first_token = p;
    ++count;
    p = q;
  }
  if (count != 3 && count != 4 && count != 6) fail_count(first_token ? first_token : p, count);
  return count;
}

// Fails (as parse_obj_vertex) when the vertex lies too far from `origin` for a float.
template <class Fail>
void check_obj_vertex_fits(const double (&values)[7], const std::array<double, 3>& origin,
                           const char* pos, Fail&& fail) {
  if (const int a = axis_beyond_float(values, origin); a >= 0) {
    fail(pos, "v: coordinate " + std::to_string(a + 1) +
                  " is too far from the other vertices for a float (more than 3.4e38 from " +
                  short_number(origin[a]) + "); remove the stray vertex");
  }
}

}  // namespace pointillist::io_detail
