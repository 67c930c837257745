// QSplat's code tables (Rusinkiewicz & Levoy, SIGGRAPH 2000), generated as
// ../shared/specs/qsplat-qs-format.md §4.1 and §5.1 describe. The float32 expressions follow the
// spec's order of operations exactly: the .qs writer must reproduce QSplat 1.0's bits (§8.6).
#include "pointillist/lod/quantization.hpp"

#include "pointillist/core/float_order.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

namespace pointillist::quant {
namespace {

struct SphereTables {
  std::array<SphereCandidate, kSphereCodeCount> entries;
  // code[((m * 13 + x) * 13 + y) * 13 + z], -1 where the cube is not in the table.
  std::vector<std::int16_t> code;
};

SphereTables make_sphere_tables() {
  SphereTables t;
  t.code.assign(std::size_t{14} * 13 * 13 * 13, -1);
  // The table is float32 throughout (1/13 as a float32 constant): it matches QSplat 1.0's bit
  // for bit, which the writer needs because it encodes children against decoded parents.
  const float c = 1.0f / 13.0f;
  const double sqrt3 = std::numbers::sqrt3;
  std::uint32_t next = 0;
  for (int m = 1; m <= kSphereGrid; ++m) {
    for (int x = 0; x <= kSphereGrid - m; ++x) {
      for (int y = 0; y <= kSphereGrid - m; ++y) {
        for (int z = 0; z <= kSphereGrid - m; ++z) {
          SphereCandidate s;
          s.x = float(m + 2 * x) * c - 1.0f;
          s.y = float(m + 2 * y) * c - 1.0f;
          s.z = float(m + 2 * z) * c - 1.0f;
          s.r = float(m) * c;
          // Keep cubes whose circumscribed sphere (radius √3·R) reaches the unit ball; no
          // candidate is within 1e-4 of this boundary, so double or float decide alike.
          const double d2 = double(s.x) * s.x + double(s.y) * s.y + double(s.z) * s.z;
          const double reach = 1.0 + sqrt3 * s.r;
          if (d2 > reach * reach) continue;
          t.entries[next] = s;
          t.code[((std::size_t(m) * 13 + x) * 13 + y) * 13 + z] = static_cast<std::int16_t>(next);
          ++next;
        }
      }
    }
  }
  return t;
}

const SphereTables& sphere_tables() {
  static const SphereTables tables = make_sphere_tables();
  return tables;
}

// Decoded normals of all 16224 codes (spec §5.1).
std::vector<Vec3f> make_normal_table() {
  std::array<float, kNormalGrid> g{};
  for (int i = 0; i < kNormalGrid; ++i) {
    const double t = ((i + 0.5) * 2.0 / kNormalGrid - 1.0) * std::numbers::pi / 4.0;
    g[i] = float(std::tan(t));
  }
  std::vector<Vec3f> table(kNormalCodeCount);
  for (std::uint32_t q = 0; q < kNormalCodeCount; ++q) {
    const std::uint32_t a = q / (kNormalGrid * kNormalGrid);
    const float u = g[(q / kNormalGrid) % kNormalGrid], v = g[q % kNormalGrid];
    const float w2 = 1.0f - u * u - v * v;
    // Grid corners off the sphere (never written by an encoder): put them on the cube face's
    // edge instead of QSplat 1.0's NaN.
    const float w = w2 > 0 ? std::sqrt(w2) : 0.0f;
    Vec3f n;
    switch (a) {
      case 0: n = {w, u, v}; break;
      case 1: n = {-w, u, v}; break;
      case 2: n = {v, w, u}; break;
      case 3: n = {v, -w, u}; break;
      case 4: n = {u, v, w}; break;
      default: n = {u, v, -w}; break;
    }
    table[q] = w2 > 0 ? n : normalized(n);
  }
  return table;
}

// Floor of a finite or non-finite float, clamped to [lo, hi] (NaN gives lo).
int clamped_floor(float f, int lo, int hi) {
  f = std::floor(f);
  if (!(f >= float(lo))) return lo;
  if (f > float(hi)) return hi;
  return int(f);
}

// Cell 0..51 of one raw normal component on the atan-warped face grid (spec §5.2): atan(t)·4 in
// float32, the division by π in double, then rounded to float32.
int normal_cell(float t) {
  const float warped = std::atan(t) * 4.0f;
  float w = float(double(warped) / std::numbers::pi);
  w = std::clamp(w, -1.0f, 1.0f);
  return clamped_floor((w + 1.0f) * 0.5f * float(kNormalGrid), 0, kNormalGrid - 1);
}

// The least float of each cell 1..51 of normal_cell (bisection over the floats' order, from
// -infinity to +infinity), then NaN to pad to whole vectors (no comparison with NaN holds).
using CellBounds = std::array<float, 56>;
CellBounds make_cell_bounds() {
  CellBounds bounds;
  bounds.fill(std::numeric_limits<float>::quiet_NaN());
  for (int cell = 1; cell < kNormalGrid; ++cell) {
    // normal_cell(from_ordered_key(lo)) < cell <= normal_cell(from_ordered_key(hi))
    std::uint32_t lo = ordered_key(-std::numeric_limits<float>::infinity());
    std::uint32_t hi = ordered_key(std::numeric_limits<float>::infinity());
    while (hi - lo > 1) {
      const std::uint32_t mid = lo + (hi - lo) / 2;
      (normal_cell(from_ordered_key(mid)) >= cell ? hi : lo) = mid;
    }
    bounds[std::size_t(cell - 1)] = from_ordered_key(hi);
  }
  return bounds;
}

std::uint32_t cell_by_bounds(const CellBounds& bounds, float t) {
  std::uint32_t cell = 0;
  for (const float b : bounds) cell += t >= b;
  return cell;
}

}  // namespace

std::span<const std::int16_t> sphere_code_table() { return sphere_tables().code; }

std::span<const SphereCandidate, kSphereCodeCount> sphere_table() {
  return sphere_tables().entries;
}

int sphere_code(int m, int x, int y, int z) {
  if (m < 1 || m > kSphereGrid) return -1;
  const int last = kSphereGrid - m;
  if (x < 0 || y < 0 || z < 0 || x > last || y > last || z > last) return -1;
  return sphere_tables().code[((std::size_t(m) * 13 + x) * 13 + y) * 13 + z];
}

std::span<const Vec3f, kNormalCodeCount> normal_table() {
  static const std::vector<Vec3f> table = make_normal_table();
  return std::span<const Vec3f, kNormalCodeCount>(table.data(), kNormalCodeCount);
}

namespace {

// The face of n and its two components on it, as QSplat 1.0 picks them.
struct FaceComponents {
  std::uint32_t face;
  float u, v;
};
FaceComponents face_components(Vec3f n) {
  const float ax = std::fabs(n.x), ay = std::fabs(n.y), az = std::fabs(n.z);
  // Ties go to the later axis (y over x, z over either), as QSplat 1.0 decides.
  std::uint32_t face;
  if (ax > ay) {
    face = (ax > az) ? (n.x > 0 ? 0 : 1) : (n.z > 0 ? 4 : 5);
  } else {
    face = (ay > az) ? (n.y > 0 ? 2 : 3) : (n.z > 0 ? 4 : 5);
  }
  if (face < 2) return {face, n.y, n.z};
  if (face < 4) return {face, n.z, n.x};
  return {face, n.x, n.y};
}

}  // namespace

std::uint32_t encode_normal(Vec3f n) {
  const FaceComponents f = face_components(n);
  return (f.face * kNormalGrid + std::uint32_t(normal_cell(f.u))) * kNormalGrid +
         std::uint32_t(normal_cell(f.v));
}

std::uint32_t encode_normal_by_bounds(Vec3f n) {
  static const CellBounds bounds = make_cell_bounds();
  const FaceComponents f = face_components(n);
  return (f.face * kNormalGrid + cell_by_bounds(bounds, f.u)) * kNormalGrid +
         cell_by_bounds(bounds, f.v);
}

}  // namespace pointillist::quant
