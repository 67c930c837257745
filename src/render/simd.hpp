// Four-lane float and int vectors (GCC vector extensions: SSE2 on x86-64, NEON on ARM, plain
// scalar code elsewhere) for the renderer's hot loops.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace pointillist::render_detail {

using Float4 = float __attribute__((vector_size(16)));
using Int4 = std::int32_t __attribute__((vector_size(16)));
constexpr int kLanes = 4;

inline Float4 splat4(float v) { return Float4{v, v, v, v}; }
inline Float4 load4(const float* p) {
  Float4 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline Int4 load4(const std::uint32_t* p) {
  Int4 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline Int4 load4(const std::int32_t* p) {
  Int4 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline void store4(float* p, Float4 v) { std::memcpy(p, &v, sizeof v); }
inline void store4(std::int32_t* p, Int4 v) { std::memcpy(p, &v, sizeof v); }
inline void store4(std::uint32_t* p, Int4 v) { std::memcpy(p, &v, sizeof v); }
inline Int4 select4(Int4 mask, Int4 a, Int4 b) { return (mask & a) | (~mask & b); }
inline Float4 select4(Int4 mask, Float4 a, Float4 b) {
  return reinterpret_cast<Float4>(
      select4(mask, reinterpret_cast<Int4>(a), reinterpret_cast<Int4>(b)));
}
// max(lo, v) and min(hi, v) lane by lane; a NaN lane gives lo (hi).
inline Float4 max4(Float4 lo, Float4 v) { return select4(lo < v, v, lo); }
inline Float4 min4(Float4 hi, Float4 v) { return select4(v < hi, v, hi); }
inline Float4 sqrt4(Float4 v) {
#if defined(__SSE2__)
  return reinterpret_cast<Float4>(_mm_sqrt_ps(reinterpret_cast<__m128>(v)));
#else
  return Float4{std::sqrt(v[0]), std::sqrt(v[1]), std::sqrt(v[2]), std::sqrt(v[3])};
#endif
}
// Truncation toward zero (the lanes must be within the int range).
// Lanes set in a mask (each -1 or 0).
inline std::uint64_t lane_count(Int4 m) {
  return static_cast<std::uint64_t>(-(m[0] + m[1] + m[2] + m[3]));
}
inline Int4 to_int4(Float4 v) { return __builtin_convertvector(v, Int4); }
inline Float4 to_float4(Int4 v) { return __builtin_convertvector(v, Float4); }

}  // namespace pointillist::render_detail
