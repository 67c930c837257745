// The occluder pass of occlusion culling in quality mode (shared/specs/
// occlusion-simplification-hybrid.md §1.7). The quality rasterizer blends, at each pixel, the
// fragments whose key is within the smallest bound B of the pixel's fragments (Reconstruction),
// so a hidden node is one whose every fragment has a key beyond B. The depth the queries test is
// therefore not the blended depth but an upper bound U on B: each drawn splat lowers U, at the
// pixels where the rasterizer is certain to give it a fragment, to the largest bound that
// fragment can have.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "pointillist/core/camera.hpp"
#include "pointillist/core/thread_pool.hpp"
#include "pointillist/render/occlusion.hpp"
#include "pointillist/render/quality.hpp"
#include "pointillist/render/settings.hpp"
#include "pointillist/render/splat_stream.hpp"
#include "raster/quality_kernel.hpp"

namespace pointillist::quality_detail {

// Work buffers of the occluder pass, kept across batches and frames.
struct OccluderScratch {
  std::vector<SoftwareQueries::Rect> band_rects;
};

// Lowers `bound` (eye depth per pixel, rows top to bottom, the camera's size; +∞ where nothing
// was drawn) with the splats of chunks [first, last) of `stream` (opaque surfaces, no sharp
// features): at every pixel where rasterize_quality is certain to give a splat a fragment (its
// kernel argument within 1 − 1e-3 of the disc or low-pass edge), to the largest bound that
// fragment can have (ZRange: the splat's widened interval's end; ZThreshold: its deepest depth
// plus ε·R). The smallest bound of a pixel's fragments is then never above `bound`. The chunks'
// setup is left in `prepared` as rasterize_quality_pieces expects it (quality_kernel.hpp).
// Returns the rectangle of pixels lowered, [x0, x1) × [y0, y1) (empty when none). Without
// `occluders` (nothing will test them), only the setup is made.
SoftwareQueries::Rect draw_quality_occluders(const SplatStream& stream, std::size_t first,
                                             std::size_t last, const CameraFrame& camera,
                                             const RenderSettings& settings,
                                             const QualitySettings& quality, ThreadPool& pool,
                                             QualityScratch& prepared, OccluderScratch& scratch,
                                             std::span<float> bound, bool occluders = true);

// The footprint a query must assume of a node's splats in quality mode: every disc lies within
// the node's sphere grown by radius_scale (and the splat scale), covers the low-pass disc, and
// its fragments' keys reach (1 + margin) disc radii in front of the centre (ZRange) or one
// (ZThreshold).
QueryFootprint quality_query_footprint(const QualitySettings& quality, float splat_scale);

}  // namespace pointillist::quality_detail
