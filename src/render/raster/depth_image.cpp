#include "pointillist/render/depth_image.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pointillist {

std::vector<std::uint16_t> depth_to_gray16(std::span<const float> depth, float near, float far) {
  constexpr std::uint16_t kBackground = 65535;
  constexpr double kFarthest = 65534.0;
  std::vector<std::uint16_t> out(depth.size(), kBackground);
  const double range = static_cast<double>(far) - static_cast<double>(near);
  const double scale = range > 0 ? kFarthest / range : 0.0;
  for (std::size_t i = 0; i < depth.size(); ++i) {
    const float d = depth[i];
    if (!std::isfinite(d)) continue;
    const double v = (static_cast<double>(d) - near) * scale;
    out[i] = static_cast<std::uint16_t>(std::lround(std::clamp(v, 0.0, kFarthest)));
  }
  return out;
}

std::vector<std::uint16_t> depth_to_gray16(const Frame& frame) {
  float near = std::numeric_limits<float>::infinity();
  float far = -std::numeric_limits<float>::infinity();
  for (const float d : frame.depth) {
    if (!std::isfinite(d)) continue;
    near = std::min(near, d);
    far = std::max(far, d);
  }
  if (!(near <= far)) near = far = 0;  // nothing drawn
  return depth_to_gray16(frame.depth, near, far);
}

}  // namespace pointillist
