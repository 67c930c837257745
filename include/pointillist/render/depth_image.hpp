// Depth buffer to a 16-bit gray image (for `pointillist render --depth DEPTH.png`).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "pointillist/render/render.hpp"

namespace pointillist {

// Maps each drawn pixel's depth d linearly from [near, far] to [0, 65534], rounding to nearest
// and clamping: value = round(65534·(d − near)/(far − near)), so 0 is the nearest depth and
// 65534 the farthest. Pixels where nothing was drawn (depth +inf or not finite) are 65535. When
// far ≤ near every drawn pixel is 0. Row order as in the depth buffer (top to bottom).
std::vector<std::uint16_t> depth_to_gray16(std::span<const float> depth, float near, float far);

// As above with near and far the smallest and largest finite depth of the frame, so the drawn
// pixels use the whole range 0..65534.
std::vector<std::uint16_t> depth_to_gray16(const Frame& frame);

}  // namespace pointillist
