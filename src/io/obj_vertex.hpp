// OBJ `v`, `vn` and `f` lines, as the whole reader (obj_reader.cpp) and the streams
// (obj_stream.cpp) both parse them (private to io).
#pragma once

#include <array>
#include <cstdint>
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

// The 3 numbers of a `vn` line after its keyword, [p, le); anything else calls fail.
template <class Fail>
void parse_obj_normal(const char* p, const char* le, float (&values)[3], Fail&& fail) {
  for (int c = 0; c < 3; ++c) {
    p = skip_blanks(p, le);
    const char* q = p < le ? parse_real(p, le, values[c]) : nullptr;
    if (!q) {
      fail(p, "vn: value " + std::to_string(c + 1) + ": expected a number, found " +
                  quote_token(p, le) + " (vn lines hold 3 numbers)");
    }
    p = q;
  }
  p = skip_blanks(p, le);
  if (p < le) fail(p, "vn: extra value " + quote_token(p, le) + " (vn lines hold 3 numbers)");
}

// One corner of an `f` line: v, v/vt, v//vn or v/vt/vn, the indices as the file gives them
// (1-based; negative ones count back).
struct ObjCorner {
  std::int64_t v = 0, vn = 0;
  bool has_vn = false;
  const char* token = nullptr;
};

// The corner at the next token of [p, le) (`number`: its 1-based place, for messages); returns
// the position after it, or nullptr when the line has no more corners.
template <class Fail>
const char* parse_obj_corner(const char* p, const char* le, std::int64_t number, ObjCorner& c,
                             Fail&& fail) {
  p = skip_blanks(p, le);
  if (p == le) return nullptr;
  c = ObjCorner{};
  c.token = p;
  std::int64_t vt = 0;
  p = parse_index(p, le, c.v);
  if (p && p < le && *p == '/') {
    ++p;
    if (p < le && *p != '/') p = parse_index(p, le, vt);  // texture index: unused
    if (p && p < le && *p == '/') {
      c.has_vn = true;
      p = parse_index(p + 1, le, c.vn);
    }
  }
  if (!p || (p < le && !is_blank(*p))) {
    fail(c.token, "f: corner " + std::to_string(number) +
                      ": expected v, v/vt, v//vn or v/vt/vn with integer indices, found " +
                      quote_token(c.token, le));
  }
  return p;
}

// The largest index seen before what it refers to was defined, and where.
struct ForwardReference {
  std::int64_t index = 0;  // 1-based, as in the file
  const char* token = nullptr;
};

// A corner's 0-based index. A positive index past what is defined so far refers forward: the
// caller checks it at the end (`forward` keeps the largest).
template <class Fail>
std::int64_t resolve_obj_index(std::int64_t index, std::uint64_t defined, const char* token,
                               const char* what, ForwardReference& forward, Fail&& fail) {
  constexpr std::int64_t kMax = 0xffffffffLL;
  if (index == 0) {
    fail(token, std::string("f: ") + what + " index 0 (OBJ indices start at 1; negative ones " +
                    "count back from the last " + what + ")");
  }
  if (index < 0) {
    const std::int64_t resolved = static_cast<std::int64_t>(defined) + index;
    if (resolved < 0) {
      fail(token, std::string("f: relative ") + what + " index " + std::to_string(index) +
                      " points before the first " + what + " (" + std::to_string(defined) +
                      " defined so far)");
    }
    return resolved;
  }
  if (index > kMax) {
    fail(token, std::string("f: ") + what + " index " + std::to_string(index) +
                    " is larger than 2^32 - 1");
  }
  if (static_cast<std::uint64_t>(index) > defined && index > forward.index) {
    forward = {index, token};
  }
  return index - 1;
}

}  // namespace pointillist::io_detail
