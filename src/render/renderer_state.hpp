// What the renderer keeps per model across frames, and the helpers its entry points share
// (renderer.cpp, occlusion_render.cpp). Internal to render.
#pragma once

#include <algorithm>
#include <atomic>
#include <cmath>
#include <functional>
#include <memory>
#include <optional>

#include "pointillist/lod/tree_features.hpp"
#include "pointillist/render/occlusion.hpp"
#include "pointillist/render/paged.hpp"
#include "pointillist/lod/hybrid_lod.hpp"
#include "pointillist/render/renderer.hpp"
#include "raster/quality_occluders.hpp"
#include "select/stream_features.hpp"
#include "select/traversal_common.hpp"
#include "shading.hpp"

namespace pointillist::render_detail {

// Page size when a model held whole is cut into pages (RendererOptions::page_all).
inline constexpr std::uint64_t kInMemoryPageBytes = 64 * 1024;
inline constexpr std::uint32_t kInMemoryPageLevels = 4;

// The camera as the model sees it: the same image of the model at p as the world camera gives
// of translate + scale·R·p. Sizes on screen are unchanged (radius and distance scale alike).
inline Camera model_camera(const Camera& world, const InstanceTransform& t) {
  Camera c = world;
  const float inv_scale = 1.0f / t.scale;
  c.eye = t.rotate_back(world.eye - t.translate) * inv_scale;
  c.target = t.rotate_back(world.target - t.translate) * inv_scale;
  c.up = t.rotate_back(world.up);
  return c;
}

// The camera frame in model space. As make_camera_frame builds it from model_camera, except
// where that cannot work although the world frame did: an eye so far away that, scaled into a
// small instance's space, the view vector's length overflows (a path fuzzer's camera at 1e19).
// There the world frame's axes and planes are carried over instead (same projection).
inline CameraFrame model_camera_frame(const Camera& camera, const CameraFrame& world,
                                      const InstanceTransform& t) {
  const Camera c = model_camera(camera, t);
  const Vec3f view = c.target - c.eye;
  const float len = length(view);
  if (len > 0.0f && std::isfinite(len) && is_finite(view) &&
      length(cross(view / len, c.up)) > 1e-6f * length(c.up)) {
    return make_camera_frame(c);
  }
  CameraFrame f = world;
  const float inv_scale = 1.0f / t.scale;
  f.eye = t.rotate_back(world.eye - t.translate) * inv_scale;
  f.right = t.rotate_back(world.right);
  f.up = t.rotate_back(world.up);
  f.forward = t.rotate_back(world.forward);
  if (world.ortho) f.focal_px = world.focal_px * t.scale;  // pixels per model unit
  for (std::size_t k = 0; k < f.planes.size(); ++k) {
    // n·(translate + R·p·s) + d >= 0  <=>  (Rᵀn)·p + (d + n·translate)/s >= 0
    const Plane& w = world.planes[k];
    f.planes[k] = {t.rotate_back(w.normal), (w.d + dot(w.normal, t.translate)) * inv_scale};
  }
  return f;
}

// Occlusion culling inside a paged instance (PagedRenderer::select): a subtree, its sphere in
// model space, is hidden when its world bound cannot show over `pyramid` (bound_may_be_visible).
// Adds the tiles tested to `tested`; safe from several selection tasks at once.
struct InstancePyramidTest {
  const DepthPyramid* pyramid;
  const CameraFrame* camera;
  const InstanceTransform* transform;
  const QueryFootprint* footprint;
  std::atomic<std::uint64_t>* tested;

  static bool hidden(const void* context, Vec3f center, float radius) {
    const InstancePyramidTest& t = *static_cast<const InstancePyramidTest*>(context);
    std::uint64_t tiles = 0;
    const QueryBound bound{t.transform->apply(center), radius * t.transform->scale};
    const bool visible = bound_may_be_visible(*t.pyramid, *t.camera, bound, *t.footprint, tiles);
    *t.tested += tiles;
    return !visible;
  }
  SubtreeOcclusion occlusion() const { return {&hidden, this}; }
};

// Moves a chunk selected in model space into the world: discs, and depth (model depth × scale).
inline void to_world(const InstanceTransform& t, SplatChunk& chunk, bool with_discs) {
  for (std::size_t i = 0; i < chunk.count; ++i) {
    chunk.depth[i] *= t.scale;
    chunk.normal[i] = t.rotate(chunk.normal[i]);
    if (with_discs) {
      chunk.center[i] = t.apply(chunk.center[i]);
      chunk.radius[i] *= t.scale;
    }
  }
}

inline std::uint8_t to_byte(float v) {
  return static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f));
}

// The sharp features of a model: its hierarchy's, or (paged) what its pages carry.
inline const TreeFeatures* model_features(const RenderModel& m) {
  if (m.tree.features) return m.tree.features;
  return m.pages ? m.pages->features() : nullptr;
}

inline void add(SelectionStats& a, const SelectionStats& b) {
  a.splats += b.splats;
  a.nodes_visited += b.nodes_visited;
  a.culled_frustum += b.culled_frustum;
  a.culled_backface += b.culled_backface;
}


// A chunk of a model without colours drawn beside coloured ones: its splats take the settings'
// base colour, as the others carry theirs.
inline void fill_base_color(SplatChunk& chunk, const RenderSettings& settings, bool with_discs) {
  const Rgb8 base{to_byte(settings.base_color.x), to_byte(settings.base_color.y),
                  to_byte(settings.base_color.z)};
  chunk.reserve(chunk.count, true, with_discs);
  std::fill(chunk.color.begin(), chunk.color.begin() + chunk.count, base);
}

// Every splat of the chunk drawn `scale` times its size (FrameSettings::splat_scale).
inline void scale_splats(SplatChunk& chunk, float scale, bool with_discs) {
  if (scale == 1.0f) return;
  for (std::size_t i = 0; i < chunk.count; ++i) chunk.size_px[i] *= scale;
  if (with_discs) {
    for (std::size_t i = 0; i < chunk.count; ++i) chunk.radius[i] *= scale;
  }
}

// What makes a selected chunk of one instance ready for the rasterizers (place_chunk).
struct ChunkPlacement {
  std::uint32_t instance = 0;
  const InstanceTransform* transform = nullptr;  // null: the identity
  bool features = false;     // the stream carries sharp features:
  bool from_pages = false;   // filled from a paged model's pages during selection,
  const TreeFeatures* tree_features = nullptr;  // or looked up here (null: mixed, unclipped)
  std::uint32_t id_base = 0;  // the instance's first surface id
  bool base_color = false;    // the stream has colours and the model none
  float splat_scale = 1.0f;
  bool with_discs = false;
};

// The chunk into the world, its sharp features, base colours, splat scale.
inline void place_chunk(SplatChunk& chunk, const ChunkPlacement& p,
                        const RenderSettings& settings) {
  chunk.instance = p.instance;
  if (p.transform) to_world(*p.transform, chunk, p.with_discs);
  if (p.features) {
    if (p.from_pages) {
      place_features(p.transform, p.id_base, chunk);
    } else {
      attach_features(p.tree_features, p.transform, p.id_base, chunk);
    }
  }
  if (p.base_color) fill_base_color(chunk, settings, p.with_discs);
  scale_splats(chunk, p.splat_scale, p.with_discs);
}

// Moves the chunks of `from` behind those of `to` (their buffers swapped, not copied; `from`'s
// count is left as it was, so SplatStream::trim keeps the buffers it now holds). Returns the
// index in `to` of the first one moved.
inline std::size_t append_chunks(SplatStream& to, SplatStream& from) {
  const std::size_t base = to.chunk_count;
  if (to.chunks.size() < base + from.chunk_count) to.chunks.resize(base + from.chunk_count);
  for (std::size_t c = 0; c < from.chunk_count; ++c) std::swap(to.chunks[base + c], from.chunks[c]);
  to.chunk_count = base + from.chunk_count;
  return base;
}

// The smallest sphere around `a` and `b` (a sphere holding both), slightly grown for rounding.
Sphere enclose(const Sphere& a, const Sphere& b);
// A model-space sphere (or a node's) in the world of instance transform `t`.
Sphere world_sphere(const InstanceTransform& t, const Sphere& s);
Sphere world_sphere(const InstanceTransform& t, const SphereNode& n);

// The pixels [x0, x1) × [y0, y1) the fast rasterizer may touch drawing `chunk`.
SoftwareQueries::Rect chunk_pixel_rect(const SplatChunk& chunk, const CameraFrame& cam);

// A model's hierarchy cut for occlusion culling: nodes down to subtrees of at most `leaf_points`
// points (the culling leaves), in depth-first order, each with its children.
struct ModelCullTree {
  struct Node {
    std::uint32_t tree_node = 0;
    std::uint32_t parent = UINT32_MAX;              // local index
    std::uint32_t first_child = 0, child_count = 0;  // into `children`
    std::uint32_t culling_leaves = 1;
    std::uint32_t points = 0;  // leaves of the hierarchy below
  };
  std::uint32_t leaf_points = 0;
  std::vector<Node> nodes;
  std::vector<std::uint32_t> children;
};
// How an instance sees the frame's camera (occlusion culling selects instance by instance).
struct InstanceView {
  bool ready = false;
  bool identity = true;
  CameraFrame cam;
  std::optional<Shader> shader;
  ViewConstants v;
  std::uint32_t id_base = 0;  // its first surface id (sharp features)
};

ModelCullTree build_cull_tree(std::span<const SphereNode> nodes, std::uint32_t leaf_points);
// A Sequential Point Tree's: its root over one leaf per list range (tree_node = kSptTopList for
// the top list, k for chunk k; the root's is kSptTopList + 1).
inline constexpr std::uint32_t kSptTopList = UINT32_MAX - 1;
ModelCullTree build_spt_cull_tree(const SequentialPointTree& spt);

// Occlusion culling's hierarchy over a scene: a BVH over the instances (median splits on the
// longest axis of their world spheres' centres), each instance's model cull tree below its BVH
// leaf (the leaf is the model's root itself), parents before children.
struct CullMeta {
  std::uint32_t instance = UINT32_MAX;  // UINT32_MAX: a BVH node
  std::uint32_t local = 0;              // the node in the instance's model cull tree
};
struct SceneHierarchy {
  CullHierarchy h;
  std::vector<CullMeta> meta;                // per node
  std::vector<std::uint32_t> instance_root;  // the node of each instance's model root
};
// Builds `h` (empty) for `scene`: `cull_tree(i)` is instance i's model cull tree,
// `model_bound(i, node)` a node's sphere in model space.
void build_scene_hierarchy(std::span<const SceneInstance> scene,
                           const std::function<const ModelCullTree&(std::uint32_t)>& cull_tree,
                           const std::function<Sphere(std::uint32_t, const ModelCullTree::Node&)>&
                               model_bound,
                           SceneHierarchy& h);

}  // namespace pointillist::render_detail

namespace pointillist {

struct Renderer::ModelState {
  const RenderModel* model = nullptr;
  std::unique_ptr<PageSource> owned_pages;  // a model held whole, cut into pages
  const PageSource* pages = nullptr;
  std::optional<PagedRenderer> paged;
  std::optional<SequentialPointTree> spt;
  std::optional<TreeFeatures> spt_features;  // the model's features on the SPT's entries
  std::optional<HybridLod> hybrid;  // the hybrid point/polygon lists over `spt` (--hybrid)
  std::uint64_t frame = 0;  // the last frame that drew the model
  std::uint64_t model_bytes = 0;  // storage bytes of a paged model (open + every page)
  std::optional<render_detail::ModelCullTree> cull_tree;      // occlusion culling (QSplat)
  std::optional<render_detail::ModelCullTree> spt_cull_tree;  // occlusion culling (SPT)
  std::optional<float> largest_leaf;  // largest_leaf_radius of the model's tree, once needed
};


// The scene's culling hierarchy (BVH nodes first, then each instance's model nodes) and its
// state across frames.
struct Renderer::SceneCull : render_detail::SceneHierarchy {
  using Meta = render_detail::CullMeta;
  std::vector<std::pair<const RenderModel*, InstanceTransform>> scene;  // what it was built for
  std::uint32_t leaf_points = 0;
  LodScheme lod = LodScheme::QSplat;
  CullState state;
  DepthPyramid pyramid;
  // Work buffers of a frame, kept for the next: per node the per-node tests left when it is
  // reached and after its visit; per instance whether it drew.
  std::vector<std::uint8_t> tests_in, tests_out, instance_drawn;
  std::vector<float> weight;  // splats a node drawn as a leaf is expected to give
  std::vector<render_detail::InstanceView> views;
  // Quality mode: the leaves drawn in the frame, and the occluder pass's buffers.
  std::vector<std::pair<std::uint32_t, quality_detail::StreamPiece>> drawn;
  std::vector<quality_detail::StreamPiece> pieces;
  quality_detail::OccluderScratch occluders;

  bool matches(std::span<const SceneInstance> s, std::uint32_t leaves, LodScheme l) const {
    if (s.size() != scene.size() || leaves != leaf_points || l != lod) return false;
    for (std::size_t i = 0; i < s.size(); ++i) {
      const InstanceTransform& a = s[i].transform;
      const InstanceTransform& b = scene[i].second;
      if (s[i].model != scene[i].first || !(a.translate == b.translate) || a.scale != b.scale ||
          !(a.rotation[0] == b.rotation[0]) || !(a.rotation[1] == b.rotation[1]) ||
          !(a.rotation[2] == b.rotation[2])) {
        return false;
      }
    }
    return true;
  }
};

}  // namespace pointillist
