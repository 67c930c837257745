// Normal maps: a unit normal as an 8-bit colour and back. The renderers' --normal-colors images
// (RenderSettings::normal_colors), `generate --reference-normals` and `compare --normals` share
// this one encoding, so a measured angle is the normals' and not the encoders'.
#pragma once

#include <algorithm>
#include <cmath>

#include "pointillist/core/math.hpp"

namespace pointillist {

// round(255·(c + 1)/2) per component, c clamped to [−1, 1]; NaN gives 0.
inline Rgb8 encode_normal_color(Vec3f n) {
  const auto channel = [](float c) {
    return static_cast<std::uint8_t>(std::min(1.0f, std::max(0.0f, 0.5f * c + 0.5f)) * 255.0f +
                                     0.5f);
  };
  return {channel(n.x), channel(n.y), channel(n.z)};
}

// The unit vector along (c/127.5 − 1) per channel, or (0, 0, 0) when that vector is shorter than
// 0.01 (no unit normal encodes there). The round trip of a unit normal is within 0.4° of it:
// each channel is off by at most 1/255.
inline Vec3f decode_normal_color(Rgb8 c) {
  const Vec3f v{c.r / 127.5f - 1.0f, c.g / 127.5f - 1.0f, c.b / 127.5f - 1.0f};
  const float len = std::sqrt(dot(v, v));
  return len > 0.01f ? v / len : Vec3f{0, 0, 0};
}

}  // namespace pointillist
