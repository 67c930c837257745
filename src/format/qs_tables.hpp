// Code tables of the QSplat .qs 1.1 format (spec ../shared/specs/qsplat-qs-format.md §4-7),
// generated in code, and glibc's rand() for the normal dither. Private to the format module.
#pragma once

#include <array>
#include <cstdint>
#include <span>

#include "pointillist/core/math.hpp"

namespace pointillist::qs_detail {

// ---- 13-bit sphere codes (spec §4) ----

constexpr int kSphereGrid = 13;
constexpr std::uint32_t kSphereCodeCount = 7621;

// Candidate sphere in parent units: centre offset (x, y, z) and radius r.
struct SphereCandidate {
  float x = 0, y = 0, z = 0, r = 0;
};

// The 7621 candidates, indexed by code: m (cube size in cells, 1..13) outermost, then the low
// cell x, y, z; cubes whose circumsphere misses the unit ball are skipped (spec §4.1).
std::span<const SphereCandidate, kSphereCodeCount> sphere_table();

// Code of the cube of m cells with low cell (x, y, z), or -1 when that cube is not in the table
// (out of range or skipped).
int sphere_code(int m, int x, int y, int z);

// Decoded sphere of `code` (< kSphereCodeCount) relative to the decoded parent sphere (spec
// §4.2): float32, each component multiplied then added, so every reader and writer of a format
// built on these codes (.qs, .ptl version 2) computes the same bits.
inline Sphere decode_sphere(const Sphere& parent, std::uint32_t code) {
  const SphereCandidate& s = sphere_table()[code];
  return {{parent.center.x + parent.radius * s.x, parent.center.y + parent.radius * s.y,
           parent.center.z + parent.radius * s.z},
          parent.radius * s.r};
}

// Code for a child sphere (centre c, radius r) quantized against its decoded parent (centre p,
// radius rho) the way QSplat 1.0 does (spec §4.3). Where QSplat 1.0 would pick a cube that is not
// in the table (and write the invalid code 8191), the cube is grown until it is.
int encode_sphere(Vec3f p, float rho, Vec3f c, float r);

// ---- 14-bit normal codes (spec §5) ----

constexpr int kNormalGrid = 52;
constexpr std::uint32_t kNormalCodeCount = 6 * kNormalGrid * kNormalGrid;  // 16224

// Unit normals of all codes 0..16223 (grid corners that are not on the sphere, never written,
// clamped onto it). Codes >= 16224 mean (0, 0, 1) in QSplat 1.0.
std::span<const Vec3f, kNormalCodeCount> normal_table();

// Code of a unit normal (the cube-face grid on atan of the components, spec §5.2; no dither).
std::uint32_t encode_normal(Vec3f n);

// ---- 2-bit normal cone codes (spec §6) ----

// Code of a cone half-angle theta (radians, >= 0).
std::uint32_t encode_cone(float theta);
// Upper bound on sin θ that code k (0..2) promises: ((k + 1)/4)². Code 3 means "no bound".
constexpr float cone_sin_bound(std::uint32_t k) {
  return float((k + 1) * (k + 1)) / 16.0f;
}

// ---- RGB 565 (spec §7) ----

constexpr std::uint16_t encode_rgb565(Rgb8 c) {
  return static_cast<std::uint16_t>((c.r >> 3) << 11 | (c.g >> 2) << 5 | (c.b >> 3));
}
constexpr Rgb8 decode_rgb565(std::uint16_t w) {
  const unsigned r5 = w >> 11, g6 = (w >> 5) & 63, b5 = w & 31;
  return {static_cast<std::uint8_t>(r5 << 3 | r5 >> 2),
          static_cast<std::uint8_t>(g6 << 2 | g6 >> 4),
          static_cast<std::uint8_t>(b5 << 3 | b5 >> 2)};
}

// ---- glibc rand() (TYPE_3 additive feedback generator), for byte-identical dithering ----

class GlibcRandom {
 public:
  static constexpr std::int32_t kMax = 2147483647;  // RAND_MAX

  // Same sequence as glibc's srand(seed) followed by rand() calls; seed 0 acts as 1.
  explicit GlibcRandom(std::uint32_t seed = 1);
  std::int32_t next() {
    const std::uint32_t v = r_[(i_ + 3) % 34] + r_[(i_ + 31) % 34];  // r[n-31] + r[n-3]
    r_[i_] = v;
    i_ = (i_ + 1) % 34;
    return static_cast<std::int32_t>(v >> 1);
  }

 private:
  // Ring of the last 34 values r[n-34..n-1] of the recurrence, r[k] at k mod 34; i_ = n mod 34.
  std::array<std::uint32_t, 34> r_{};
  unsigned i_ = 0;
};

}  // namespace pointillist::qs_detail
