// Splat radii.
#pragma once

#include <span>
#include <vector>

#include "pointillist/core/point_set.hpp"
#include "pointillist/core/progress.hpp"
#include "pointillist/core/thread_pool.hpp"

namespace pointillist {

// QSplat's rule for meshes: the spheres of two vertices joined by an edge touch, i.e. each
// radius is half the longest edge incident to the vertex, times `scale`.
std::vector<float> mesh_radii(std::span<const Vec3f> positions,
                              std::span<const std::array<std::uint32_t, 3>> triangles, float scale,
                              ThreadPool& pool);

struct CloudRadiusOptions {
  std::uint32_t neighbours = 5;  // the mean distance to this many nearest neighbours is measured
  // Radius = mean distance × coverage × scale. The default closes the holes between the discs of
  // a uniformly (randomly) sampled surface; raise it for sparse or uneven scans.
  float coverage = 1.0f;
  float scale = 1.0f;  // the user's --radius-scale
};

std::vector<float> cloud_radii(std::span<const Vec3f> positions, ThreadPool& pool,
                               Progress& progress = Progress::none(),
                               const CloudRadiusOptions& options = {});

}  // namespace pointillist
