// The ellipse kernel's per-splat setup (splat_raster.cpp): the screen ellipse of a disc seen at
// an angle, as QSplat's normal-oriented splats draw it. Internal to render.
#pragma once

#include <algorithm>
#include <cmath>

#include "pointillist/core/camera.hpp"
#include "pointillist/render/splat_raster.hpp"

namespace pointillist::render_detail {

inline constexpr float kMinEllipseRatio = 0.1f;
inline constexpr int kEllipseStride = 6;  // A, 2B, C, half extent x / r, half extent y / r, ratio

// Ellipse of a disc with eye-space normal ne seen along ve: minor axis (ax, ay) along the screen
// projection of the normal (pixel y runs down), minor/major = max(|n·v|, 0.1). With q = ratio²
// the ellipse is dᵀ·M·d ≤ r², M = a·aᵀ/q + b·bᵀ (b ⟂ a), so A = ax²/q + ay², B = ax·ay·(1/q − 1),
// C = ay²/q + ax²; its bounding box has half extents r·√(ax²·q + ay²) and r·√(ay²·q + ax²).
inline void ellipse_parameters(Vec3f ne, Vec3f ve, float* e) {
  float ax = ne.x, ay = -ne.y;
  const float len = std::sqrt(ax * ax + ay * ay);
  float ratio = std::min(std::max(std::abs(dot(ne, ve)), kMinEllipseRatio), 1.0f);
  if (len > 1e-6f) {
    ax /= len;
    ay /= len;
  } else {
    ax = 1.0f;
    ay = 0.0f;
    ratio = 1.0f;
  }
  const float q = ratio * ratio, inv_q = 1.0f / q;
  e[0] = ax * ax * inv_q + ay * ay;
  e[1] = 2.0f * ax * ay * (inv_q - 1.0f);
  e[2] = ay * ay * inv_q + ax * ax;
  e[3] = std::sqrt(ax * ax * q + ay * ay);
  e[4] = std::sqrt(ay * ay * q + ax * ax);
  e[5] = ratio;
}

// Ellipse parameters of every splat of `chunk`.
inline void prepare_ellipses(const SplatChunk& chunk, const CameraFrame& cam, RasterScratch::Chunk& out) {
  const std::size_t n = chunk.count;
  if (out.ellipse.size() < kEllipseStride * n) {
    out.ellipse.resize(std::max(kEllipseStride * n, 2 * out.ellipse.size()));
  }
  const float half_w = 0.5f * static_cast<float>(cam.width);
  const float half_h = 0.5f * static_cast<float>(cam.height);
  const float inv_f = 1.0f / cam.focal_px;
  const Vec3f right = cam.right, up = cam.up, back = -cam.forward;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3f nw = chunk.normal[i];
    const Vec3f ne{dot(nw, right), dot(nw, up), dot(nw, back)};
    // Unit vector to the eye in eye space: −(x_e/z, y_e/z, −1), normalized; (0, 0, 1) for
    // parallel rays.
    const float a = cam.ortho ? 0.0f : (chunk.x_px[i] - half_w) * inv_f;
    const float b = cam.ortho ? 0.0f : (chunk.y_px[i] - half_h) * inv_f;
    const float inv_len = 1.0f / std::sqrt(a * a + b * b + 1.0f);
    ellipse_parameters(ne, Vec3f{-a * inv_len, b * inv_len, inv_len},
                       &out.ellipse[kEllipseStride * i]);
  }
}

}  // namespace pointillist::render_detail
