#include "render/point_baseline.hpp"

#include <algorithm>
#include <cassert>
#include <limits>

namespace pointillist {

std::size_t project_points_baseline(std::span<const Vec3f> points, const CameraFrame& camera,
                                    std::span<float> depth) {
  const int w = camera.width, h = camera.height;
  assert(depth.size() == static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
  std::fill(depth.begin(), depth.end(), std::numeric_limits<float>::infinity());
  const float half_w = 0.5f * static_cast<float>(w), half_h = 0.5f * static_cast<float>(h);
  const float fw = static_cast<float>(w), fh = static_cast<float>(h);
  std::size_t landed = 0;
  for (const Vec3f p : points) {
    const Vec3f d = p - camera.eye;
    const float z = dot(d, camera.forward);
    if (!(z > 0.0f)) continue;
    const float inv_z = 1.0f / z;
    const float x = half_w + camera.focal_px * dot(d, camera.right) * inv_z;
    const float y = half_h - camera.focal_px * dot(d, camera.up) * inv_z;
    if (!(x >= 0.0f && x < fw && y >= 0.0f && y < fh)) continue;
    const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(w) +
                          static_cast<std::size_t>(x);
    depth[i] = std::min(depth[i], z);
    ++landed;
  }
  return landed;
}

}  // namespace pointillist
