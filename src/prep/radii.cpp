// Splat radii. Meshes: Rusinkiewicz & Levoy, "QSplat: A multiresolution point rendering system
// for large meshes", SIGGRAPH 2000, section 3.1 (spheres of adjacent vertices touch). Clouds: the
// mean distance to the nearest neighbours, widened by a coverage factor (see radii.hpp).
#include "pointillist/prep/radii.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "pointillist/core/error.hpp"
#include "prep/ordered_cloud.hpp"
#include "prep/vertex_ranges.hpp"

namespace pointillist {
namespace {

constexpr std::size_t kGrain = 1 << 15;

}  // namespace

std::vector<float> mesh_radii(std::span<const Vec3f> positions,
                              std::span<const std::array<std::uint32_t, 3>> triangles, float scale,
                              ThreadPool& pool) {
  const std::size_t n = positions.size();
  std::vector<float> radii(n, 0.0f);
  const float half = 0.5f * scale;
  prep_detail::for_each_vertex_range(pool, n, [&](std::uint32_t lo, std::uint32_t hi) {
    const std::uint32_t size = hi - lo;
    for (const auto& t : triangles) {
      assert(t[0] < n && t[1] < n && t[2] < n);
      // v - lo < size (unsigned) tests lo <= v < hi.
      const std::uint32_t i0 = t[0] - lo, i1 = t[1] - lo, i2 = t[2] - lo;
      if (std::min({i0, i1, i2}) >= size) continue;
      const float e01 = distance(positions[t[0]], positions[t[1]]);
      const float e12 = distance(positions[t[1]], positions[t[2]]);
      const float e20 = distance(positions[t[2]], positions[t[0]]);
      if (i0 < size) radii[t[0]] = std::max(radii[t[0]], std::max(e01, e20));
      if (i1 < size) radii[t[1]] = std::max(radii[t[1]], std::max(e01, e12));
      if (i2 < size) radii[t[2]] = std::max(radii[t[2]], std::max(e12, e20));
    }
    for (std::uint32_t v = lo; v < hi; ++v) radii[v] *= half;
  });
  return radii;
}

namespace prep_detail {

std::vector<float> cloud_radii_ordered(const OrderedCloud& cloud, std::uint32_t neighbours,
                                       float factor, ThreadPool& pool, Progress& progress) {
  const std::size_t n = cloud.size();
  const std::size_t used = std::min(neighbours, cloud.k);
  ProgressPhase phase(progress, "radii", n);
  std::vector<float> radii(n, 0.0f);
  if (used == 0) return radii;
  parallel_for(pool, n, kGrain, [&](std::size_t begin, std::size_t end) {
    for (std::size_t j = begin; j < end; ++j) {
      float sum = 0.0f;
      for (const std::uint32_t i : cloud.row(j).first(used)) {
        sum += distance(cloud.positions[i], cloud.positions[j]);
      }
      radii[j] = sum / float(used) * factor;
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
      prep_detail::order_cloud(positions, options.neighbours, pool, progress);
  const std::vector<float> radii = prep_detail::cloud_radii_ordered(
      cloud, options.neighbours, options.coverage * options.scale, pool, progress);
  return prep_detail::to_caller_order<float>(cloud, radii, pool);
}

}  // namespace pointillist
