// Software splat renderer: QSplat traversal (selection) feeding a z-buffered splat rasterizer.
#pragma once

#include <cstdint>
#include <vector>

#include "pointillist/core/camera.hpp"
#include "pointillist/core/math.hpp"
#include "pointillist/core/thread_pool.hpp"
#include "pointillist/lod/sphere_tree.hpp"
#include "pointillist/render/occlusion.hpp"
#include "pointillist/render/selection.hpp"
#include "pointillist/render/settings.hpp"
#include "pointillist/render/splat_raster.hpp"
#include "pointillist/render/splat_stream.hpp"

namespace pointillist {

// Counts as in SelectionStats (selection.hpp).
struct RenderStats {
  std::uint64_t splats = 0;           // splats rasterized
  std::uint64_t triangles = 0;        // triangles rasterized (hybrid mode; after near clipping)
  std::uint64_t nodes_visited = 0;    // nodes whose sphere was tested
  std::uint64_t culled_frustum = 0;   // subtrees skipped outside the frustum (or nodes behind the eye)
  std::uint64_t culled_backface = 0;  // subtrees (or terminal nodes) skipped facing away
  // Sharp features (0 without them): splats drawn with clip planes; covered pixels their planes
  // discarded; and (quality mode) fragments left out of a pixel because another surface is in
  // front there (the per-surface rule), and the pixels where such a fragment lay within the
  // front surface's depth window, so that it would have blended in without the rule (where
  // the front surface switches between surfaces that touch or cross).
  std::uint64_t clipped_splats = 0;
  std::uint64_t clipped_fragments = 0;
  std::uint64_t other_surface_fragments = 0;
  std::uint64_t surface_switch_pixels = 0;
  // Empty pixels that clip planes emptied, in gaps of at most 2 pixels between covered ones,
  // filled from the nearest (clipping never opens a pinhole).
  std::uint64_t clip_pinholes_filled = 0;
  int width = 0, height = 0;
  unsigned threads = 1;
  double ms_select = 0, ms_raster = 0, ms_total = 0;  // wall clock (steady_clock)
  // Occlusion culling (FrameSettings::occlusion; zeros without it).
  OcclusionStats occlusion;
};

// The rendered image: 8-bit RGB color, rows top to bottom, and depth along the view direction
// (world units; +infinity where nothing was drawn). Buffers are reused across frames, so keep one
// Frame per view and pass it to every render call.
struct Frame {
  int width = 0, height = 0;
  // Written whole by every render (not zeroed when they grow: see core/buffer.hpp).
  Buffer<Rgb8> color;
  Buffer<float> depth;
  RenderStats stats;
  SplatStream splats;     // the splats drawn in this frame, in stream order
  RasterScratch scratch;  // rasterizer work buffers (contents unspecified)
};

// Renders the hierarchy seen by `camera` into `frame` (resized as needed): select_splats, then
// rasterize_splats. The image bits depend only on the arguments, never on pool.thread_count().
// Throws OptionError for an invalid camera, threshold, light direction or shininess.
void render(const SphereTreeView& tree, const Camera& camera, const RenderSettings& settings,
            ThreadPool& pool, Frame& frame);

}  // namespace pointillist
