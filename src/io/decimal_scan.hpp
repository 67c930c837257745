// Shared pieces of the text readers (PLY ascii, XYZ/CSV, OBJ): the fast scan of a plain decimal
// token, and the clean-up of normals read from a file.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "pointillist/core/math.hpp"

namespace pointillist::io_detail {

inline bool is_digit(char c) { return static_cast<unsigned char>(c - '0') < 10; }

// "-12.345e-6" as mantissa 12345, exponent -9.
struct Decimal {
  std::uint64_t mantissa = 0;
  int exponent = 0;
  bool negative = false;
};

// Scans the decimal token at `p` into `d`. Returns the first character after it, or null unless
// the mantissa has at most 19 digits, the exponent at most 4, and `ends_at(q, end)` accepts the
// character after the token (each format has its own token ends).
template <class EndsAt>
const char* scan_decimal(const char* p, const char* end, Decimal& d, EndsAt ends_at) {
  if (p < end && (*p == '-' || *p == '+')) d.negative = *p++ == '-';
  const char* digits = p;
  std::uint64_t m = 0;
  while (p < end && is_digit(*p)) m = m * 10 + static_cast<unsigned>(*p++ - '0');
  std::ptrdiff_t count = p - digits;
  if (p < end && *p == '.') {
    const char* fraction = ++p;
    while (p < end && is_digit(*p)) m = m * 10 + static_cast<unsigned>(*p++ - '0');
    d.exponent = -static_cast<int>(p - fraction);
    count += p - fraction;
  }
  if (count == 0 || count > 19) return nullptr;
  if (p < end && (*p == 'e' || *p == 'E')) {
    ++p;
    bool negative_exponent = false;
    if (p < end && (*p == '-' || *p == '+')) negative_exponent = *p++ == '-';
    const char* exponent_digits = p;
    int e = 0;
    while (p < end && is_digit(*p) && p - exponent_digits < 4) e = e * 10 + (*p++ - '0');
    if (p == exponent_digits) return nullptr;
    d.exponent += negative_exponent ? -e : e;
  }
  if (!ends_at(p, end)) return nullptr;
  d.mantissa = m;
  return p;
}

// Scans an optionally signed decimal integer of at most 18 digits at `p` into `out`. Returns the
// first character after it, or null when there are no digits, too many, or `ends_at(q, end)`
// rejects the character after them.
template <class EndsAt>
const char* scan_integer(const char* p, const char* end, std::int64_t& out, EndsAt ends_at) {
  bool negative = false;
  if (p < end && (*p == '-' || *p == '+')) negative = *p++ == '-';
  const char* digits = p;
  std::int64_t v = 0;
  while (p < end && is_digit(*p) && p - digits < 18) v = v * 10 + (*p++ - '0');
  if (p == digits || !ends_at(p, end)) return nullptr;
  out = negative ? -v : v;
  return p;
}

// Unit normals as finish_normals leaves them, a window of a streamed file at a time: a zero or
// non-finite normal becomes (0, 0, 1). Returns whether any was usable. (The readers drop the
// normals of a file where none is usable; a streamed file's caller asks
// PointStream::saw_usable_normals() after its first pass for the same rule.)
inline bool normalize_normals_window(std::vector<Vec3f>& normals) {
  bool any = false;
  for (Vec3f& n : normals) {
    const float length2 = dot(n, n);
    if (length2 > 0.99999f && length2 < 1.00001f) {
      any = true;
    } else if (length2 > 0.0f && std::isfinite(length2)) {
      n = n / std::sqrt(length2);
      any = true;
    } else {
      n = {0, 0, 1};
    }
  }
  return any;
}

// Normalizes in place; a zero or non-finite normal becomes (0, 0, 1). When no normal is usable
// the file had none in substance, and the array is dropped.
inline void finish_normals(std::vector<Vec3f>& normals) {
  if (!normalize_normals_window(normals)) {
    normals.clear();
    normals.shrink_to_fit();
  }
}

}  // namespace pointillist::io_detail
