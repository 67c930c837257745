// QSplat traversal: level-of-detail selection with frustum and normal-cone backface culling
// (Rusinkiewicz & Levoy, "QSplat: A Multiresolution Point Rendering System for Large Meshes",
// SIGGRAPH 2000, section 3.2; the per-node tests follow the original viewer, see
// shared/specs/qsplat-qs-format.md section 9, without its approximate shortcuts).
//
// Parallel and deterministic: the top of the tree is expanded level by level, in depth-first
// order, until there are about kTargetTasks pending subtrees; each subtree is then walked by one
// task into its own chunk of the stream, and the chunks are read in order, so the stream is the
// plain depth-first order whatever the thread count.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "pointillist/core/error.hpp"
#include "pointillist/render/selection.hpp"
#include "shading.hpp"
#include "select/traversal_common.hpp"

namespace pointillist {

void SplatChunk::reserve(std::size_t n, bool with_colors) {
  if (n <= capacity() && (!with_colors || color.size() >= n)) return;
  const std::size_t cap = std::max(n, 2 * capacity());
  x_px.resize(cap);
  y_px.resize(cap);
  depth.resize(cap);
  size_px.resize(cap);
  shaded.resize(cap);
  center.resize(cap);
  radius.resize(cap);
  normal.resize(cap);
  node.resize(cap);
  if (with_colors) color.resize(cap);
}

namespace {

using namespace render_detail;

void walk_subtree(std::span<const SphereNode> nodes, Pending start, const ViewConstants& v,
                  bool with_colors, std::vector<Pending>& stack, SplatChunk& out,
                  Counters& total) {
  Counters counters;
  Emitter emitter(out, with_colors);
  if (start.tests & kDecidedDraw) {
    const SphereNode& n = nodes[start.node];
    const Vec3f d = n.center - v.eye;
    emitter.emit(n, start.node, d, dot(d, v.forward), v, counters);
  } else {
    stack.clear();
    stack.push_back(start);
    while (!stack.empty()) {
      Pending p = stack.back();
      stack.pop_back();
      // Follow the first child without a round trip through the stack.
      for (;;) {
        const SphereNode& n = nodes[p.node];
        Vec3f d;
        float z;
        const Decision decision = visit(n, v, p.tests, counters, d, z);
        if (decision == Decision::Draw) emitter.emit(n, p.node, d, z, v, counters);
        if (decision != Decision::Refine) break;
        // Leading leaf children are visited right here (most interior nodes near the bottom
        // have only leaves); from the first interior child on, the order is kept by going on
        // with it and pushing the others last to first.
        std::uint32_t c = 0;
        for (; c < n.child_count; ++c) {
          const std::uint32_t index = n.first_child + c;
          const SphereNode& child = nodes[index];
          if (child.child_count != 0) break;
          std::uint8_t tests = p.tests;
          if (visit(child, v, tests, counters, d, z) == Decision::Draw) {
            emitter.emit(child, index, d, z, v, counters);
          }
        }
        if (c == n.child_count) break;
        for (std::uint32_t k = n.child_count; k-- > c + 1;) {
          stack.push_back({n.first_child + k, p.tests});
        }
        p.node = n.first_child + c;
      }
    }
  }
  total.visited += counters.visited;
  total.culled_frustum += counters.culled_frustum;
  total.culled_backface += counters.culled_backface;
}

// Expands the top of the tree, level by level, into pending subtrees in depth-first order.
std::vector<Pending> split_top(std::span<const SphereNode> nodes, const ViewConstants& v,
                               std::uint8_t tests, Counters& counters) {
  std::vector<Pending> items{{0, tests}}, next;
  while (items.size() < kTargetTasks) {
    bool expanded = false;
    next.clear();
    for (Pending p : items) {
      const SphereNode& n = nodes[p.node];
      if ((p.tests & kDecidedDraw) || n.child_count == 0) {
        next.push_back(p);
        continue;
      }
      Vec3f d;
      float z;
      switch (visit(n, v, p.tests, counters, d, z)) {
        case Decision::Cull:
          break;
        case Decision::Draw:
          next.push_back({p.node, static_cast<std::uint8_t>(p.tests | kDecidedDraw)});
          break;
        case Decision::Refine:
          for (std::uint32_t c = 0; c < n.child_count; ++c) {
            next.push_back({n.first_child + c, p.tests});
          }
          expanded = true;
          break;
      }
    }
    items.swap(next);
    if (!expanded) break;
  }
  return items;
}

}  // namespace

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
                                (settings.backface_culling ? kTestBackface : 0));
  Counters top;
  const std::vector<Pending> items = split_top(tree.nodes, v, tests, top);

  if (stream.chunks.size() < items.size()) stream.chunks.resize(items.size());
  stream.chunk_count = items.size();
  std::vector<Counters> counters(items.size());
  const bool with_colors = tree.has_colors;
  pool.run(items.size(), [&](std::size_t t) {
    SplatChunk& chunk = stream.chunks[t];
    chunk.count = 0;
    chunk.reserve(kInitialChunkCapacity, with_colors);
    std::vector<Pending> stack;
    stack.reserve(64);
    walk_subtree(tree.nodes, items[t], v, with_colors, stack, chunk, counters[t]);
    finish_chunk([&](std::uint32_t i) -> const SphereNode& { return tree.nodes[i]; }, v,
                 with_colors, chunk);
  });

  stats.nodes_visited = top.visited;
  stats.culled_frustum = top.culled_frustum;
  stats.culled_backface = top.culled_backface;
  for (std::size_t t = 0; t < items.size(); ++t) {
    stats.nodes_visited += counters[t].visited;
    stats.culled_frustum += counters[t].culled_frustum;
    stats.culled_backface += counters[t].culled_backface;
    stats.splats += stream.chunks[t].count;
  }
}

}  // namespace pointillist
