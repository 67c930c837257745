// The entry points for a hierarchy held whole: the QSplat selection, then the fast or the
// quality rasterizer (frame_pass.hpp).
#include "pointillist/render/quality.hpp"
#include "pointillist/render/render.hpp"

#include "frame_pass.hpp"

namespace pointillist {

namespace {

auto qsplat(const SphereTreeView& tree, const RenderSettings& settings, ThreadPool& pool) {
  return [&](const CameraFrame& cam, SplatStream& stream) {
    SelectionStats selection;
    select_splats(tree, cam, settings, pool, stream, selection);
    return selection;
  };
}

}  // namespace

void render(const SphereTreeView& tree, const Camera& camera, const RenderSettings& settings,
            ThreadPool& pool, Frame& frame) {
  render_detail::frame_pass(camera, settings, nullptr, nullptr, pool, frame,
                            qsplat(tree, settings, pool));
}

void render_quality(const SphereTreeView& tree, const Camera& camera,
                    const RenderSettings& settings, const QualitySettings& quality,
                    ThreadPool& pool, Frame& frame, QualityScratch& scratch) {
  validate_quality_settings(quality);
  render_detail::frame_pass(camera, settings, &quality, &scratch, pool, frame,
                            qsplat(tree, settings, pool));
}

void render_quality(const SphereTreeView& tree, const Camera& camera,
                    const RenderSettings& settings, const QualitySettings& quality,
                    ThreadPool& pool, Frame& frame) {
  QualityScratch scratch;
  render_quality(tree, camera, settings, quality, pool, frame, scratch);
}

}  // namespace pointillist
