// Z-buffered software splat rasterizer: draws a splat stream into color and depth buffers.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "pointillist/core/buffer.hpp"
#include "pointillist/core/camera.hpp"
#include "pointillist/core/thread_pool.hpp"
#include "pointillist/render/settings.hpp"
#include "pointillist/render/splat_stream.hpp"

namespace pointillist {

// Per-chunk work buffers of the rasterizer, kept across frames so that steady-state frames do not
// allocate. The contents between calls are unspecified.
struct RasterScratch {
  struct Chunk {
    Buffer<float> ellipse;  // 6 floats per splat (Ellipse shape only)
    float y_min_px = 0, y_max_px = 0;  // rows the chunk's splats may touch (several bands only)
    std::vector<float> planes;  // sharp features: the chunk's clip planes, eye coordinates
    const CameraFrame* camera = nullptr;  // the frame's camera (sharp features)
  };
  std::vector<Chunk> chunks;
  std::vector<Buffer<std::uint32_t>> band_colors;  // one packed-color band per thread
  Buffer<std::uint32_t> image;   // per pixel: packed colour, drawing in several batches
  Buffer<float> log_depth;       // eye-dome lighting: log2 of each pixel's depth
  std::uint64_t clipped_fragments = 0;  // the last frame's (RenderStats::clipped_fragments)
  // Sharp features: the pixels where a clip plane discarded a covered pixel this frame, and
  // how many empty ones among them were filled (fill_clipped_pinholes).
  std::vector<std::uint8_t> clip_mask;
  bool clip_mask_active = false;
  std::uint64_t pinholes_filled = 0;
};

// Clears color to settings.background and depth to +infinity, then draws every splat of
// `stream` (positions and sizes in pixels of `camera`'s image, which must be color's and depth's
// width × height) with a depth test on the splat's centre depth; at equal depth the smaller
// packed colour (r | g << 8 | b << 16) wins. Each pixel thus shows the minimum of (depth, colour)
// over the splats covering it: the image depends on the set of splats, not on their order in
// the stream (occlusion culling draws them in another order and must give the same bits). Pixels are unit squares with centres at (i + 0.5, j + 0.5);
// a splat covers the pixels whose centre lies inside its shape (closed), and a splat covering no
// centre covers the pixel that contains its centre:
//  * Square: |px − x| ≤ d/2 and |py − y| ≤ d/2, d = size_px;
//  * Circle: (px − x)² + (py − y)² ≤ (d/2)²;
//  * Ellipse: semi-major axis d/2, semi-minor axis (d/2)·max(|n·v|, 0.1) along the screen
//    projection of the normal n (v: unit vector from the splat to the eye).
// When the stream has_features, a splat with clip planes skips the pixels whose ray meets its
// plane (its centre, where the ray misses the plane) on the side its planes discard (one plane
// test per covered pixel and plane; features.hpp clip_discards).
// Splats are drawn in their `shaded` color. The image bits depend only on the arguments, not
// on pool.thread_count(): rows are split into bands, and each band draws the splats that may
// touch it in stream order.
void rasterize_splats(const SplatStream& stream, const CameraFrame& camera,
                      const RenderSettings& settings, ThreadPool& pool, RasterScratch& scratch,
                      std::span<Rgb8> color, std::span<float> depth);

// The same drawing in batches (occlusion culling draws, tests depths, and draws more):
// begin_splats clears the image held in `scratch` and `depth`; draw_splats draws chunks
// [first_chunk, end_chunk) of `stream` over what is there; finish_splats writes the colours
// (and, with sharp features, fills the pinholes clipping opened, as rasterize_splats does).
// Drawing a stream in any split into batches and any order of its chunks gives the image of
// rasterize_splats over the whole stream. scratch.clipped_fragments sums the batches.
void begin_splats(const CameraFrame& camera, const RenderSettings& settings, ThreadPool& pool,
                  RasterScratch& scratch, std::span<float> depth);
void draw_splats(const SplatStream& stream, std::size_t first_chunk, std::size_t end_chunk,
                 const CameraFrame& camera, const RenderSettings& settings, ThreadPool& pool,
                 RasterScratch& scratch, std::span<float> depth);
void finish_splats(const CameraFrame& camera, ThreadPool& pool, RasterScratch& scratch,
                   std::span<Rgb8> color, std::span<float> depth);

}  // namespace pointillist
