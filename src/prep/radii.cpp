// Splat radii. Meshes: Rusinkiewicz & Levoy, "QSplat: A multiresolution point rendering system
// for large meshes", SIGGRAPH 2000, section 3.1, with the rule its preprocessor applies (the
// smallest circle enclosing each incident triangle, ../shared/specs/qsplat-qs-format.md §8.2). Clouds: the
// mean distance to the nearest neighbours, widened by a coverage factor (see radii.hpp).
#include <array>
#include "pointillist/prep/radii.hpp"

#include <algorithm>
#include <bit>
#include <limits>
#include <utility>
#include <vector>
#include <cassert>
#include <cmath>

#include "pointillist/core/error.hpp"
#include "ordered_cloud.hpp"
#include "vertex_ranges.hpp"

namespace pointillist {
namespace {

constexpr std::size_t kGrain = 1 << 15;

// Batcher's odd-even merge sort for `size` (a power of two, at most 64) values: the pairs to
// compare and exchange, in order.
std::vector<std::pair<std::uint8_t, std::uint8_t>> sorting_network(std::size_t size) {
  std::vector<std::pair<std::uint8_t, std::uint8_t>> pairs;
  for (std::size_t p = 1; p < size; p *= 2) {
    for (std::size_t k = p; k >= 1; k /= 2) {
      for (std::size_t j = k % p; j + k < size; j += 2 * k) {
        for (std::size_t i = 0; i < std::min(k, size - j - k); ++i) {
          if ((i + j) / (2 * p) == (i + j + k) / (2 * p)) {
            pairs.emplace_back(std::uint8_t(i + j), std::uint8_t(i + j + k));
          }
        }
      }
    }
  }
  return pairs;
}

}  // namespace

// Radius of the smallest circle enclosing triangle (a, b, c): half the longest edge when the
// triangle is right or obtuse (that edge is then a diameter), otherwise the circumradius
// |ab|·|bc|·|ca| / (2·|ab × ac|). Discs of this radius centred on the three corners cover the
// whole triangle (the point of the triangle farthest from every corner is the circumcentre, or
// the midpoint of the longest edge), so splats sized by it leave no hole in the mesh. Double
// precision: the circumradius of a thin triangle is a quotient of small numbers.
float enclosing_circle_radius(Vec3f a, Vec3f b, Vec3f c) {
  const double ab[3] = {double(b.x) - a.x, double(b.y) - a.y, double(b.z) - a.z};
  const double ac[3] = {double(c.x) - a.x, double(c.y) - a.y, double(c.z) - a.z};
  const double bc[3] = {ac[0] - ab[0], ac[1] - ab[1], ac[2] - ab[2]};
  auto dot3 = [](const double* u, const double* v) { return u[0] * v[0] + u[1] * v[1] + u[2] * v[2]; };
  const double lab = dot3(ab, ab), lac = dot3(ac, ac), lbc = dot3(bc, bc);
  const double longest = std::max({lab, lac, lbc});
  // An angle of 90° or more: at a (ab·ac ≤ 0), b (ba·bc ≤ 0) or c (ca·cb ≤ 0).
  const bool obtuse = dot3(ab, ac) <= 0 || -dot3(ab, bc) <= 0 || dot3(ac, bc) <= 0;
  if (obtuse) return static_cast<float>(0.5 * std::sqrt(longest));
  const double cx = ab[1] * ac[2] - ab[2] * ac[1], cy = ab[2] * ac[0] - ab[0] * ac[2],
               cz = ab[0] * ac[1] - ab[1] * ac[0];
  const double twice_area = std::sqrt(cx * cx + cy * cy + cz * cz);
  if (!(twice_area > 0)) return static_cast<float>(0.5 * std::sqrt(longest));
  return static_cast<float>(std::sqrt(lab * lac * lbc) / (2.0 * twice_area));
}

std::vector<float> mesh_radii(std::span<const Vec3f> positions,
                              std::span<const std::array<std::uint32_t, 3>> triangles, float scale,
                              ThreadPool& pool) {
  const std::size_t n = positions.size();
  std::vector<float> radii(n, 0.0f);
  prep_detail::for_each_vertex_range(pool, n, [&](std::uint32_t lo, std::uint32_t hi) {
    const std::uint32_t size = hi - lo;
    for (const auto& t : triangles) {
      assert(t[0] < n && t[1] < n && t[2] < n);
      // v - lo < size (unsigned) tests lo <= v < hi.
      const std::uint32_t i0 = t[0] - lo, i1 = t[1] - lo, i2 = t[2] - lo;
      if (std::min({i0, i1, i2}) >= size) continue;
      const float r = enclosing_circle_radius(positions[t[0]], positions[t[1]], positions[t[2]]);
      if (i0 < size) radii[t[0]] = std::max(radii[t[0]], r);
      if (i1 < size) radii[t[1]] = std::max(radii[t[1]], r);
      if (i2 < size) radii[t[2]] = std::max(radii[t[2]], r);
    }
    for (std::uint32_t v = lo; v < hi; ++v) radii[v] *= scale;
  });
  return radii;
}

namespace prep_detail {

std::vector<float> cloud_radii_ordered(const OrderedCloud& cloud, std::uint32_t neighbours,
                                       float factor, float outlier_ratio, ThreadPool& pool,
                                       Progress& progress) {
  const std::size_t n = cloud.size();
  const std::size_t used = std::min(neighbours, cloud.k);
  ProgressPhase phase(progress, "radii", n);
  std::vector<float> raw(n, 0.0f);
  if (used == 0) return raw;
  parallel_for(pool, n, kGrain, [&](std::size_t begin, std::size_t end) {
    for (std::size_t j = begin; j < end; ++j) {
      float sum = 0.0f;
      for (const std::uint32_t i : cloud.row(j).first(used)) {
        sum += distance(cloud.positions[i], cloud.positions[j]);
      }
      raw[j] = sum / float(used);
    }
  });
  std::vector<float> radii(n, 0.0f);
  if (!(outlier_ratio > 0.0f)) {
    parallel_for(pool, n, kGrain, [&](std::size_t begin, std::size_t end) {
      for (std::size_t j = begin; j < end; ++j) radii[j] = raw[j] * factor;
      phase.advance(end - begin);
    });
    return radii;
  }
  // The median of the neighbours' mean distances, kLanes points at a time through a sorting
  // network (branch-free, vectorized across the points; padded with +inf, which sorts last).
  const std::size_t m = std::min<std::size_t>(cloud.k, kOutlierNeighbours);
  const std::vector<std::pair<std::uint8_t, std::uint8_t>> network =
      sorting_network(std::bit_ceil(m));
  parallel_for(pool, n, kGrain, [&](std::size_t begin, std::size_t end) {
    // Eight points' values per vector (two SSE registers, one AVX register).
    using Lanes = float __attribute__((vector_size(32)));
    constexpr std::size_t kLanes = sizeof(Lanes) / sizeof(float);
    std::array<Lanes, 64> v;
    for (std::size_t j0 = begin; j0 < end; j0 += kLanes) {
      const std::size_t lanes = std::min(kLanes, end - j0);
      for (std::size_t l = 0; l < kLanes; ++l) {
        const auto row = cloud.row(j0 + std::min(l, lanes - 1));
        for (std::size_t q = 0; q < m; ++q) v[q][l] = raw[row[q]];
      }
      for (std::size_t q = m; q < std::bit_ceil(m); ++q) {
        v[q] = Lanes{} + std::numeric_limits<float>::infinity();
      }
      for (const auto& [a, b] : network) {
        const Lanes x = v[a], y = v[b];
        v[a] = y < x ? y : x;
        v[b] = y < x ? x : y;
      }
      for (std::size_t l = 0; l < lanes; ++l) {
        const float median = v[m / 2][l];
        float r = raw[j0 + l];
        if (median > 0.0f) r = std::min(r, outlier_ratio * median);
        radii[j0 + l] = r * factor;
      }
    }
    phase.advance(end - begin);
  });
  return radii;
}

}  // namespace prep_detail

std::vector<float> cloud_radii(std::span<const Vec3f> positions, ThreadPool& pool,
                               Progress& progress, const CloudRadiusOptions& options) {
  if (options.neighbours == 0) {
    throw OptionError(
        "cloud radii: neighbours = 0; the radius is measured to at least 1 "
        "nearest neighbour (5 is typical)");
  }
  const prep_detail::OrderedCloud cloud =
      prep_detail::order_cloud(
          positions,
          options.outlier_ratio > 0 ? std::max(options.neighbours, kOutlierNeighbours)
                                    : options.neighbours,
          pool, progress);
  const std::vector<float> radii = prep_detail::cloud_radii_ordered(
      cloud, options.neighbours, options.coverage * options.scale, options.outlier_ratio, pool,
      progress);
  return prep_detail::to_caller_order<float>(cloud, radii, pool);
}

}  // namespace pointillist
