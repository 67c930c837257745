// What every render entry point does around selection and rasterization: size the frame for the
// camera, and fill its statistics from the selection counts and the three time points.
#pragma once

#include <chrono>
#include <cstddef>

#include "pointillist/render/render.hpp"
#include "pointillist/render/selection.hpp"

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

}  // namespace pointillist::render_detail
