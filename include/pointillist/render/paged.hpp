// Out-of-core and progressive rendering of a paged hierarchy (lod/pages.hpp), as QSplat streams
// a model in (Rusinkiewicz & Levoy 2000, section 4.3). The traversal draws from the pages that
// are resident in a PageCache (lod/page_cache.hpp); where a node's children are in a page that is
// not, it draws the node as a splat and requests the page. Between frames the requested pages
// are loaded (coarsest first), within a cap on resident memory.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "pointillist/core/camera.hpp"
#include "pointillist/core/thread_pool.hpp"
#include "pointillist/lod/page_cache.hpp"
#include "pointillist/lod/pages.hpp"
#include "pointillist/lod/sphere_tree.hpp"
#include "pointillist/render/quality.hpp"
#include "pointillist/render/render.hpp"
#include "pointillist/render/selection.hpp"

namespace pointillist {

using PagedRenderStats = PageCacheStats;

// Renders a paged model. Not thread-safe: one frame at a time; the pool parallelises page loads
// and rasterization, and an optional loader thread decodes pages in the background.
class PagedRenderer {
 public:
  // Loads page 0. Throws OptionError when page 0 alone needs more than `memory_cap` bytes (the
  // message gives the size needed), and what the source throws.
  PagedRenderer(const PageSource& source, std::uint64_t memory_cap, ThreadPool& pool);
  ~PagedRenderer();
  PagedRenderer(const PagedRenderer&) = delete;
  PagedRenderer& operator=(const PagedRenderer&) = delete;

  // The QSplat traversal of render() (same tests, threshold and culling, same splats where the
  // pages are resident) over the resident pages. A node whose children are in a page that is
  // not resident is drawn as a splat whatever its size, and the page is requested. Selection
  // and rasterization run on the pool; the image does not depend on the thread count.
  void render(const Camera& camera, const RenderSettings& settings, ThreadPool& pool,
              Frame& frame);
  // The same selection drawn by the quality rasterizer (rasterize_quality: Gaussian surface
  // splatting, per-pixel shading), so models larger than memory render in the quality mode too.
  // With every page the view needs resident, the image is render_quality's on the whole
  // hierarchy. Throws OptionError for invalid settings.
  void render_quality(const Camera& camera, const RenderSettings& settings,
                      const QualitySettings& quality, ThreadPool& pool, Frame& frame,
                      QualityScratch& scratch);

  // The selection of render() alone: writes the splats of the resident pages seen by `camera`
  // into `stream` (discs filled when stream.with_discs) and records the pages wanted. With
  // `same_frame`, the selection adds to the last one's requests (another instance of the model
  // in the same frame) instead of starting a frame. With `features` (a source whose pages carry
  // them), each chunk also gets its splats' surface ids (the model's own) and clip planes
  // (model space); the stream's has_features is the caller's to set. With `occlusion`, a node
  // whose children are in another page is first tested, and when hidden its subtree is neither
  // drawn nor requested (occlusion culling inside a paged model; SelectionStats::
  // culled_occluded counts them).
  SelectionStats select(const CameraFrame& camera, const RenderSettings& settings,
                        ThreadPool& pool, SplatStream& stream, bool same_frame = false,
                        bool features = false, const SubtreeOcclusion* occlusion = nullptr);

  // Starts a frame whose selections all pass same_frame (occlusion culling selects a model's
  // instances only when they are visible): drops the last frame's page requests, so a model
  // found hidden requests none.
  void begin_frame();
  // The sphere of the hierarchy's root (page 0's first node): it holds every splat's disc.
  Sphere root_sphere() const;
  // Loading between frames: see PageCache (the requests are the last render's).
  std::size_t load_requested(ThreadPool& pool, std::size_t max_pages = SIZE_MAX,
                             std::uint64_t max_storage_bytes = UINT64_MAX) {
    return cache_.load_requested(pool, max_pages, max_storage_bytes);
  }
  std::size_t request_in_background(std::size_t max_pages = SIZE_MAX,
                                    std::uint64_t max_storage_bytes = UINT64_MAX) {
    return cache_.request_in_background(max_pages, max_storage_bytes);
  }
  void wait_for_loader() { cache_.wait_for_loader(); }
  bool complete() const { return cache_.complete(); }
  bool loading() const { return cache_.loading(); }
  const PagedRenderStats& stats() const { return cache_.stats(); }
  const PageCache& cache() const { return cache_; }
  // Counts and boxes of the model (PageSource::summary), for the camera.
  const SphereTreeView& summary() const { return summary_; }

 private:
  void render_frame(const Camera& camera, const RenderSettings& settings,
                    const QualitySettings* quality, QualityScratch* scratch, ThreadPool& pool,
                    Frame& frame);
  struct Selection;
  struct Tasks;  // each selection task's output of the last frame (paged_render.cpp)
  // The traversal (select/qsplat_traversal.hpp) over decoded or packed pages.
  template <class Access, class TaskStates>
  void select_pages(const Access& access, Selection& selection, ThreadPool& pool,
                    TaskStates& tasks);

  PageCache cache_;
  SphereTreeView summary_;
  mutable std::optional<Sphere> root_;  // root_sphere(), once page 0 was read
  std::unique_ptr<Tasks> tasks_;
};

}  // namespace pointillist
