// High-quality surface splatting: object-space discs with a Gaussian kernel, ray cast per pixel
// (perspective correct), a screen-space low-pass so minified splats neither alias nor break up,
// per-pixel reconstruction of the front surface (Z-threshold or Z-range), deferred Blinn-Phong
// shading of the blended normal, and optional front-to-back compositing of semi-transparent
// surfaces. The fast rasterizer (splat_raster.hpp) is the other mode; both consume the same
// SplatStream.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "pointillist/core/camera.hpp"
#include "pointillist/core/math.hpp"
#include "pointillist/core/thread_pool.hpp"
#include "pointillist/lod/sphere_tree.hpp"
#include "pointillist/render/render.hpp"
#include "pointillist/render/settings.hpp"
#include "pointillist/render/splat_stream.hpp"

namespace pointillist {

// How a pixel decides which of its fragments belong to the front surface. Both rules have the
// same form: every fragment has an interval [key, bound] in depth; with B the smallest bound of
// the pixel's fragments, the fragments with key <= B form the front surface (the fragment with
// the smallest key always belongs to it). The result does not depend on the order of fragments.
enum class Reconstruction {
  // Zwicker et al. 2001 / Botsch et al. 2004: key = the fragment's depth at the pixel,
  // bound = depth + z_threshold·radius. Fragments within ε of the front one are blended.
  ZThreshold,
  // Räsänen 2002: key, bound = the splat's depth interval [depth_min, depth_max] widened by
  // z_range_margin·radius on both sides. Fragments whose interval overlaps the interval that
  // ends first are blended.
  ZRange,
};

// Every splat is the disc of its node: centre and normal of the node, radius R = radius_scale ×
// the node's radius ("the splat radius" below).
struct QualitySettings {
  Reconstruction reconstruction = Reconstruction::ZRange;
  // Z-threshold ε in splat radii (ε = z_threshold·R, so it scales with the level of detail).
  // Raise it when one curved or noisy surface shows seams where fragments fail to blend; lower
  // it when a surface behind a close one bleeds through. > 0.
  float z_threshold = 1.0f;
  // Z-range: margin added on both sides of each splat's depth interval, in splat radii. A disc
  // facing the eye has an interval of zero width; the margin lets neighbouring discs of a curved
  // or noisy surface overlap. Two parallel surfaces facing the eye separate when their gap
  // exceeds 2·margin·R; tilted by α, the intervals of discs that both cover a pixel can reach
  // 2R·sin α further, so a gap above 2R·(2·sin α + margin)·cos α (at most 2.74 R for margin
  // 0.5) always separates. >= 0.
  float z_range_margin = 0.5f;
  // Disc radius R over the node's radius, in [1, 2]. Radii made for eye-facing circles (QSplat's
  // mesh rule: the circumradius of the largest incident triangle) can fall a few percent short
  // when the disc lies in the vertex's tangent plane and the surface bends: on the dragon at
  // 1280×720, 1.0 leaves 1–2 pinholes per view, 1.05 none; 1.1 keeps a margin.
  float radius_scale = 1.1f;
  // Gaussian kernel exp(−½·(d/σ)²), d the distance from the disc's centre in its plane, cut at
  // the disc's edge d = R: σ = kernel_sigma·R (weight at the edge exp(−1/(2·kernel_sigma²)),
  // 0.135 for 0.5). Smaller gives crisper blends (more like flat discs), larger smoother ones.
  // In [0.1, 4].
  float kernel_sigma = 0.5f;
  // Screen-space low-pass (the "max" approximation of EWA resampling, Botsch et al. 2005): a
  // pixel also receives a splat's fragment when its centre is within this radius (pixels) of
  // the splat's projected centre; the kernel is evaluated at the smaller of the two normalised
  // distances (d/R and pixel distance/lowpass_radius_px), so the screen filter's standard
  // deviation is kernel_sigma × lowpass_radius_px. Every splat covers at least this disc: at
  // least √½ ≈ 0.71 px reaches a pixel centre wherever the splat projects (no break-up when
  // minified); larger values blur and widen silhouettes. In [0.5, 16].
  float lowpass_radius_px = 0.75f;
  // Opacity A of every reconstructed surface, in (0, 1]. Below 1, up to max_layers surfaces per
  // pixel are reconstructed front to back and composited: color = Σ_k A·(1−A)^k·c_k +
  // (1−A)^L·background, L = the number of surfaces found (at most max_layers; surfaces behind
  // the last are ignored). Each extra layer costs one more pass over the band's splats.
  float opacity = 1.0f;
  int max_layers = 4;  // surfaces composited per pixel when opacity < 1; in [1, 16]
};

// Throws OptionError naming the field when a value is out of the documented range.
void validate_quality_settings(const QualitySettings& quality);

// One splat's contribution at one pixel (what the rasterizer computes; tests build them by hand).
struct Fragment {
  float depth = 0;      // eye-space depth where the pixel's ray meets the splat (world units)
  float depth_min = 0;  // the splat's depth interval over its whole disc (world units), ZRange
  float depth_max = 0;
  float radius = 0;     // the splat's radius R (world units; scales z_threshold, z_range_margin)
  float weight = 0;     // kernel weight, > 0
  Vec3f normal;         // unit normal, world space
  Vec3f base_color;     // linear 0..1 (node color / 255, or RenderSettings::base_color)
  std::uint32_t node = 0;  // index of the splat's node in the tree (for clipping, surface ids)
};

// A surface reconstructed at one pixel: the normalised weighted mean of its fragments.
struct ReconstructedSurface {
  float weight = 0;      // sum of the fragments' weights (> 0)
  float depth = 0;       // Σ w·depth / Σ w
  Vec3f base_color;      // Σ w·color / Σ w
  Vec3f normal;          // normalize(Σ w·n); the front fragment's normal when the sum is 0
  std::uint32_t fragment_count = 0;
  std::uint32_t front_node = 0;  // node of the fragment with the smallest key (the first on ties)
};

// The surfaces of one pixel, front to back (at most `max_surfaces`; fewer when the fragments run
// out): surface 1 is the front surface of all fragments by quality.reconstruction (see
// Reconstruction), surface k+1 the front surface of the fragments left after removing those of
// surfaces 1..k. The rasterizer applies the same rule to the fragments of each pixel, summing in
// stream order. Throws OptionError for invalid settings.
std::vector<ReconstructedSurface> reconstruct_pixel(std::span<const Fragment> fragments,
                                                    const QualitySettings& quality,
                                                    int max_surfaces = 1);

// Work buffers of the quality rasterizer, kept across frames so that steady-state frames do not
// allocate. Contents between calls are unspecified.
struct QualityScratch {
  std::vector<std::vector<float>> chunk_splats;         // per-splat setup, one array per chunk
  std::vector<std::vector<std::uint32_t>> chunk_bins;  // per chunk: its splats by band of rows
  std::vector<std::vector<float>> chunk_planes;        // per chunk: clip planes, eye space
  std::vector<std::vector<float>> band_buffers;        // per-pixel accumulators, one per worker
  std::vector<std::vector<std::uint32_t>> band_tiles;  // sharp features: surfaces per column
  std::vector<std::uint8_t> clip_mask;  // sharp features: pixels where clipping discarded some
  // The last frame's counts (RenderStats::clipped_fragments, other_surface_fragments,
  // surface_switch_pixels, clip_pinholes_filled).
  std::uint64_t clipped_fragments = 0, other_surface_fragments = 0, surface_switch_pixels = 0;
  std::uint64_t pinholes_filled = 0;
};

// Draws `stream` (selected for `camera`) into color and depth (width × height of the camera, rows
// top to bottom), reading nothing but the stream. Every splat is its disc (centre c, normal n,
// radius R = radius_scale × the stream's radius) with the Gaussian kernel of `quality`; for pixel centre
// (i + ½, j + ½) the eye ray
// t·(a, b, 1) in eye coordinates (x right, y up, z = depth), a = (i + ½ − W/2)/f,
// b = (H/2 − j − ½)/f, meets the disc's plane at depth t = (n·c)/(n·(a, b, 1)) (Botsch et al.
// 2004); with u = |t·(a, b, 1) − c|²/R² (+∞ unless t > 0) and s = squared pixel distance to
// the projected centre / lowpass_radius_px², the pixel gets a fragment when m = min(u, s) <= 1,
// of weight exp(−m/(2·kernel_sigma²)) and depth t clamped to the disc's depth interval
// c_z ± R·√(1 − n_z²) (the centre depth when t is not > 0). Pixels then reconstruct their front surface (or up to
// max_layers surfaces), normalise the weighted colors and normals and shade them with
// RenderSettings' Blinn-Phong model (view vector along the pixel's ray; the normal falls back to
// the view vector where the weighted normals cancel). Depth receives the
// front surface's weighted depth (+infinity where nothing was drawn); color the background
// there. The image bits do not depend on pool.thread_count(): bands of rows are drawn in
// parallel, each visiting its splats in stream order. Throws OptionError for invalid settings.
void rasterize_quality(const SplatStream& stream, const CameraFrame& camera, const RenderSettings& settings,
                       const QualitySettings& quality, ThreadPool& pool, QualityScratch& scratch,
                       std::span<Rgb8> color, std::span<float> depth);

// select_splats, then rasterize_quality, into `frame` (resized as needed; frame.splats holds
// the stream, frame.stats the counts and times as for render()). Throws OptionError for an
// invalid camera, threshold, light, shininess or quality setting.
void render_quality(const SphereTreeView& tree, const Camera& camera,
                    const RenderSettings& settings, const QualitySettings& quality,
                    ThreadPool& pool, Frame& frame, QualityScratch& scratch);
// The same with scratch buffers allocated for this call only.
void render_quality(const SphereTreeView& tree, const Camera& camera,
                    const RenderSettings& settings, const QualitySettings& quality,
                    ThreadPool& pool, Frame& frame);

}  // namespace pointillist
