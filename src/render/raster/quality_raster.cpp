// High-quality surface splatting on the CPU:
//  * object-space elliptical weighted average splats, the pixel's ray cast against the splat's
//    plane for perspective-correct kernels (Zwicker, Pfister, van Baar, Gross, "Surface
//    Splatting", SIGGRAPH 2001; Botsch, Spernat, Kobbelt, "Phong Splatting", SPBG 2004);
//  * the screen-space low-pass of EWA resampling approximated by the larger of the object and
//    screen kernels (Botsch, Hornung, Zwicker, Kobbelt, "High-Quality Surface Splatting on
//    Today's GPUs", SPBG 2005);
//  * per-pixel reconstruction by Z-threshold (Zwicker et al. 2001) or Z-range (Räsänen 2002,
//    see quality_reconstruction.cpp), deferred Blinn-Phong shading of the blended normal.
//
// Why two passes per band instead of an A-buffer of fragment lists: a pixel of the dragon at
// one-pixel detail receives 5–15 fragments, each list would be unbounded, and the rule needs the
// smallest bound of all fragments before it can accept any. Classic surface splatting's
// visibility pass (smallest bound per pixel) followed by an accumulation pass (blend the
// fragments whose key is within it) gives the order-independent rule exactly with fixed memory:
// 36 bytes per pixel of one band per thread. Semi-transparent surfaces peel one more surface per
// extra pass (the accumulation pass of surface k finds the bound of surface k + 1), adding 24
// bytes per pixel.
//
// Deterministic: each band visits its splats (binned in stream order) one by one and every
// pixel is computed by the same lane arithmetic wherever it sits in a 4-pixel group, so the
// image bits do not depend on the band layout or the thread count.
#include <algorithm>
#include <atomic>
#include <cassert>
#include <cmath>
#include <cstring>
#include <limits>

#include "pointillist/core/error.hpp"
#include "pointillist/render/quality.hpp"
#include "raster/clip_lanes.hpp"
#include "raster/clip_pinholes.hpp"
#include "raster/quality_band.hpp"
#include "raster/quality_kernel.hpp"

namespace pointillist {
namespace {

using namespace quality_detail;

// What sharp features add to a pass: nothing; the clip test (layered rendering); the clip test
// and the front surface's id (the visibility and accumulation passes of opaque rendering take
// only fragments of that id); the pass that finds that id.
enum Features : int { kNoFeatures, kClipOnly, kSameSurface, kFindFront };

// Lanes whose fragment the splat's clip planes discard (features.hpp): the point P where the
// pixel's ray meets the splat's plane, pulled back to the disc's rim for a fragment of the
// low-pass alone (u > 1), the centre when the ray misses the plane.
inline Int4 clipped_lanes(const float* s, const float* planes, Float4 t, Float4 px_ray,
                          Float4 py_ray, Float4 u, Int4 valid) {
  const auto code = static_cast<std::uint8_t>(float_to_bits(s[kClipCode]));
  const Float4 one = splat4(1.0f);
  const Float4 pull = select4(u > one, 1.0f / render_detail::sqrt4(select4(u > one, u, one)), one);
  const float cx = s[kCx], cy = s[kCy], cz = s[kCz];
  const Float4 px = select4(valid, cx + (px_ray - cx) * pull, splat4(cx));
  const Float4 py = select4(valid, cy + (py_ray - cy) * pull, splat4(cy));
  const Float4 pz = select4(valid, cz + (t - cz) * pull, splat4(cz));
  return render_detail::clip_discard4(
      planes + 4 * static_cast<std::size_t>(float_to_bits(s[kClipFirst])), clip_count(code),
      clip_mode(code), px, py, pz);
}

// One splat over its pixels in the band. Visibility pass (kAccumulate false): B = min(B, bound)
// over covered lanes. Accumulation pass: lanes with key <= B add their weighted attributes, and
// with kNext, lanes with key > B lower the next surface's bound. kPeel: only lanes with key >
// lower (the previous surface's bound) take part. kFeat (Features): clipped lanes take no part;
// kFindFront keeps each pixel's nearest fragment depth and its surface id; kSameSurface lets
// only fragments of that id (or of a mixed inner node, or any when the front is mixed) take
// part.
template <bool kAccumulate, bool kZRange, bool kPeel, bool kNext, int kFeat>
void draw_splat(const float* s, const float* planes, const View& v, const Band& band) {
  const int i0 = static_cast<int>(s[kI0]), i1 = static_cast<int>(s[kI1]);
  const int j0 = std::max(static_cast<int>(s[kJ0]), band.row0);
  const int j1 = std::min(static_cast<int>(s[kJ1]), band.row1 - 1);
  const Float4 lane{0.0f, 1.0f, 2.0f, 3.0f};
  const float nx = s[kNx], ny = s[kNy], nz = s[kNz], nc = s[kNc];
  const float cx = s[kCx], cy = s[kCy], cz = s[kCz], inv_r2 = s[kInvR2];
  const float lo = s[kDepthLo], hi = s[kDepthHi];
  const Float4 one = splat4(1.0f), zero = splat4(0.0f), inf = splat4(kInf);
  for (int k = i0 >> 2; k <= (i1 >> 2); ++k) {
    if constexpr (kFeat == kFindFront) {
      if (band.tiles[k >> kTileShift] != kMultiTile) continue;
    }
    const Float4 iv = static_cast<float>(k * kLanes) + lane;
    const Int4 in_box = (iv >= static_cast<float>(i0)) & (iv <= static_cast<float>(i1));
    const Float4 pcx = iv + 0.5f;
    const Float4 a = (pcx - v.half_w) * v.inv_f;
    const Float4 dx = pcx - s[kSx];
    const Float4 dx2 = dx * dx;
    const Float4 na = nx * a + nz;
    for (int j = j0; j <= j1; ++j) {
      const float pcy = static_cast<float>(j) + 0.5f;
      const float b = (v.half_h - pcy) * v.inv_f;
      const float dy = pcy - s[kSy];
      // Where the pixel's ray meets the splat's plane: (X, Y, t) in eye space, t the depth.
      Float4 t, X, Y;
      ray_hits(v.ortho, a, na, b, nx, ny, nz, nc, t, X, Y);
      const Int4 valid = (t > zero) & (t < inf);
      const Float4 ex = X - cx, ey = Y - cy, ez = t - cz;
      const Float4 u = (ex * ex + ey * ey + ez * ez) * inv_r2;
      const Float4 sd = (dx2 + dy * dy) * v.inv_rho2;
      const Float4 m = select4(valid, min4(sd, u), sd);
      Int4 cover = in_box & (m <= one);
      if (!any4(cover)) continue;
      if constexpr (kFeat != kNoFeatures) {
        if (float_to_bits(s[kClipCode]) & 31u) {
          const Int4 cut = cover & clipped_lanes(s, planes, t, X, Y, u, valid);
          // Counted once a frame: in the visibility pass (the front-surface pass skips
          // columns), or the first pass of the layered rule.
          if (!kAccumulate && (kFeat == kSameSurface || kFeat == kClipOnly)) {
            *band.clipped += render_detail::lane_count(cut);
            if (band.clip_mask != nullptr && any4(cut)) {
              render_detail::mark_lanes(band.clip_mask, band.width, cut, k * kLanes, j);
            }
          }
          cover &= ~cut;
          if (!any4(cover)) continue;
        }
      }
      if constexpr (kFeat == kFindFront) {
        float* ids = band.ids_at(j, k);
        const Float4 frag = min4(splat4(hi), max4(splat4(lo), select4(valid, t, splat4(cz))));
        const Float4 front = load4(ids + kFrontDepth * kLanes);
        const Int4 closer = cover & (frag < front);
        store4(ids + kFrontDepth * kLanes, select4(closer, frag, front));
        Int4 id;
        std::memcpy(&id, ids + kFrontId * kLanes, sizeof id);
        const std::int32_t mine = static_cast<std::int32_t>(float_to_bits(s[kSurface]));
        id = select4(closer, Int4{} + mine, id);
        std::memcpy(ids + kFrontId * kLanes, &id, sizeof id);
        continue;
      }
      Int4 other{};  // accumulation with features: lanes whose front is another surface
      if constexpr (kFeat == kSameSurface) {
        Int4 id;
        std::memcpy(&id, band.ids_at(j, k) + kFrontId * kLanes, sizeof id);
        const std::int32_t mine = static_cast<std::int32_t>(float_to_bits(s[kSurface]));
        if (mine != kMixedId) {
          const Int4 same = (id == mine) | (id == kMixedId);
          if constexpr (kAccumulate) {
            other = cover & ~same;
            *band.other_surface += render_detail::lane_count(other);
          }
          cover &= same;
        }
        if (!any4(cover) && !any4(other)) continue;
      }
      float* acc = band.acc_at(j, k);
      float* layer = kPeel || kNext ? band.layer_at(j, k) : nullptr;
      Float4 depth{}, key, bound;
      if constexpr (kZRange) {
        key = splat4(s[kKey]);
        bound = splat4(s[kBound]);
        if constexpr (kAccumulate) depth = min4(splat4(hi), max4(splat4(lo), select4(valid, t, splat4(cz))));
      } else {
        depth = min4(splat4(hi), max4(splat4(lo), select4(valid, t, splat4(cz))));
        key = depth;
        bound = depth + s[kBound];
      }
      if constexpr (kPeel) cover &= key > load4(layer + kLower * kLanes);
      const Float4 old_b = load4(acc + kSumBound * kLanes);
      if constexpr (!kAccumulate) {
        store4(acc + kSumBound * kLanes, select4(cover & (bound < old_b), bound, old_b));
        continue;
      }
      if constexpr (kFeat == kSameSurface) {
        // A fragment of another surface within the front surface's depth window: without the
        // per-surface rule it would have blended in. Such pixels are marked (front depth −∞,
        // no longer needed after the front pass) and counted after the band's accumulation.
        const Int4 stopped = other & (key <= old_b);
        if (any4(stopped)) {
          float* front = band.ids_at(j, k) + kFrontDepth * kLanes;
          store4(front, select4(stopped, splat4(-kInf), load4(front)));
        }
        if (!any4(cover)) continue;
      }
      if constexpr (kNext) {
        const Int4 behind = cover & (key > old_b);
        const Float4 next = load4(layer + kNext * kLanes);
        store4(layer + kNext * kLanes, select4(behind & (bound < next), bound, next));
      }
      const Int4 take = cover & (key <= old_b);
      if (!any4(take)) continue;
      const Float4 w = select4(take, exp_neg4(m * v.kernel_k), zero);
      const auto add = [&](int plane, Float4 value) {
        store4(acc + plane * kLanes, load4(acc + plane * kLanes) + value);
      };
      add(kSumW, w);
      add(kSumDepth, w * depth);
      add(kSumR, w * s[kBaseR]);
      add(kSumG, w * s[kBaseG]);
      add(kSumB, w * s[kBaseB]);
      add(kSumNx, w * s[kWx]);
      add(kSumNy, w * s[kWy]);
      add(kSumNz, w * s[kWz]);
    }
  }
}

// The surface rule's first look at a band: which tile columns several surfaces reach.
void mark_tiles(const float* s, const float*, const View&, const Band& band) {
  const std::uint32_t id = float_to_bits(s[kSurface]);
  if (id == kMixedSurface) return;
  const int i0 = static_cast<int>(s[kI0]), i1 = static_cast<int>(s[kI1]);
  if (i1 < i0) return;
  const int shift = kTileShift + 2;  // pixels -> tile columns
  for (int t = i0 >> shift; t <= (i1 >> shift); ++t) {
    std::uint32_t& tile = band.tiles[t];
    tile = tile == kEmptyTile || tile == id ? id : kMultiTile;
  }
}

using DrawFn = void (*)(const float*, const float*, const View&, const Band&);

template <bool kAccumulate, bool kPeel, bool kNext, int kFeat = kNoFeatures>
DrawFn pick(bool z_range) {
  return z_range ? &draw_splat<kAccumulate, true, kPeel, kNext, kFeat>
                 : &draw_splat<kAccumulate, false, kPeel, kNext, kFeat>;
}

// Calls draw for every splat binned into band `b`, chunk by chunk in stream order.
// The splats of band b, in stream order or, with `pieces`, piece by piece (a chunk's bin of a
// band lists its splats in ascending order, so a piece is a contiguous run of it).
struct PassOrder {
  std::size_t chunks = 0;
  const std::span<const StreamPiece>* pieces = nullptr;
};

void band_pass(const PassOrder& order, const QualityScratch& scratch, std::size_t b,
               std::size_t band_count, const View& v, const Band& band, DrawFn draw) {
  const auto run = [&](std::size_t c, std::uint32_t begin, std::uint32_t end) {
    const std::vector<std::uint32_t>& bins = scratch.chunk_bins[c];
    const std::uint32_t* index = bins.data() + band_count + 1;
    const float* splats = scratch.chunk_splats[c].data();
    const float* planes = scratch.chunk_planes[c].data();
    const std::uint32_t* k = index + bins[b];
    const std::uint32_t* last = index + bins[b + 1];
    if (begin > 0) k = std::lower_bound(k, last, begin);
    for (; k < last && *k < end; ++k) {
      draw(splats + static_cast<std::size_t>(kStride) * *k, planes, v, band);
    }
  };
  if (order.pieces) {
    for (const StreamPiece& p : *order.pieces) run(p.chunk, p.begin, p.end);
    return;
  }
  for (std::size_t c = 0; c < order.chunks; ++c) run(c, 0, UINT32_MAX);
}

void clear_planes(const Band& band, bool layered, bool ids) {
  const std::size_t groups = static_cast<std::size_t>(band.row1 - band.row0) * band.groups;
  for (std::size_t g = 0; g < groups; ++g) {
    float* acc = band.acc + g * kGroupFloats;
    std::fill(acc, acc + kLanes, kInf);
    std::fill(acc + kLanes, acc + kGroupFloats, 0.0f);
    if (ids) {
      float* id = band.ids + g * kIdFloats;
      std::fill(id + kFrontDepth * kLanes, id + (kFrontDepth + 1) * kLanes, kInf);
      std::fill(id + kFrontId * kLanes, id + (kFrontId + 1) * kLanes,
                bits_to_float(kMixedSurface));
    }
    if (layered) {
      float* layer = band.layer + g * kLayerFloats;
      std::fill(layer + kLower * kLanes, layer + (kLower + 1) * kLanes, -kInf);
      std::fill(layer + kNext * kLanes, layer + (kNext + 1) * kLanes, kInf);
      std::fill(layer + kOutR * kLanes, layer + kTransmit * kLanes, 0.0f);
      std::fill(layer + kTransmit * kLanes, layer + (kTransmit + 1) * kLanes, 1.0f);
    }
  }
}

// Pixels of the band where the per-surface rule kept another surface out of the blend (marked
// by the accumulation pass: front depth −∞).
std::uint64_t count_switches(const Band& band) {
  const std::size_t groups = static_cast<std::size_t>(band.row1 - band.row0) * band.groups;
  std::uint64_t count = 0;
  for (std::size_t g = 0; g < groups; ++g) {
    const float* front = band.ids + g * kIdFloats + kFrontDepth * kLanes;
    for (int l = 0; l < kLanes; ++l) count += front[l] == -kInf;
  }
  return count;
}

// Moves on to the next surface: lower = B, B = next, next = +inf, sums = 0.
void next_surface(const Band& band) {
  const std::size_t groups = static_cast<std::size_t>(band.row1 - band.row0) * band.groups;
  for (std::size_t g = 0; g < groups; ++g) {
    float* acc = band.acc + g * kGroupFloats;
    float* layer = band.layer + g * kLayerFloats;
    std::copy(acc + kSumBound * kLanes, acc + (kSumBound + 1) * kLanes, layer + kLower * kLanes);
    std::copy(layer + kNext * kLanes, layer + (kNext + 1) * kLanes, acc + kSumBound * kLanes);
    std::fill(layer + kNext * kLanes, layer + (kNext + 1) * kLanes, kInf);
    std::fill(acc + kLanes, acc + kGroupFloats, 0.0f);
  }
}

void rasterize(const SplatStream& stream, const std::span<const StreamPiece>* pieces,
               const CameraFrame& camera, const RenderSettings& settings,
               const QualitySettings& quality, ThreadPool& pool, QualityScratch& scratch,
               std::span<Rgb8> color, std::span<float> depth) {
  [[maybe_unused]] const std::size_t pixels =
      static_cast<std::size_t>(camera.width) * static_cast<std::size_t>(camera.height);
  assert(color.size() == pixels && depth.size() == pixels);
  validate_quality_settings(quality);
  const render_detail::Shader shader(settings, camera);
  const bool layered = quality.opacity < 1.0f;
  const SetupConstants setup =
      quality_setup(camera, settings, quality, stream.has_colors, pool.thread_count());
  const bool features = stream.has_features;
  if (!pieces) {
    fit_chunks(scratch, stream.chunk_count);
    pool.run(stream.chunk_count, [&](std::size_t c) {
      prepare_chunk(stream.chunks[c], setup, features, scratch.chunk_splats[c],
                    scratch.chunk_bins[c], scratch.chunk_planes[c]);
    });
  }
  const PassOrder stream_order{stream.chunk_count, pieces};

  View v;
  v.half_w = 0.5f * static_cast<float>(camera.width);
  v.half_h = 0.5f * static_cast<float>(camera.height);
  v.inv_f = 1.0f / camera.focal_px;
  v.ortho = camera.ortho;
  v.inv_rho2 = 1.0f / (quality.lowpass_radius_px * quality.lowpass_radius_px);
  v.kernel_k = 0.5f / (quality.kernel_sigma * quality.kernel_sigma);
  const BandShader band_shader(shader, camera, v, settings.background,
                               layered ? quality.opacity : 1.0f);
  const bool z_range = setup.rule.z_range;
  const Output out{color, depth, camera.width};

  const int groups = (camera.width + kLanes - 1) / kLanes;
  const std::size_t band_groups = static_cast<std::size_t>(setup.band_rows) * groups;
  // Opaque rendering with features finds each pixel's front surface first (spec §1.12: the
  // exact order-independent rule in three passes); layered rendering only clips.
  const bool surface_rule = features && !layered;
  const std::size_t buffer_floats =
      band_groups * (kGroupFloats + (layered ? kLayerFloats : 0) + (surface_rule ? kIdFloats : 0));
  const std::size_t workers =
      std::min<std::size_t>(pool.thread_count(), static_cast<std::size_t>(setup.band_count));
  if (scratch.band_buffers.size() < workers) scratch.band_buffers.resize(workers);
  const std::size_t tile_count = (static_cast<std::size_t>(groups) >> kTileShift) + 1;
  if (surface_rule) {
    if (scratch.band_tiles.size() < workers) scratch.band_tiles.resize(workers);
    for (std::size_t w = 0; w < workers; ++w) scratch.band_tiles[w].resize(tile_count);
  }
  for (std::size_t w = 0; w < workers; ++w) {
    if (scratch.band_buffers[w].size() < buffer_floats) scratch.band_buffers[w].resize(buffer_floats);
  }
  // Pixels that clipping emptied are marked, and the narrow gaps among them filled after.
  const bool fill_pinholes = surface_rule && !depth.empty();
  if (fill_pinholes) {
    scratch.clip_mask.assign(static_cast<std::size_t>(camera.width) * camera.height, 0);
  }
  const std::size_t band_count = static_cast<std::size_t>(setup.band_count);
  std::atomic<std::size_t> next_band{0};
  std::atomic<std::uint64_t> clipped{0}, other_surface{0}, switches{0};
  pool.run(workers, [&](std::size_t worker) {
    float* buffer = scratch.band_buffers[worker].data();
    std::uint64_t clipped_here = 0, other_here = 0, switch_here = 0;
    for (std::size_t b = next_band++; b < band_count; b = next_band++) {
      const int row0 = static_cast<int>(b) * setup.band_rows;
      const Band band{row0,
                      std::min(camera.height, row0 + setup.band_rows),
                      groups,
                      buffer,
                      buffer + band_groups * kGroupFloats,
                      buffer + band_groups * (kGroupFloats + (layered ? kLayerFloats : 0)),
                      &clipped_here,
                      &other_here,
                      surface_rule ? scratch.band_tiles[worker].data() : nullptr,
                      fill_pinholes ? scratch.clip_mask.data() : nullptr,
                      camera.width};
      clear_planes(band, layered, surface_rule);
      if (surface_rule) {
        std::fill(band.tiles, band.tiles + tile_count, kEmptyTile);
        band_pass(stream_order, scratch, b, band_count, v, band, &mark_tiles);
        band_pass(stream_order, scratch, b, band_count, v, band,
                  pick<false, false, false, kFindFront>(z_range));
        band_pass(stream_order, scratch, b, band_count, v, band,
                  pick<false, false, false, kSameSurface>(z_range));
        band_pass(stream_order, scratch, b, band_count, v, band,
                  pick<true, false, false, kSameSurface>(z_range));
        switch_here += count_switches(band);
        band_shader.shade<false>(band, out, true);
        continue;
      }
      band_pass(stream_order, scratch, b, band_count, v, band,
                features ? pick<false, false, false, kClipOnly>(z_range)
                         : pick<false, false, false>(z_range));
      if (!layered) {
        band_pass(stream_order, scratch, b, band_count, v, band, pick<true, false, false>(z_range));
        band_shader.shade<false>(band, out, true);
        continue;
      }
      for (int surface = 0; surface < quality.max_layers; ++surface) {
        const bool last = surface + 1 == quality.max_layers;
        DrawFn draw =
            features
                ? (surface == 0 ? (last ? pick<true, false, false, kClipOnly>(z_range)
                                        : pick<true, false, true, kClipOnly>(z_range))
                                : (last ? pick<true, true, false, kClipOnly>(z_range)
                                        : pick<true, true, true, kClipOnly>(z_range)))
                : (surface == 0 ? (last ? pick<true, false, false>(z_range)
                                        : pick<true, false, true>(z_range))
                                : (last ? pick<true, true, false>(z_range)
                                        : pick<true, true, true>(z_range)));
        band_pass(stream_order, scratch, b, band_count, v, band, draw);
        const bool more = band_shader.shade<true>(band, out, surface == 0);
        if (last || !more) break;
        next_surface(band);
      }
      band_shader.finish_layers(band, out);
    }
    clipped += clipped_here;
    other_surface += other_here;
    switches += switch_here;
  });
  scratch.clipped_fragments = clipped;
  scratch.pinholes_filled =
      fill_pinholes && clipped > 0
          ? render_detail::fill_clipped_pinholes(color, depth, scratch.clip_mask, camera.width,
                                                 camera.height)
          : 0;
  scratch.other_surface_fragments = other_surface;
  scratch.surface_switch_pixels = switches;
}

}  // namespace

namespace quality_detail {

void rasterize_quality_pieces(const SplatStream& stream, std::span<const StreamPiece> pieces,
                              const CameraFrame& camera, const RenderSettings& settings,
                              const QualitySettings& quality, ThreadPool& pool,
                              QualityScratch& scratch, std::span<Rgb8> color,
                              std::span<float> depth) {
  assert(scratch.chunk_splats.size() >= stream.chunk_count);
  rasterize(stream, &pieces, camera, settings, quality, pool, scratch, color, depth);
}

}  // namespace quality_detail

void rasterize_quality(const SplatStream& stream, const CameraFrame& camera,
                       const RenderSettings& settings, const QualitySettings& quality,
                       ThreadPool& pool, QualityScratch& scratch, std::span<Rgb8> color,
                       std::span<float> depth) {
  rasterize(stream, nullptr, camera, settings, quality, pool, scratch, color, depth);
}

}  // namespace pointillist
