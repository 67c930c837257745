// The quality mode's entry point: selection, then the quality rasterizer, timed.
#include "frame_timing.hpp"

#include "pointillist/render/quality.hpp"

namespace pointillist {

using render_detail::Clock;

void render_quality(const SphereTreeView& tree, const Camera& camera,
                    const RenderSettings& settings, const QualitySettings& quality,
                    ThreadPool& pool, Frame& frame, QualityScratch& scratch) {
  const auto start = Clock::now();
  validate_quality_settings(quality);
  const CameraFrame cam = make_camera_frame(camera);
  render_detail::size_frame(frame, cam);

  SelectionStats selection;
  frame.splats.with_discs = true;
  select_splats(tree, cam, settings, pool, frame.splats, selection);
  const auto selected = Clock::now();
  rasterize_quality(frame.splats, cam, settings, quality, pool, scratch, frame.color,
                    frame.depth);
  render_detail::fill_stats(frame, selection, cam, pool.thread_count(), start, selected,
                            Clock::now());
}

void render_quality(const SphereTreeView& tree, const Camera& camera,
                    const RenderSettings& settings, const QualitySettings& quality,
                    ThreadPool& pool, Frame& frame) {
  QualityScratch scratch;
  render_quality(tree, camera, settings, quality, pool, frame, scratch);
}

}  // namespace pointillist
