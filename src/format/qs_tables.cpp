// The parts of QSplat's quantization only the .qs files use (Rusinkiewicz & Levoy, SIGGRAPH
// 2000; ../shared/specs/qsplat-qs-format.md §4.3, §6, §8.6): QSplat 1.0's own sphere and cone
// encoders and glibc's rand() for its normal dither. The tables are in lod/quantization.hpp.
#include "qs_tables.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace pointillist::qs_detail {
namespace {

// Floor of a finite or non-finite float, clamped to [lo, hi] (NaN gives lo).
int clamped_floor(float f, int lo, int hi) {
  f = std::floor(f);
  if (!(f >= float(lo))) return lo;
  if (f > float(hi)) return hi;
  return int(f);
}

int clamped_ceil(float f, int lo, int hi) {
  f = std::ceil(f);
  if (!(f >= float(lo))) return lo;
  if (f > float(hi)) return hi;
  return int(f);
}

}  // namespace

int encode_sphere(Vec3f p, float rho, Vec3f c, float r) {
  const float s = r / rho;
  int lo[3], hi[3];
  int m = 1;
  for (int a = 0; a < 3; ++a) {
    const float t = 0.5f * ((c[a] - p[a]) / rho + 1.0f);  // parent cube mapped to [0, 1]
    // Outward rounding: the cube [lo, hi] covers the child's extent on this axis.
    lo[a] = clamped_floor((t - s * 0.5f) * float(kSphereGrid), 0, kSphereGrid - 1);
    hi[a] = clamped_ceil((t + s * 0.5f) * float(kSphereGrid), 1, kSphereGrid);
    m = std::max(m, hi[a] - lo[a]);
  }
  // The three extents differ by at most one cell; widen the narrower ones, downwards if possible.
  for (int a = 0; a < 3; ++a) {
    if (hi[a] - lo[a] < m) {
      if (lo[a] > 0) {
        --lo[a];
      } else {
        ++hi[a];
      }
    }
  }
  // The cube is looked up as it is, not moved or grown into the table: QSplat 1.0 writes the
  // out-of-table code for a cube that sticks out of the grid or that the table skips.
  const int code = sphere_code(m, lo[0], lo[1], lo[2]);
  return code >= 0 ? code : int(kOutOfTableSphereCode);
}

std::uint32_t encode_cone(float theta) {
  // sin θ falls again past 90°; 1.5 rad is QSplat 1.0's cut-off for "no bound".
  const float s = theta > 1.5f ? 0.999f : std::sin(theta);
  return std::uint32_t(clamped_floor(4.0f * std::sqrt(s), 0, 3));
}

GlibcRandom::GlibcRandom(std::uint32_t seed) {
  // glibc srandom_r: r[0] = seed, r[i] = 16807 r[i-1] mod (2^31 - 1) (signed arithmetic, as
  // Schrage's method), r[31..33] = r[0..2], then 310 values are discarded.
  std::array<std::int32_t, 34> r{};
  r[0] = static_cast<std::int32_t>(seed == 0 ? 1 : seed);
  for (int i = 1; i < 31; ++i) {
    const std::int64_t hi = r[i - 1] / 127773, lo = r[i - 1] % 127773;
    const std::int64_t word = 16807 * lo - 2836 * hi;
    r[i] = static_cast<std::int32_t>(word < 0 ? word + 2147483647 : word);
  }
  for (int i = 31; i < 34; ++i) r[i] = r[i - 31];
  for (int i = 0; i < 34; ++i) r_[i] = static_cast<std::uint32_t>(r[i]);
  i_ = 0;  // n = 34
  for (int i = 34; i < 344; ++i) next();
}

}  // namespace pointillist::qs_detail
