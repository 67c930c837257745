// The one frame pass every render entry point runs: size the frame for the camera, select into
// its stream, rasterize the stream with the fast or the quality rasterizer, and fill its
// statistics (counts and the three time points). The entry points differ only in how they
// select.
#pragma once

#include <chrono>
#include <cstddef>

#include "pointillist/render/quality.hpp"
#include "pointillist/render/render.hpp"
#include "pointillist/render/selection.hpp"
#include "pointillist/render/splat_raster.hpp"

namespace pointillist::render_detail {

using Clock = std::chrono::steady_clock;

// Resizes frame's images to the camera's size.
inline void size_frame(Frame& frame, const CameraFrame& cam) {
  const std::size_t pixels =
      static_cast<std::size_t>(cam.width) * static_cast<std::size_t>(cam.height);
  frame.width = cam.width;
  frame.height = cam.height;
  frame.color.resize(pixels);
  frame.depth.resize(pixels);
}

// frame.stats from the selection's counts and the times selection started, ended, and
// rasterization ended.
inline void fill_stats(Frame& frame, const SelectionStats& selection, const CameraFrame& cam,
                       unsigned threads, Clock::time_point start, Clock::time_point selected,
                       Clock::time_point done) {
  const auto ms = [](Clock::time_point a, Clock::time_point b) {
    return std::chrono::duration<double, std::milli>(b - a).count();
  };
  RenderStats& s = frame.stats;
  s = {};
  s.splats = selection.splats;
  s.nodes_visited = selection.nodes_visited;
  s.culled_frustum = selection.culled_frustum;
  s.culled_backface = selection.culled_backface;
  s.width = cam.width;
  s.height = cam.height;
  s.threads = threads;
  s.ms_select = ms(start, selected);
  s.ms_raster = ms(selected, done);
  s.ms_total = ms(start, done);
}

// Runs the pass: `select(cam, stream)` fills frame.splats (with_discs already set: true for the
// quality rasterizer, which reads the discs) and returns its counts; `quality` null draws with
// the fast rasterizer, otherwise with the quality one into `scratch`.
template <class Select>
void frame_pass(const Camera& camera, const RenderSettings& settings,
                const QualitySettings* quality, QualityScratch* scratch, ThreadPool& pool,
                Frame& frame, const Select& select) {
  const auto start = Clock::now();
  const CameraFrame cam = make_camera_frame(camera);
  size_frame(frame, cam);
  frame.splats.with_discs = quality != nullptr;
  frame.splats.has_features = false;  // set by a selection that attaches them
  const SelectionStats selection = select(cam, frame.splats);
  const auto selected = Clock::now();
  if (quality) {
    rasterize_quality(frame.splats, cam, settings, *quality, pool, *scratch, frame.color,
                      frame.depth);
  } else {
    rasterize_splats(frame.splats, cam, settings, pool, frame.scratch, frame.color, frame.depth);
  }
  fill_stats(frame, selection, cam, pool.thread_count(), start, selected, Clock::now());
  if (frame.splats.has_features) {
    RenderStats& s = frame.stats;
    for (std::size_t c = 0; c < frame.splats.chunk_count; ++c) {
      const SplatChunk& chunk = frame.splats.chunks[c];
      for (std::size_t i = 0; i < chunk.count; ++i) s.clipped_splats += clip_count(chunk.clip_code[i]) != 0;
    }
    s.clipped_fragments = quality ? scratch->clipped_fragments : frame.scratch.clipped_fragments;
    s.other_surface_fragments = quality ? scratch->other_surface_fragments : 0;
    s.surface_switch_pixels = quality ? scratch->surface_switch_pixels : 0;
    s.clip_pinholes_filled = quality ? scratch->pinholes_filled : frame.scratch.pinholes_filled;
  }
}

}  // namespace pointillist::render_detail
