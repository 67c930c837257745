// The clip test of sharp features (Ivo, eq. 4.18; features.hpp clip_discards) on four pixels at
// once, shared by the fast and the quality rasterizer. Internal to render.
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include "pointillist/core/camera.hpp"
#include "pointillist/features/features.hpp"
#include "pointillist/render/splat_stream.hpp"
#include "simd.hpp"

namespace pointillist::render_detail {

// Lanes whose point (px, py, pz), eye coordinates on the splat's plane, the splat's `count`
// planes (4 floats each: n_e, h_e; n_e·P − h_e < 0 is the clipped side) discard under `mode`.
inline Int4 clip_discard4(const float* planes, std::uint32_t count, ClipMode mode, Float4 px,
                          Float4 py, Float4 pz) {
  const Float4 zero = splat4(0.0f);
  Int4 any{}, all = Int4{} - 1;
  Float4 nearest = splat4(std::numeric_limits<float>::infinity()), nearest_side = zero;
  for (std::uint32_t k = 0; k < count; ++k, planes += 4) {
    const Float4 side = planes[0] * px + planes[1] * py + planes[2] * pz - planes[3];
    const Int4 out = side < zero;
    any |= out;
    all &= out;
    const Float4 dist = select4(out, -side, side);
    const Int4 closer = dist < nearest;
    nearest = select4(closer, dist, nearest);
    nearest_side = select4(closer, side, nearest_side);
  }
  switch (mode) {
    case ClipMode::Union: return any;
    case ClipMode::Intersection: return all;
    case ClipMode::Nearest: return nearest_side < zero;
    case ClipMode::None: break;
  }
  return Int4{};
}

// A chunk's clip planes in eye coordinates (x right, y up, z = depth): a world point is
// eye + x·right + y·up + z·forward, so n·X − h = n_e·P − h_e with n_e = (n·right, n·up,
// n·forward), h_e = h − n·eye.
inline void eye_space_planes(const SplatChunk& chunk, const CameraFrame& cam,
                             std::vector<float>& out) {
  out.clear();
  for (const ClipPlane& p : chunk.clip_planes) {
    out.push_back(dot(p.n, cam.right));
    out.push_back(dot(p.n, cam.up));
    out.push_back(dot(p.n, cam.forward));
    out.push_back(p.h - dot(p.n, cam.eye));
  }
}

}  // namespace pointillist::render_detail
