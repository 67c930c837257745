// Checks of the splats a hierarchy is built from, shared by the QSplat hierarchy and the
// Sequential Point Tree builders. Private to the lod module.
#pragma once

#include <string>

#include "pointillist/core/math.hpp"
#include "pointillist/core/point_set.hpp"
#include "pointillist/core/thread_pool.hpp"

namespace pointillist::lod_detail {

// Throws Error when `points` is empty, has more than 2^31 points, lacks normals or radii, or an
// attribute array has the wrong length. `what` starts every message ("cannot build a ...").
void check_splat_attributes(const PointSet& points, const std::string& what);

// Checks that every position, normal and radius is finite (radii >= 0) and returns the box
// around the positions. Throws Error naming the lowest bad point, after `what`. Parallel; the
// result does not depend on the thread count.
Aabb check_points_and_bound(const PointSet& points, ThreadPool& pool, const std::string& what);

// Largest distance from `center` to a position (max is exact, so chunking cannot change it).
float max_distance(const std::vector<Vec3f>& positions, Vec3f center, ThreadPool& pool);

}  // namespace pointillist::lod_detail
