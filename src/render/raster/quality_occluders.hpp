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

// With sharp features the quality rasterizer blends, at each pixel, only the surface of its
// front fragment F (the nearest unclipped one) and bounds the blend by F's own bound, so a sure
// fragment g no longer bounds B by g's bound: F, maybe drawn later, may reach further. But F is
// no deeper than g (depth_F ≤ depth_g ≤ g's deepest, hi_g), and F's bound lies at most
// W_F = width_per_radius · r_F behind its depth (r_F its node's radius): ZRange, the disc's
// depth interval (≤ 2 drawn radii) plus the margin; ZThreshold, ε drawn radii. r_F is at most
// the largest leaf radius of the scene, or, for an inner node the QSplat traversal draws at
// depth z, threshold·z/(2f − threshold·disc) (perspective; orthographic: threshold/(2f)). So
// B ≤ hi_g + W_max(hi_g) wherever an unclipped splat surely covers the pixel, and a node whose
// nearest key lies behind that everywhere can neither be the front nor blend in.
struct FeatureOccluderBound {
  bool active = false;
  float width_per_radius = 0;  // W_F over r_F (drawn radii per node radius times the rule's)
  float leaf_radius = 0;       // the largest leaf radius of any instance, eye units
  float radius_per_depth = 0;  // perspective: an inner node drawn at depth z has r ≤ this·z
  float inner_radius = 0;      // orthographic: an inner node drawn has r ≤ this
};

// The bound of a scene whose largest leaf radius (world units, instance scale included) is
// `leaf_radius`, its inner nodes drawn by the QSplat traversal at `threshold_px` through
// `camera`, with `quality`'s rule and disc scale and the splat scale.
FeatureOccluderBound feature_occluder_bound(const QualitySettings& quality, float splat_scale,
                                            float threshold_px, const CameraFrame& camera,
                                            float leaf_radius);

// Work buffers of the occluder pass, kept across batches and frames.
struct OccluderScratch {
  std::vector<SoftwareQueries::Rect> band_rects;
};

// Lowers `bound` (eye depth per pixel, rows top to bottom, the camera's size; +∞ where nothing
// was drawn) with the splats of chunks [first, last) of `stream` (opaque surfaces): at every pixel where rasterize_quality is certain to give a splat a fragment (its
// kernel argument within 1 − 1e-3 of the disc or low-pass edge), to the largest bound that
// fragment can have (ZRange: the splat's widened interval's end; ZThreshold: its deepest depth
// plus ε·R). The smallest bound of a pixel's fragments is then never above `bound`. A stream
// with sharp features needs `features` active: then only splats without clip planes lower the
// bound, to their deepest depth plus features' W_max there. The chunks'
// setup is left in `prepared` as rasterize_quality_pieces expects it (quality_kernel.hpp).
// Returns the rectangle of pixels lowered, [x0, x1) × [y0, y1) (empty when none). Without
// `occluders` (nothing will test them), only the setup is made.
SoftwareQueries::Rect draw_quality_occluders(const SplatStream& stream, std::size_t first,
                                             std::size_t last, const CameraFrame& camera,
                                             const RenderSettings& settings,
                                             const QualitySettings& quality, ThreadPool& pool,
                                             QualityScratch& prepared, OccluderScratch& scratch,
                                             std::span<float> bound, bool occluders = true,
                                             const FeatureOccluderBound& features = {});

// The footprint a query must assume of a node's splats in quality mode: every disc lies within
// the node's sphere grown by radius_scale (and the splat scale), covers the low-pass disc, and
// its fragments' keys reach (1 + margin) disc radii in front of the centre (ZRange) or one
// (ZThreshold).
QueryFootprint quality_query_footprint(const QualitySettings& quality, float splat_scale);

}  // namespace pointillist::quality_detail
