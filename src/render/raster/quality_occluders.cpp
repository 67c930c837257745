// The occluder pass of occlusion culling in quality mode (quality_occluders.hpp): the quality
// rasterizer's per-splat setup and band binning (kept for the quality pass), then per band of
// rows the pixels each splat surely covers, computed as the rasterizer computes them.
#include "raster/quality_occluders.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>

#include "raster/quality_kernel.hpp"

namespace pointillist::quality_detail {
namespace {

using render_detail::Float4;
using render_detail::Int4;
using render_detail::min4;
using render_detail::select4;

// A pixel counts as covered only when its kernel argument is this far inside the edge: the
// rasterizer's lane arithmetic may round differently from this scalar loop right at the edge.
constexpr float kOccluderCoverMargin = 1e-3f;

// hi + W_max(hi) (FeatureOccluderBound), with slack for the float arithmetic of the setup.
float feature_bound(const FeatureOccluderBound& f, float hi) {
  const float r = std::max({f.leaf_radius, f.inner_radius, f.radius_per_depth * hi});
  return hi + f.width_per_radius * r * (1.0f + 1e-4f) + std::fabs(hi) * 1e-6f;
}

}  // namespace

SoftwareQueries::Rect draw_quality_occluders(const SplatStream& stream, std::size_t first,
                                             std::size_t last, const CameraFrame& camera,
                                             const RenderSettings& settings,
                                             const QualitySettings& quality, ThreadPool& pool,
                                             QualityScratch& prepared, OccluderScratch& scratch,
                                             std::span<float> bound, bool occluders,
                                             const FeatureOccluderBound& features) {
  const int width = camera.width, height = camera.height;
  SoftwareQueries::Rect out{width, height, 0, 0};
  if (last <= first || width <= 0 || height <= 0) return out;
  // The quality pass's own setup and bands, kept for it (rasterize_quality_pieces).
  const SetupConstants setup =
      quality_setup(camera, settings, quality, stream.has_colors, pool.thread_count());
  const int band_rows = setup.band_rows;
  fit_chunks(prepared, last);
  const std::size_t chunks = last - first;
  pool.run(chunks, [&](std::size_t c) {
    prepare_chunk(stream.chunks[first + c], setup, stream.has_features,
                  prepared.chunk_splats[first + c],
                  prepared.chunk_bins[first + c], prepared.chunk_planes[first + c]);
  });

  if (!occluders) return out;
  assert(!stream.has_features || features.active);
  const std::size_t bands = static_cast<std::size_t>(setup.band_count);
  scratch.band_rects.assign(bands, out);
  const float half_w = 0.5f * static_cast<float>(width);
  const float half_h = 0.5f * static_cast<float>(height);
  const float inv_f = 1.0f / camera.focal_px;
  const float inv_rho2 = 1.0f / (quality.lowpass_radius_px * quality.lowpass_radius_px);
  const float inf = std::numeric_limits<float>::infinity();
  const float limit = 1.0f - kOccluderCoverMargin;
  const bool z_range = setup.rule.z_range;
  pool.run(bands, [&](std::size_t band) {
    const int row0 = static_cast<int>(band) * band_rows;
    const int row1 = std::min(height, row0 + band_rows);
    SoftwareQueries::Rect& r = scratch.band_rects[band];
    for (std::size_t c = first; c < last; ++c) {
      const std::vector<std::uint32_t>& bins = prepared.chunk_bins[c];
      const std::size_t base = bands + 1;
      for (std::uint32_t k = bins[band]; k < bins[band + 1]; ++k) {
        const float* s = &prepared.chunk_splats[c][kStride * bins[base + k]];
        // With features a clipped splat may lose any pixel: it is no occluder.
        if (stream.has_features && (float_to_bits(s[kClipCode]) & 31u) != 0) continue;
        const int i0 = static_cast<int>(s[kI0]), i1 = static_cast<int>(s[kI1]);
        const int j0 = std::max(static_cast<int>(s[kJ0]), row0);
        const int j1 = std::min(static_cast<int>(s[kJ1]), row1 - 1);
        // The largest bound of the splat's fragments (ZThreshold: depth ≤ the disc's deepest).
        float u_bound = z_range ? s[kBound] : s[kDepthHi] + s[kBound];
        if (stream.has_features) u_bound = feature_bound(features, s[kDepthHi]);
        const float nx = s[kNx], ny = s[kNy], nz = s[kNz], nc = s[kNc];
        const float cx = s[kCx], cy = s[kCy], cz = s[kCz], inv_r2 = s[kInvR2];
        const Float4 lane{0.0f, 1.0f, 2.0f, 3.0f};
        for (int j = j0; j <= j1; ++j) {
          const float pcy = static_cast<float>(j) + 0.5f;
          const float b = (half_h - pcy) * inv_f;
          const float dy = pcy - s[kSy];
          const float dy2 = dy * dy;
          float* row = bound.data() + static_cast<std::size_t>(j) * static_cast<std::size_t>(width);
          bool any = false;
          // Four pixels at a time, as the rasterizer computes them.
          for (int i = i0; i <= i1; i += 4) {
            const Float4 iv = static_cast<float>(i) + lane;
            const Float4 pcx = iv + 0.5f;
            const Float4 a = (pcx - half_w) * inv_f;
            Float4 t, x, y;
            ray_hits(camera.ortho, a, nx * a + nz, b, nx, ny, nz, nc, t, x, y);
            const Float4 dx = pcx - s[kSx];
            const Float4 sd = (dx * dx + dy2) * inv_rho2;
            const Int4 valid = (t > 0.0f) & (t < inf);
            const Float4 ex = x - cx, ey = y - cy, ez = t - cz;
            const Float4 u = (ex * ex + ey * ey + ez * ez) * inv_r2;
            const Float4 m = select4(valid, min4(sd, u), sd);
            const Int4 cover = (iv <= static_cast<float>(i1)) & (m <= limit);
            if (!(cover[0] | cover[1] | cover[2] | cover[3])) continue;
            for (int l = 0; l < 4; ++l) {
              if (!cover[l] || !(u_bound < row[i + l])) continue;
              row[i + l] = u_bound;
              any = true;
              r.x0 = std::min(r.x0, i + l);
              r.x1 = std::max(r.x1, i + l + 1);
            }
          }
          if (any) {
            r.y0 = std::min(r.y0, j);
            r.y1 = std::max(r.y1, j + 1);
          }
        }
      }
    }
  });
  for (const SoftwareQueries::Rect& r : scratch.band_rects) out.add(r);
  return out;
}

FeatureOccluderBound feature_occluder_bound(const QualitySettings& quality, float splat_scale,
                                            float threshold_px, const CameraFrame& camera,
                                            float leaf_radius) {
  const float disc = quality.radius_scale * std::max(1.0f, splat_scale);
  FeatureOccluderBound b;
  b.active = true;
  b.width_per_radius = disc * (quality.reconstruction == Reconstruction::ZRange
                                   ? 2.0f + quality.z_range_margin
                                   : quality.z_threshold);
  b.leaf_radius = leaf_radius;
  const float t = threshold_px, f = camera.focal_px;
  if (camera.ortho) {
    b.inner_radius = t / (2.0f * f);
  } else {
    b.radius_per_depth =
        2.0f * f > t * disc ? t / (2.0f * f - t * disc) : std::numeric_limits<float>::infinity();
  }
  return b;
}

QueryFootprint quality_query_footprint(const QualitySettings& quality, float splat_scale) {
  const float disc = quality.radius_scale * std::max(1.0f, splat_scale);
  const float forward = quality.reconstruction == Reconstruction::ZRange
                            ? disc * (1.0f + quality.z_range_margin)
                            : disc;
  // Relative slack for the float arithmetic of the discs' setup.
  return {disc * (1.0f + 1e-5f), forward * (1.0f + 1e-5f), quality.lowpass_radius_px + 1.0f};
}

}  // namespace pointillist::quality_detail
