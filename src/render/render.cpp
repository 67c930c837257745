// The renderer's entry point: selection, then rasterization, timed.
#include "pointillist/render/render.hpp"

#include "frame_timing.hpp"

namespace pointillist {

using render_detail::Clock;

void render(const SphereTreeView& tree, const Camera& camera, const RenderSettings& settings,
            ThreadPool& pool, Frame& frame) {
  const auto start = Clock::now();
  const CameraFrame cam = make_camera_frame(camera);
  render_detail::size_frame(frame, cam);

  SelectionStats selection;
  frame.splats.with_discs = false;  // the fast rasterizer does not read them
  select_splats(tree, cam, settings, pool, frame.splats, selection);
  const auto selected = Clock::now();
  rasterize_splats(frame.splats, cam, settings, pool, frame.scratch, frame.color, frame.depth);
  render_detail::fill_stats(frame, selection, cam, pool.thread_count(), start, selected,
                            Clock::now());
}

}  // namespace pointillist
