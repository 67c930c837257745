// The .qs-only parts of QSplat's quantization (spec ../shared/specs/qsplat-qs-format.md §4.3,
// §6, §8.6): QSplat 1.0's sphere and cone encoders and glibc's rand() for the normal dither. The
// code tables themselves are in lod/quantization.hpp, visible here too. Private to the format
// module.
#pragma once

#include <array>
#include <cstdint>

#include "pointillist/core/math.hpp"
#include "pointillist/lod/quantization.hpp"

namespace pointillist::qs_detail {

using namespace pointillist::quant;  // NOLINT(google-build-using-namespace): one vocabulary

// The sphere code QSplat 1.0 writes when the cube it picked is not in the table (spec §4.3): the
// low 13 bits of its lookup table's "no entry" value 0xFFFF. Its viewer takes the candidate from
// the zero-filled memory past the table's end, so the code decodes to the parent's centre with
// radius 0 (spec §4.1).
constexpr std::uint32_t kOutOfTableSphereCode = 8191;

// Code for a child sphere (centre c, radius r) quantized against its decoded parent (centre p,
// radius rho) the way QSplat 1.0 does (spec §4.3), kOutOfTableSphereCode included: a child that
// sticks out of its decoded parent can land in a corner cube the table skips (two leaves of the
// twice-subdivided Stanford dragon do).
int encode_sphere(Vec3f p, float rho, Vec3f c, float r);

// Decoded sphere of a .qs sphere code (< kSphereCodeCount, or kOutOfTableSphereCode) against the
// decoded parent, as QSplat 1.0 decodes it.
inline Sphere decode_qs_sphere(const Sphere& parent, std::uint32_t code) {
  return code == kOutOfTableSphereCode ? Sphere{parent.center, 0.0f}
                                       : decode_sphere(parent, code);
}

// Code of a cone half-angle theta (radians, >= 0), as QSplat 1.0 writes it.
std::uint32_t encode_cone(float theta);

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
