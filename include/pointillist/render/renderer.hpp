// The renderer: one entry point that draws a scene of model instances with either level-of-detail
// scheme (QSplat traversal, Sequential Point Tree) and any rasterizer (fast splats, quality
// surface splatting, the mesh reference), in memory or page by page, and the state a sequence of
// frames keeps (page caches, Sequential Point Trees built on first use).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <unordered_map>
#include <vector>

#include "pointillist/core/camera.hpp"
#include "pointillist/core/math.hpp"
#include "pointillist/core/point_set.hpp"
#include "pointillist/core/thread_pool.hpp"
#include "pointillist/lod/page_cache.hpp"
#include "pointillist/lod/pages.hpp"
#include "pointillist/lod/sphere_tree.hpp"
#include "pointillist/render/occlusion.hpp"
#include "pointillist/render/quality.hpp"
#include "pointillist/render/render.hpp"
#include "pointillist/render/settings.hpp"
#include "pointillist/render/spt_render.hpp"

namespace pointillist {

enum class LodScheme {
  QSplat,  // the bounding-sphere traversal, detail RenderSettings::threshold_px
  Spt,     // the Sequential Point Tree, detail FrameSettings::epsilon_px
};

enum class Rasterizer {
  Fast,       // one flat splat per node (RenderSettings::shape)
  Quality,    // Gaussian surface splatting with per-pixel shading (FrameSettings::quality)
  Reference,  // the source mesh's triangles (a scan with faces, single instance)
};

// The names the command line and the reports use: "qsplat", "spt"; "fast", "quality",
// "reference".
constexpr const char* name(LodScheme l) { return l == LodScheme::Spt ? "spt" : "qsplat"; }
constexpr const char* name(Rasterizer r) {
  return r == Rasterizer::Fast ? "fast" : r == Rasterizer::Quality ? "quality" : "reference";
}

// What the renderer needs of a model: its hierarchy (whole, or only its counts and boxes when it
// is paged), its pages, and for the reference rasterizer its mesh. The pointed-to data must
// outlive the renderer's use of it; the address identifies the model across frames.
struct RenderModel {
  SphereTreeView tree;
  const PageSource* pages = nullptr;  // paged: draw from these pages
  const PointSet* mesh = nullptr;     // prepared points with faces, or null
  // A mesh's faces over the hierarchy's leaves (indices in sphere_tree_leaves order), for the
  // hybrid point/polygon mode; empty for point clouds and files that do not keep them.
  std::span<const std::array<std::uint32_t, 3>> triangles;
  std::string name;                   // for messages (a path)
};

// A model point p is drawn at translate + scale · rotation · p (rotation orthonormal, scale > 0).
struct InstanceTransform {
  Vec3f translate{0, 0, 0};
  Vec3f rotation[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};  // rows of the rotation matrix
  float scale = 1.0f;
  bool is_identity() const;
  Vec3f rotate(Vec3f v) const {
    return {dot(rotation[0], v), dot(rotation[1], v), dot(rotation[2], v)};
  }
  // Rᵀ·v: the inverse rotation.
  Vec3f rotate_back(Vec3f v) const {
    return rotation[0] * v.x + rotation[1] * v.y + rotation[2] * v.z;
  }
  Vec3f apply(Vec3f p) const { return translate + rotate(p) * scale; }
};

struct SceneInstance {
  const RenderModel* model = nullptr;
  InstanceTransform transform;
};

// Settings of a frame beyond RenderSettings (shading, kernel, QSplat threshold, culling).
struct FrameSettings {
  LodScheme lod = LodScheme::QSplat;
  Rasterizer rasterizer = Rasterizer::Fast;
  // SPT: allowed geometric error in pixels (1 draws about QSplat's 1-pixel detail). > 0.
  float epsilon_px = 1.0f;
  // SPT: skip chunks outside the view frustum (turn off only to measure what it saves).
  bool spt_chunk_culling = true;
  // SPT: hybrid point/polygon rendering (lod/hybrid_lod.hpp): near the eye a mesh's triangles
  // replace the points they cover, drawn by the fast rasterizer with per-pixel depth and
  // shading. Models without triangles draw points only.
  bool hybrid = false;
  // Hybrid: a triangle replaces points while its longest edge projects to more than this many
  // times epsilon_px pixels. > 0.
  float triangle_px_per_epsilon = 4.0f;
  QualitySettings quality;
  // Every splat is drawn this many times its size (a point-size control); the level of detail
  // is chosen as at 1. > 0.
  float splat_scale = 1.0f;
  // Draw the sharp features of models that have them (TreeFeatures: clip planes, surface ids;
  // QSplat on hierarchies held whole). Off draws as without them.
  bool features = true;
  // Occlusion culling (occlusion.hpp): with a method other than None, nodes hidden behind what
  // is already drawn are skipped. The image is the same bits as without culling. The fast
  // rasterizer on models held whole only (for now).
  OcclusionSettings occlusion;
};

struct RendererOptions {
  // Draw every model page by page, also models held whole (cut into pages in memory), so paging
  // can be watched: progressive loading, a memory cap.
  bool page_all = false;
  // Memory the resident pages of a paged model may take (bytes); 0 = no cap.
  std::uint64_t memory_cap = 0;
};

// Paging state summed over the scene's paged models.
struct PagingStats {
  bool paged = false;
  std::uint32_t pages = 0;        // pages of the paged models
  std::uint64_t model_bytes = 0;  // storage bytes of those models (open + every page)
  PageCacheStats cache;           // summed over the models' caches
  bool complete = true;           // every paged model has all the last frame needed
};

class Renderer {
 public:
  explicit Renderer(const RendererOptions& options = {});
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Draws the instances seen by `camera` into `frame` (resized as needed): every instance's
  // splats are selected (in its own frame, through the inverse of its transform, so the detail
  // is the same as if the model stood there) into one stream, instance after instance, and
  // rasterized once. Equal depths go to the smaller colour (fast) or are summed in stream order
  // (quality). The image does not depend on pool.thread_count(), nor on the occlusion method:
  // with occlusion culling, a hierarchy over the instances and their models is traversed front
  // to back and only what the queries find visible is selected and drawn. A paged model draws
  // what is resident and requests the rest (load_requested, request_in_background).
  // frame.stats sums the instances. Throws OptionError for combinations that cannot be drawn
  // (the message says what to drop): the reference rasterizer with SPT or on a model without a
  // mesh (it draws every instance's mesh at its transform); SPT on a paged model; --hybrid
  // without SPT, with another rasterizer or occlusion culling, or on a scene without
  // triangles; occlusion culling other
  // than with the fast rasterizer on models held whole; invalid settings.
  void render(std::span<const SceneInstance> scene, const Camera& camera,
              const RenderSettings& settings, const FrameSettings& frame_settings,
              ThreadPool& pool, Frame& frame);

  // Paging between frames (see PageCache): loads what the last frame requested, or hands it to
  // the loader threads. Return the number of pages loaded or handed over, summed over models.
  std::size_t load_requested(ThreadPool& pool, std::size_t max_pages = SIZE_MAX,
                             std::uint64_t max_storage_bytes = UINT64_MAX);
  std::size_t request_in_background(std::size_t max_pages = SIZE_MAX,
                                    std::uint64_t max_storage_bytes = UINT64_MAX);
  void wait_for_loader();
  // True when no paged model is waiting for a page the last frame needed.
  bool complete() const;
  // True while the loader thread has pages on their way (taken in by the next frame).
  bool loading() const;
  bool paging() const;  // some model of the last frame is drawn page by page
  // Whether rendering `scene` draws some model page by page.
  bool pages_any(std::span<const SceneInstance> scene) const;
  PagingStats paging_stats() const;
  // SPT selection details of the last frame (summed over instances).
  const SptSelectionStats& spt_stats() const { return spt_stats_; }
  // Hybrid mode: triangles of the last frame (selected; scanned list entries).
  std::uint64_t triangles_selected() const { return triangles_selected_; }
  std::uint64_t triangle_entries_scanned() const { return triangle_entries_scanned_; }

 private:
  struct ModelState;
  struct SceneCull;
  void render_occluded(std::span<const SceneInstance> scene, const Camera& camera,
                       const RenderSettings& settings, const FrameSettings& fs, ThreadPool& pool,
                       Frame& frame);
  ModelState& state_for(const RenderModel& model, ThreadPool& pool, const FrameSettings& fs);
  SelectionStats select(std::span<const SceneInstance> scene, const Camera& camera,
                        const CameraFrame& world, const RenderSettings& settings,
                        const FrameSettings& fs, ThreadPool& pool, SplatStream& stream);

  RendererOptions options_;
  std::unordered_map<const RenderModel*, std::unique_ptr<ModelState>> states_;
  std::vector<ModelState*> last_frame_;  // the models of the last frame, in instance order
  SplatStream scratch_stream_;
  QualityScratch quality_scratch_;
  SptSelectionStats spt_stats_;
  std::uint64_t triangles_selected_ = 0, triangle_entries_scanned_ = 0;
  // Hybrid mode: each instance's selected triangles, and the triangle rasterizer's buffers.
  struct TriangleState;
  std::unique_ptr<TriangleState> triangles_;
  std::uint64_t frame_number_ = 0;
  std::unique_ptr<SceneCull> cull_;  // occlusion culling: the scene's hierarchy and state
};

}  // namespace pointillist
