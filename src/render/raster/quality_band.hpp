// The quality rasterizer's per-band state (quality_raster.cpp): the per-pixel planes of a band
// of rows, four pixels a group, and the shading of what a band accumulated. Internal to the
// rasterizer and its passes.
#pragma once

#include <algorithm>
#include <cstdint>
#include <limits>
#include <span>

#include "pointillist/core/camera.hpp"
#include "pointillist/features/features.hpp"
#include "raster/quality_kernel.hpp"
#include "shading.hpp"

namespace pointillist::quality_detail {

using render_detail::Float4;
using render_detail::Int4;
using render_detail::kLanes;
using render_detail::load4;
using render_detail::max4;
using render_detail::min4;
using render_detail::select4;
using render_detail::splat4;
using render_detail::store4;

constexpr float kInf = std::numeric_limits<float>::infinity();
// Per-pixel state of a band, in planes of 4 lanes per 4-pixel group.
enum AccPlane : int {
  kSumBound, kSumW, kSumDepth, kSumR, kSumG, kSumB, kSumNx, kSumNy, kSumNz, kAccPlanes
};
enum LayerPlane : int { kLower, kNext, kOutR, kOutG, kOutB, kTransmit, kLayerPlanes };
constexpr int kGroupFloats = kAccPlanes * kLanes;
constexpr int kLayerFloats = kLayerPlanes * kLanes;

inline bool any4(Int4 m) { return (m[0] | m[1] | m[2] | m[3]) != 0; }

// Per-frame constants of the pixel kernel.
struct View {
  float half_w, half_h, inv_f;
  bool ortho;  // parallel rays along +z from (a, b, 0); else rays t·(a, b, 1) from the eye
  float inv_rho2;  // 1 / lowpass_radius_px²
  float kernel_k;  // 1 / (2σ²), σ in radii
};

// The front surface of a pixel when the stream has sharp features: the depth and surface id
// of its nearest unclipped fragment.
enum IdPlane : int { kFrontDepth, kFrontId, kIdPlanes };
constexpr int kIdFloats = kIdPlanes * kLanes;
constexpr std::int32_t kMixedId = static_cast<std::int32_t>(kMixedSurface);


// Columns of 16 pixels (4 groups) across a band, for the surface rule: the one surface id of
// the splats that reach into the column (inner nodes' mixed id aside), or kMultiTile when they
// carry several. Where only one surface (and mixed nodes) reaches, every fragment belongs to the
// front surface whatever its depth, so the pass that finds the front surface skips the column
// and leaves its ids mixed (every fragment takes part): the same image as finding them.
constexpr int kTileShift = 2;  // groups per tile column: 1 << kTileShift
constexpr std::uint32_t kEmptyTile = kMixedSurface;
constexpr std::uint32_t kMultiTile = kMixedSurface - 1;

struct Band {
  int row0, row1;  // rows [row0, row1)
  int groups;      // 4-pixel groups per row
  float* acc;      // kGroupFloats per group
  float* layer;    // kLayerFloats per group (layered rendering only)
  float* ids;      // kIdFloats per group (opaque rendering with features only)
  // The worker's counts (features only): covered pixels discarded by clip planes, counted in
  // the first pass that clips; fragments of another surface than the pixel's front one, counted
  // in the accumulation pass.
  std::uint64_t* clipped;
  std::uint64_t* other_surface;
  std::uint32_t* tiles = nullptr;  // the surface rule's tile columns (see kMultiTile)
  // The surface rule: the image's pixels (row-major, `width` wide) where a clip plane discarded
  // a covered fragment, marked in the visibility pass (the band's rows only).
  std::uint8_t* clip_mask = nullptr;
  int width = 0;
  float* ids_at(int j, int k) const {
    return ids + (static_cast<std::size_t>(j - row0) * groups + k) * kIdFloats;
  }
  float* acc_at(int j, int k) const {
    return acc + (static_cast<std::size_t>(j - row0) * groups + k) * kGroupFloats;
  }
  float* layer_at(int j, int k) const {
    return layer + (static_cast<std::size_t>(j - row0) * groups + k) * kLayerFloats;
  }
};

struct Output {
  std::span<Rgb8> color;
  std::span<float> depth;
  int width;
};

// Normalises and shades the surface accumulated in the band, four pixels at a time. Opaque:
// writes color and depth. Layered: composites into the layer planes (and writes depth for the
// first surface); returns whether any pixel has a surface behind (a finite next bound).
class BandShader {
 public:
  BandShader(const render_detail::Shader& shader, const CameraFrame& cam, const View& v,
             Rgb8 background, float opacity)
      : shader_(shader), cam_(cam), v_(v), background_(background), opacity_(opacity) {}

  template <bool kLayered>
  bool shade(const Band& band, const Output& out, bool first_surface) const {
    const Float4 lane{0.0f, 1.0f, 2.0f, 3.0f};
    const Float4 zero = splat4(0.0f);
    bool more = false;
    for (int j = band.row0; j < band.row1; ++j) {
      const float b = (v_.half_h - (static_cast<float>(j) + 0.5f)) * v_.inv_f;
      for (int k = 0; k < band.groups; ++k) {
        float* acc = band.acc_at(j, k);
        const Float4 w = load4(acc + kSumW * kLanes);
        const Int4 has = w > zero;
        float* layer = kLayered ? band.layer_at(j, k) : nullptr;
        if constexpr (kLayered) more |= any4(load4(layer + kNext * kLanes) < splat4(kInf));
        const int i_first = k * kLanes;
        const int lanes = std::min(kLanes, out.width - i_first);
        if (!any4(has)) {
          if (!kLayered) write_color(out, j, i_first, lanes, has, nullptr);
          if (first_surface) write_depth(out, j, i_first, lanes, splat4(kInf));
          continue;
        }
        // View vector (world space) along each pixel's ray, toward the eye.
        const Float4 a = (static_cast<float>(i_first) + lane + 0.5f - v_.half_w) * v_.inv_f;
        Float4 view[3];
        if (v_.ortho) {
          for (int c = 0; c < 3; ++c) view[c] = splat4(-cam_.forward[c]);
        } else {
          for (int c = 0; c < 3; ++c) {
            view[c] = -(a * cam_.right[c] + b * cam_.up[c] + cam_.forward[c]);
          }
          const Float4 inv_view = 1.0f / render_detail::sqrt4(
              view[0] * view[0] + view[1] * view[1] + view[2] * view[2]);
          for (Float4& c : view) c *= inv_view;
        }
        Float4 base[3], normal[3];
        const Float4 safe_w = select4(has, w, splat4(1.0f));
        for (int c = 0; c < 3; ++c) {
          base[c] = load4(acc + (kSumR + c) * kLanes) / safe_w;
          normal[c] = load4(acc + (kSumNx + c) * kLanes);
        }
        const Float4 len = render_detail::sqrt4(
            normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]);
        const Int4 has_normal = len > splat4(1e-30f);
        const Float4 safe_len = select4(has_normal, len, splat4(1.0f));
        for (int c = 0; c < 3; ++c) normal[c] = select4(has_normal, normal[c] / safe_len, view[c]);
        Int4 rgb[3];
        shader_.shade4(normal, view, base, rgb);
        const Float4 depth = select4(has, load4(acc + kSumDepth * kLanes) / safe_w, splat4(kInf));
        if (first_surface) write_depth(out, j, i_first, lanes, depth);
        if constexpr (!kLayered) {
          write_color(out, j, i_first, lanes, has, rgb);
        } else {
          const Float4 t = load4(layer + kTransmit * kLanes);
          const Float4 ta = select4(has, t * opacity_, zero);
          for (int c = 0; c < 3; ++c) {
            const Float4 old = load4(layer + (kOutR + c) * kLanes);
            store4(layer + (kOutR + c) * kLanes, old + ta * render_detail::to_float4(rgb[c]));
          }
          store4(layer + kTransmit * kLanes, select4(has, t * (1.0f - opacity_), t));
        }
      }
    }
    return more;
  }

  // Final colors of a layered band: C + T·background.
  void finish_layers(const Band& band, const Output& out) const {
    for (int j = band.row0; j < band.row1; ++j) {
      for (int k = 0; k < band.groups; ++k) {
        const float* layer = band.layer_at(j, k);
        const Float4 t = load4(layer + kTransmit * kLanes);
        const float bg[3] = {static_cast<float>(background_.r), static_cast<float>(background_.g),
                             static_cast<float>(background_.b)};
        Int4 rgb[3];
        for (int c = 0; c < 3; ++c) {
          const Float4 v = load4(layer + (kOutR + c) * kLanes) + t * bg[c];
          rgb[c] = render_detail::to_int4(min4(splat4(255.0f), max4(splat4(0.0f), v)) + 0.5f);
        }
        const int lanes = std::min(kLanes, out.width - k * kLanes);
        write_color(out, j, k * kLanes, lanes, Int4{} - 1, rgb);
      }
    }
  }

 private:
  // Lanes with `has` get rgb, the others the background.
  void write_color(const Output& out, int j, int i_first, int lanes, Int4 has,
                   const Int4* rgb) const {
    const std::size_t p = static_cast<std::size_t>(j) * out.width + i_first;
    for (int l = 0; l < lanes; ++l) {
      out.color[p + l] = has[l] ? Rgb8{static_cast<std::uint8_t>(rgb[0][l]),
                                       static_cast<std::uint8_t>(rgb[1][l]),
                                       static_cast<std::uint8_t>(rgb[2][l])}
                                : background_;
    }
  }
  void write_depth(const Output& out, int j, int i_first, int lanes, Float4 depth) const {
    const std::size_t p = static_cast<std::size_t>(j) * out.width + i_first;
    for (int l = 0; l < lanes; ++l) out.depth[p + l] = depth[l];
  }

  const render_detail::Shader& shader_;
  const CameraFrame& cam_;
  View v_;
  Rgb8 background_;
  float opacity_;
};

}  // namespace pointillist::quality_detail
