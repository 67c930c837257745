// A plain point projection loop: the baseline that benchmarks compare the renderer against.
#pragma once

#include <cstddef>
#include <span>

#include "pointillist/core/camera.hpp"
#include "pointillist/core/math.hpp"

namespace pointillist {

// Clears `depth` (camera.width × camera.height, rows top to bottom) to +infinity, then projects
// every point once, with no hierarchy, culling, splat size or color, and keeps the smallest
// eye-space depth per pixel (the pixel containing the projected point; points with depth ≤ 0 or
// outside the image are skipped). Single-threaded. Returns how many points landed in the image.
std::size_t project_points_baseline(std::span<const Vec3f> points, const CameraFrame& camera,
                                    std::span<float> depth);

}  // namespace pointillist
