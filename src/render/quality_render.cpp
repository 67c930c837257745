// The quality mode's entry point: selection, then the quality rasterizer, timed.
#include <chrono>

#include "pointillist/render/quality.hpp"

namespace pointillist {
namespace {

double ms_between(std::chrono::steady_clock::time_point a, std::chrono::steady_clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

}  // namespace

void render_quality(const SphereTreeView& tree, const Camera& camera,
                    const RenderSettings& settings, const QualitySettings& quality,
                    ThreadPool& pool, Frame& frame, QualityScratch& scratch) {
  const auto start = std::chrono::steady_clock::now();
  validate_quality_settings(quality);
  const CameraFrame cam = make_camera_frame(camera);
  const std::size_t pixels =
      static_cast<std::size_t>(cam.width) * static_cast<std::size_t>(cam.height);
  frame.width = cam.width;
  frame.height = cam.height;
  frame.color.resize(pixels);
  frame.depth.resize(pixels);

  SelectionStats selection;
  select_splats(tree, cam, settings, pool, frame.splats, selection);
  const auto selected = std::chrono::steady_clock::now();
  rasterize_quality(frame.splats, tree, cam, settings, quality, pool, scratch, frame.color,
                    frame.depth);
  const auto done = std::chrono::steady_clock::now();

  RenderStats& s = frame.stats;
  s = {};
  s.splats = selection.splats;
  s.nodes_visited = selection.nodes_visited;
  s.culled_frustum = selection.culled_frustum;
  s.culled_backface = selection.culled_backface;
  s.width = cam.width;
  s.height = cam.height;
  s.threads = pool.thread_count();
  s.ms_select = ms_between(start, selected);
  s.ms_raster = ms_between(selected, done);
  s.ms_total = ms_between(start, done);
}

void render_quality(const SphereTreeView& tree, const Camera& camera,
                    const RenderSettings& settings, const QualitySettings& quality,
                    ThreadPool& pool, Frame& frame) {
  QualityScratch scratch;
  render_quality(tree, camera, settings, quality, pool, frame, scratch);
}

}  // namespace pointillist
