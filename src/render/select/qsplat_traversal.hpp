// The one QSplat traversal (Rusinkiewicz & Levoy 2000, section 3.2; the per-node tests of
// traversal_common.hpp), written once over a node-access policy: the whole hierarchy in memory
// (sphere_tree_traversal.cpp: one page that is always resident), decoded pages and packed pages
// (paged_render.cpp). Internal to render.
//
// Parallel and deterministic: the top of the tree is expanded level by level, in depth-first
// order, until there are about target_tasks(expected splats) pending subtrees (at most
// kTargetTasks); each subtree is then walked by one
// task into its own chunk of the stream, and the chunks are read in order, so the stream is the
// plain depth-first order whatever the thread count. A node is expanded at the top only when its
// children are resident; anything else is left for its task.
//
// Where a refined node's children are in a page that is not resident (or in levels of a page
// not loaded yet), the node stands in for its subtree: it is drawn whatever its size (even when
// its mean normal faces away, lit from the front then) and the page is requested.
//
// An Access policy has:
//   static constexpr bool kPaged;            // false: children are always resident
//   struct Item;                             // a pending node: where it is, and `tests`
//   struct Kept;                             // per task: the nodes behind its splats
//   Item root(std::uint8_t tests) const;
//   const SphereNode& node(const Item&) const;
//   std::uint32_t page(const Item&) const;
//   std::uint32_t index(const Item&) const;  // the node's index in its page
//   ChildRef children(const Item&, const SphereNode&) const;
//   const SphereNode* load_children(ChildRef, const SphereNode& parent, SphereNode* scratch4) const;
//   Item item(ChildRef, std::uint32_t k, const SphereNode* kids, std::uint8_t tests) const;
//   // The splat's node id, for node n at (page, index).
//   std::uint32_t keep(Kept&, const SphereNode& n, bool flip, std::uint32_t page,
//                      std::uint32_t index) const;
//   const SphereNode& kept(const Kept&, std::uint32_t id) const;
//   static void clear(Kept&);
//   void finish(const Kept&, SplatChunk&) const;  // after finish_chunk (e.g. sharp features)
#pragma once

#include <cstdint>
#include <vector>

#include "pointillist/core/thread_pool.hpp"
#include "pointillist/lod/page_cache.hpp"
#include "select/traversal_common.hpp"

namespace pointillist::render_detail {

// Where the children of a refined node are: nodes [first, first + child_count) of `page`, which
// may not be resident.
struct ChildRef {
  std::uint32_t page, first;
  bool resident;
};

// What one selection task produced besides its chunk, kept across frames for its buffers.
template <class Access>
struct TaskState {
  typename Access::Kept kept;
  std::vector<PageRequest> requests;    // pages it wanted, in traversal order
  std::vector<std::uint32_t> touched;   // resident pages it used below the top
  Counters counters;
};

// Levels below a refined node's children that the view will want too: a level about halves the
// spheres' radii, until the projected diameter is within the threshold (at most 8; a node
// around the eye plane wants them all).
inline std::uint32_t levels_below(const SphereNode& n, const ViewConstants& v, float z) {
  constexpr std::uint32_t kMax = 8;
  const float depth = v.ortho ? 1.0f : z;
  if (!(depth > 0.0f)) return kMax;
  const float over = n.radius * v.size_per_radius / (v.threshold_px * depth);  // > 1: refined
  if (!(over < 512.0f)) return kMax;
  std::uint32_t levels = 0;
  for (float size = over * 0.7071f; size > 1.0f && levels < kMax; size *= 0.7071f) ++levels;
  return levels;
}

// Walks the subtree of `start` into `chunk`.
template <class Access>
void walk_subtree(const Access& access, const typename Access::Item& start,
                  const ViewConstants& v, bool with_colors,
                  std::vector<typename Access::Item>& stack, SplatChunk& chunk,
                  TaskState<Access>& out) {
  using Item = typename Access::Item;
  Counters counters;  // local: the hot loop keeps it in registers
  {
    Emitter emitter(chunk, with_colors, v.with_discs);
    const auto emit = [&](const SphereNode& n, std::uint32_t page, std::uint32_t index, Vec3f d,
                          float z, bool stand_in) {
      const bool flip = stand_in && dot(d, n.normal) > 0;
      emitter.emit(n, access.keep(out.kept, n, flip, page, index), d, z, v, counters, !stand_in);
    };
    SphereNode scratch[4];
    stack.clear();
    stack.push_back(start);
    while (!stack.empty()) {
      Item p = stack.back();
      stack.pop_back();
      // Follow the first interior child without a round trip through the stack.
      for (;;) {
        const SphereNode& n = access.node(p);
        Vec3f d;
        float z;
        std::uint8_t tests = p.tests;
        const Decision decision = visit(n, v, tests, counters, d, z);
        if (decision == Decision::Draw) emit(n, access.page(p), access.index(p), d, z, false);
        if (decision != Decision::Refine) break;
        const ChildRef c = access.children(p, n);
        if constexpr (Access::kPaged) {
          // Under occlusion culling a hidden subtree in another page is neither opened nor
          // requested (nor drawn as a stand-in: its sphere holds the stand-in's splat too).
          if (v.occlusion != nullptr && (c.page != access.page(p) || !c.resident) &&
              v.occlusion->hidden(v.occlusion->context, n.center, n.radius)) {
            ++counters.culled_occluded;
            break;
          }
          if (!c.resident) {
            emit(n, access.page(p), access.index(p), d, z, true);
            out.requests.push_back({c.page, access.page(p),
                                    z > 0 ? n.radius * (v.ortho ? 1.0f : 1.0f / z) : 0.0f,
                                    c.first, levels_below(n, v, z)});
            break;
          }
          if (c.page != access.page(p)) out.touched.push_back(c.page);
        }
        // Leading leaf children are visited right here (most interior nodes near the bottom
        // have only leaves); from the first interior child on, the order is kept by going on
        // with it and pushing the others last to first.
        const SphereNode* kids = access.load_children(c, n, scratch);
        std::uint32_t k = 0;
        for (; k < n.child_count && kids[k].child_count == 0; ++k) {
          std::uint8_t leaf_tests = tests;
          if (visit(kids[k], v, leaf_tests, counters, d, z) == Decision::Draw) {
            emit(kids[k], c.page, c.first + k, d, z, false);
          }
        }
        if (k == n.child_count) break;
        for (std::uint32_t j = n.child_count; j-- > k + 1;) {
          stack.push_back(access.item(c, j, kids, tests));
        }
        p = access.item(c, k, kids, tests);
      }
    }
  }
  out.counters.visited += counters.visited;
  out.counters.culled_frustum += counters.culled_frustum;
  out.counters.culled_backface += counters.culled_backface;
  out.counters.culled_occluded += counters.culled_occluded;
}

// Selects the splats of the view `v` into `stream` (its chunks from 0). `tasks` holds each
// task's output afterwards (requests and touched pages for the caller to pass on); `top` counts
// the nodes visited while expanding the top, and `top_pages` the pages used there. `expected`
// sizes chunks that are new (expected_splats).
template <class Access>
void select_qsplat(const Access& access, const ViewConstants& v, std::uint8_t tests,
                   bool with_colors, std::uint64_t expected, ThreadPool& pool, SplatStream& stream,
                   std::vector<TaskState<Access>>& tasks, Counters& top,
                   std::vector<std::uint32_t>& top_pages) {
  using Item = typename Access::Item;
  std::vector<Item> items{access.root(tests)};
  std::vector<Item> next;
  SphereNode scratch[4];
  const std::size_t target = target_tasks(expected);
  while (items.size() < target) {
    bool expanded = false;
    next.clear();
    for (const Item& p : items) {
      const SphereNode& n = access.node(p);
      if (n.child_count == 0) {
        next.push_back(p);
        continue;
      }
      Counters trial;
      Vec3f d;
      float z;
      std::uint8_t t = p.tests;
      const Decision decision = visit(n, v, t, trial, d, z);
      const ChildRef c = decision == Decision::Refine ? access.children(p, n) : ChildRef{};
      if (decision == Decision::Cull || (decision == Decision::Refine && c.resident)) {
        top.visited += trial.visited;
        top.culled_frustum += trial.culled_frustum;
        top.culled_backface += trial.culled_backface;
        if (decision == Decision::Cull) continue;
        if constexpr (Access::kPaged) {
          if (c.page != access.page(p)) top_pages.push_back(c.page);
        }
        const SphereNode* kids = access.load_children(c, n, scratch);
        for (std::uint32_t k = 0; k < n.child_count; ++k) {
          next.push_back(access.item(c, k, kids, t));
        }
        expanded = true;
      } else {
        next.push_back(p);  // drawn, or a stand-in: its task visits it
      }
    }
    items.swap(next);
    if (!expanded) break;
  }

  if (stream.chunks.size() < items.size()) stream.chunks.resize(items.size());
  stream.chunk_count = items.size();
  if (tasks.size() < items.size()) tasks.resize(items.size());
  const std::size_t first_capacity = first_chunk_capacity(expected, items.size());
  pool.run(items.size(), [&](std::size_t t) {
    TaskState<Access>& out = tasks[t];
    Access::clear(out.kept);
    out.requests.clear();
    out.touched.clear();
    out.counters = {};
    SplatChunk& chunk = stream.chunks[t];
    chunk.count = 0;
    if (chunk.capacity() == 0) chunk.reserve(first_capacity, with_colors, v.with_discs);
    chunk.reserve(kInitialChunkCapacity, with_colors, v.with_discs);
    std::vector<Item> stack;
    stack.reserve(64);
    walk_subtree(access, items[t], v, with_colors, stack, chunk, out);
    finish_chunk([&](std::uint32_t i) -> const SphereNode& { return access.kept(out.kept, i); },
                 v, with_colors, chunk);
    access.finish(out.kept, chunk);
  });
}

}  // namespace pointillist::render_detail
