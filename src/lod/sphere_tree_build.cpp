// QSplat bounding-sphere hierarchy (Rusinkiewicz & Levoy, "QSplat: A Multiresolution Point
// Rendering System for Large Meshes", SIGGRAPH 2000, section 3.1): median splits along the
// longest axis, collapsed to 2–4 children per node, stored breadth-first.
//
// The build runs in three passes:
//   1. the partition: points are reordered so that every binary split is a median split
//      (median_split.cpp);
//   2. the shape: which range of that order each node covers depends only on the point count,
//      so the breadth-first node array (first_child, child_count) is laid out level by level;
//   3. the attributes (node_bounds.cpp): leaves copy their splat, interior nodes bound their children, level by
//      level from the bottom.
// Every pass writes each output slot from exactly one task, so the result is the same bits for
// any thread count.
#include "pointillist/lod/sphere_tree.hpp"

#include <cmath>
#include <cstdio>
#include <map>
#include <string>

#include "splat_input.hpp"
#include "median_split.hpp"
#include "node_bounds.hpp"
#include "pointillist/core/error.hpp"

namespace pointillist {
namespace {

using lod_detail::split_half;

constexpr std::size_t kNodeGrain = 8192;   // nodes per task in the per-level passes

// Children of a node over a range of n >= 2 points: each half (first split_half(n) points, then
// the rest) contributes itself when it holds one point, or when `halves_only`, and its two
// halves otherwise.
struct ChildRanges {
  std::uint32_t count = 0;
  std::uint32_t offset[4] = {};
  std::uint32_t size[4] = {};
};

ChildRanges child_ranges(std::uint32_t n, bool halves_only = false) {
  ChildRanges c;
  const auto h0 = static_cast<std::uint32_t>(split_half(n));
  const std::uint32_t halves[2][2] = {{0, h0}, {h0, n - h0}};
  for (const auto& [offset, size] : halves) {
    if (size == 1 || halves_only) {
      c.offset[c.count] = offset;
      c.size[c.count++] = size;
    } else {
      const auto q = static_cast<std::uint32_t>(split_half(size));
      c.offset[c.count] = offset;
      c.size[c.count++] = q;
      c.offset[c.count] = offset + q;
      c.size[c.count++] = size - q;
    }
  }
  return c;
}

constexpr std::uint32_t child_count_of(std::uint32_t n) { return n <= 1 ? 0 : (n >= 4 ? 4 : n); }

// Nodes of the subtree over n points. Ranges of a level differ in size by at most one, so the
// memo holds O(log n) entries.
std::size_t node_count_of(std::uint32_t n, std::map<std::uint32_t, std::size_t>& memo) {
  if (n <= 1) return 1;
  if (const auto it = memo.find(n); it != memo.end()) return it->second;
  const ChildRanges c = child_ranges(n);
  std::size_t total = 1;
  for (std::uint32_t i = 0; i < c.count; ++i) total += node_count_of(c.size[i], memo);
  memo.emplace(n, total);
  return total;
}

// The shape of the whole tree. Collapsing pairs of binary levels from the root can leave the
// bottom level full of 2-child nodes (about 1.67 nodes per leaf when n is just above a power of
// two); giving the root only its two halves shifts the pairing by one level and fills the bottom
// instead. Taking whichever needs fewer nodes keeps the ratio at or below 1.5 for every n.
struct TreeShape {
  std::size_t node_count = 1;
  bool root_halves_only = false;
};

TreeShape tree_shape(std::uint32_t n) {
  std::map<std::uint32_t, std::size_t> memo;
  TreeShape shape{node_count_of(n, memo), false};
  if (n >= 4) {
    const ChildRanges halves = child_ranges(n, true);
    const std::size_t two_way =
        1 + node_count_of(halves.size[0], memo) + node_count_of(halves.size[1], memo);
    if (two_way < shape.node_count) shape = {two_way, true};
  }
  return shape;
}





// Pass 2: lays out the breadth-first node array for n points. Fills first_child and child_count
// of every node, the input range start of every node (`range_begin`, needed for leaves), and
// returns the start index of every level plus the end (levels[d] .. levels[d + 1]).
std::vector<std::size_t> lay_out_nodes(std::uint32_t n, const TreeShape& shape,
                                       std::vector<SphereNode>& nodes,
                                       std::vector<std::uint32_t>& range_begin, ThreadPool& pool) {
  std::vector<std::uint32_t> range_size(nodes.size());
  range_begin[0] = 0;
  range_size[0] = n;
  std::vector<std::size_t> levels{0, 1};
  for (;;) {
    const std::size_t level_begin = levels[levels.size() - 2], level_end = levels.back();
    const std::size_t count = level_end - level_begin;
    const std::size_t chunks = (count + kNodeGrain - 1) / kNodeGrain;
    // Children are numbered in parent order: count per chunk, then scan.
    std::vector<std::size_t> chunk_first(chunks + 1, 0);
    parallel_for(pool, count, kNodeGrain, [&](std::size_t begin, std::size_t end) {
      std::size_t sum = 0;
      for (std::size_t i = level_begin + begin; i < level_begin + end; ++i) {
        sum += i == 0 && shape.root_halves_only ? 2 : child_count_of(range_size[i]);
      }
      chunk_first[begin / kNodeGrain + 1] = sum;
    });
    chunk_first[0] = level_end;
    for (std::size_t c = 0; c < chunks; ++c) chunk_first[c + 1] += chunk_first[c];
    if (chunk_first[chunks] == level_end) break;  // every node of this level is a leaf
    parallel_for(pool, count, kNodeGrain, [&](std::size_t begin, std::size_t end) {
      std::size_t next = chunk_first[begin / kNodeGrain];
      for (std::size_t i = level_begin + begin; i < level_begin + end; ++i) {
        if (range_size[i] < 2) continue;
        const ChildRanges c = child_ranges(range_size[i], i == 0 && shape.root_halves_only);
        nodes[i].first_child = static_cast<std::uint32_t>(next);
        nodes[i].child_count = static_cast<std::uint8_t>(c.count);
        for (std::uint32_t k = 0; k < c.count; ++k, ++next) {
          range_begin[next] = range_begin[i] + c.offset[k];
          range_size[next] = c.size[k];
        }
      }
    });
    levels.push_back(chunk_first[chunks]);
  }
  return levels;
}

// Pass 3: leaves take their splat (one pass over all nodes, so the gathers from the point arrays
// overlap), then interior nodes bound their finished children, level by level from the bottom.
void compute_attributes(const PointSet& points, std::span<const std::uint32_t> order,
                        const std::vector<std::uint32_t>& range_begin,
                        const std::vector<std::size_t>& levels, std::vector<SphereNode>& nodes,
                        ThreadPool& pool, ProgressPhase& phase) {
  const bool has_colors = points.has_colors();
  parallel_for(pool, nodes.size(), kNodeGrain, [&](std::size_t begin, std::size_t end) {
    std::size_t leaves = 0;
    for (std::size_t i = begin; i < end; ++i) {
      SphereNode& node = nodes[i];
      if (node.child_count != 0) continue;
      const std::uint32_t p = order[range_begin[i]];
      node.center = points.positions[p];
      node.radius = points.radii[p];
      node.normal = points.normals[p];
      node.cone_sin = 0;
      if (has_colors) node.color = points.colors[p];
      ++leaves;
    }
    phase.advance(leaves);
  });
  for (std::size_t d = levels.size() - 1; d-- > 0;) {
    const std::size_t level_begin = levels[d];
    parallel_for(pool, levels[d + 1] - level_begin, kNodeGrain,
                 [&](std::size_t begin, std::size_t end) {
      std::size_t interior = 0;
      for (std::size_t i = level_begin + begin; i < level_begin + end; ++i) {
        SphereNode& node = nodes[i];
        if (node.child_count == 0) continue;
        lod_detail::combine_children({&nodes[node.first_child], node.child_count}, node);
        ++interior;
      }
      phase.advance(interior);
    });
  }
}

}  // namespace

bool sphere_tree_root_halves(std::uint64_t n) {
  return n < (std::uint64_t{1} << 32) && tree_shape(static_cast<std::uint32_t>(n)).root_halves_only;
}

SphereTree build_sphere_tree(const PointSet& points, ThreadPool& pool, Progress& progress,
                             const SphereTreeOptions& options,
                             std::vector<std::uint32_t>* split_order) {
  lod_detail::check_splat_attributes(points, "cannot build a splat hierarchy");
  const auto n = static_cast<std::uint32_t>(points.size());
  SphereTree tree;
  tree.has_colors = points.has_colors();
  tree.leaf_count = n;
  tree.origin = points.origin;
  tree.up = points.up;
  tree.bounds =
      lod_detail::check_points_and_bound(points, pool, "cannot build a splat hierarchy");
  tree.view_sphere = {tree.bounds.center(),
                      lod_detail::max_distance(points.positions, tree.bounds.center(), pool)};

  const TreeShape shape = tree_shape(n);
  ProgressPhase phase(progress, "hierarchy", std::uint64_t{n} + shape.node_count);

  // The partition first: its per-axis lists are freed before the node array is allocated.
  std::vector<std::uint32_t> order;
  if (options.presorted) {
    order.resize(n);
    for (std::uint32_t i = 0; i < n; ++i) order[i] = i;
  } else {
    order = lod_detail::median_split_order(points.positions, pool, options.parallel_grain_points,
                                           progress, options.morton_labels_from,
                                           options.morton_order);
  }

  tree.nodes.resize(shape.node_count);
  std::vector<std::uint32_t> range_begin(shape.node_count);
  const std::vector<std::size_t> levels = lay_out_nodes(n, shape, tree.nodes, range_begin, pool);
  tree.depth = static_cast<std::uint32_t>(levels.size() - 2);

  compute_attributes(points, order, range_begin, levels, tree.nodes, pool, phase);
  if (split_order) *split_order = std::move(order);
  return tree;
}

}  // namespace pointillist
