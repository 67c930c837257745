// QSplat selection on a hierarchy held whole in memory: the one traversal of
// qsplat_traversal.hpp over a single page that is always resident (Rusinkiewicz & Levoy,
// "QSplat: A Multiresolution Point Rendering System for Large Meshes", SIGGRAPH 2000, section
// 3.2; the per-node tests follow the original viewer, see shared/specs/qsplat-qs-format.md
// section 9, without its approximate shortcuts).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <vector>

#include "pointillist/core/error.hpp"
#include "pointillist/render/selection.hpp"
#include "shading.hpp"
#include "select/qsplat_traversal.hpp"
#include "select/subtree_selection.hpp"

namespace pointillist {

void SplatChunk::reserve(std::size_t n, bool with_colors, bool with_discs) {
  const bool grow = n > capacity();
  const std::size_t cap = grow ? std::max(n, 2 * capacity()) : capacity();
  if (grow) {
    x_px.resize(cap);
    y_px.resize(cap);
    depth.resize(cap);
    size_px.resize(cap);
    shaded.resize(cap);
    normal.resize(cap);
    node.resize(cap);
  }
  if (with_colors && color.size() < cap) color.resize(cap);
  if (with_discs && center.size() < cap) {
    center.resize(cap);
    radius.resize(cap);
  }
}

void SplatStream::trim() {
  for (std::size_t c = 0; c < chunks.size(); ++c) {
    SplatChunk& chunk = chunks[c];
    const std::size_t held = c < chunk_count ? chunk.count : 0;
    if (chunk.capacity() <= 4 * held + kTrimSlack) continue;
    chunk = SplatChunk{};
  }
}

namespace {

using namespace render_detail;

// The whole hierarchy in memory: one page, always resident; a splat's node id is its index.
class FlatAccess {
 public:
  static constexpr bool kPaged = false;
  struct Item {
    std::uint32_t node;
    std::uint8_t tests;
  };
  struct Kept {};
  explicit FlatAccess(std::span<const SphereNode> nodes) : nodes_(nodes) {}
  Item root(std::uint8_t tests) const { return {0, tests}; }
  const SphereNode& node(const Item& p) const { return nodes_[p.node]; }
  std::uint32_t page(const Item&) const { return 0; }
  std::uint32_t index(const Item& p) const { return p.node; }
  ChildRef children(const Item&, const SphereNode& n) const { return {0, n.first_child, true}; }
  const SphereNode* load_children(ChildRef c, const SphereNode&, SphereNode*) const {
    return nodes_.data() + c.first;
  }
  Item item(ChildRef c, std::uint32_t k, const SphereNode*, std::uint8_t tests) const {
    return {c.first + k, tests};
  }
  std::uint32_t keep(Kept&, const SphereNode&, bool, std::uint32_t, std::uint32_t index) const {
    return index;
  }
  const SphereNode& kept(const Kept&, std::uint32_t id) const { return nodes_[id]; }
  static void clear(Kept&) {}
  void finish(const Kept&, SplatChunk&) const {}  // features: attached by node id afterwards

 private:
  std::span<const SphereNode> nodes_;
};

}  // namespace

namespace render_detail {

void select_subtrees(std::span<const SphereNode> nodes, std::span<const SubtreeRoot> roots,
                     const ViewConstants& v, bool with_colors, SplatChunk& chunk,
                     Counters& counters, std::vector<std::uint32_t>* ends) {
  const FlatAccess access(nodes);
  TaskState<FlatAccess> out;
  thread_local std::vector<FlatAccess::Item> stack;
  chunk.count = 0;
  chunk.reserve(kInitialChunkCapacity, with_colors, v.with_discs);
  for (const SubtreeRoot& r : roots) {
    walk_subtree(access, FlatAccess::Item{r.node, r.tests}, v, with_colors, stack, chunk, out);
    if (ends) ends->push_back(static_cast<std::uint32_t>(chunk.count));
  }
  finish_chunk([&](std::uint32_t i) -> const SphereNode& { return nodes[i]; }, v, with_colors,
               chunk);
  counters.visited += out.counters.visited;
  counters.culled_frustum += out.counters.culled_frustum;
  counters.culled_backface += out.counters.culled_backface;
}

}  // namespace render_detail

void select_splats(const SphereTreeView& tree, const CameraFrame& camera,
                   const RenderSettings& settings, ThreadPool& pool, SplatStream& stream,
                   SelectionStats& stats) {
  if (!(settings.threshold_px > 0.0f) || !std::isfinite(settings.threshold_px)) {
    throw OptionError("splat size threshold " + std::to_string(settings.threshold_px) +
                      " px is invalid; give a positive number of pixels (1 draws every detail)");
  }
  stats = {};
  stream.chunk_count = 0;
  stream.has_colors = tree.has_colors;
  if (tree.nodes.empty()) return;

  const Shader shader(settings, camera);
  const ViewConstants v = make_view_constants(shader, camera, settings, stream.with_discs);

  const std::uint8_t tests =
      static_cast<std::uint8_t>((settings.frustum_culling ? kTestFrustum : 0) |
                                (settings.culls_backfaces() ? kTestBackface : 0));
  const Sphere root_sphere{tree.nodes[0].center, tree.nodes[0].radius};
  std::vector<TaskState<FlatAccess>> tasks;
  Counters top;
  std::vector<std::uint32_t> top_pages;
  select_qsplat(FlatAccess(tree.nodes), v, tests, tree.has_colors,
                expected_splats(tree.leaf_count, camera, &root_sphere, settings.threshold_px), pool,
                stream, tasks, top, top_pages);

  stats.nodes_visited = top.visited;
  stats.culled_frustum = top.culled_frustum;
  stats.culled_backface = top.culled_backface;
  for (std::size_t t = 0; t < stream.chunk_count; ++t) {
    stats.nodes_visited += tasks[t].counters.visited;
    stats.culled_frustum += tasks[t].counters.culled_frustum;
    stats.culled_backface += tasks[t].counters.culled_backface;
    stats.splats += stream.chunks[t].count;
  }
}

}  // namespace pointillist
