// Hybrid point/polygon lists over a Sequential Point Tree (see hybrid_lod.hpp for the rule).
#include "pointillist/lod/hybrid_lod.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>

#include "pointillist/core/error.hpp"

namespace pointillist {
namespace {

// E_t is stored this much larger than the largest e'_v of its vertices, so that the triangle test
// (r_t·ε < E_t) passes wherever a vertex's own test (e'_v ≤ r_v·ε) failed, whatever rounding or
// contraction the two vectorized passes compile to.
constexpr float kTriangleSlack = 1.0f + 1.0f / (1 << 20);

// The chunk holding list entry `entry` (chunks cover [top_end, node_count) in order).
std::uint32_t chunk_of(const SequentialPointTree& tree, std::uint32_t entry) {
  const auto it = std::upper_bound(
      tree.chunks.begin(), tree.chunks.end(), entry,
      [](std::uint32_t e, const SptChunk& c) { return e < c.begin; });
  return static_cast<std::uint32_t>(it - tree.chunks.begin()) - 1;
}

}  // namespace

HybridLod build_hybrid_lod(const SequentialPointTree& tree, const PointSet& leaves,
                           std::span<const std::array<std::uint32_t, 3>> triangles,
                           const HybridLodOptions& options) {
  if (!(options.triangle_px_per_epsilon > 0.0f) || !std::isfinite(options.triangle_px_per_epsilon)) {
    throw OptionError("triangle size " + std::to_string(options.triangle_px_per_epsilon) +
                      " (times the error bound, in pixels) is invalid; give a positive number "
                      "(4 draws triangles whose edges are longer than 4 px at --epsilon 1)");
  }
  const std::size_t n = leaves.size();
  if (tree.leaf_count != n || leaves.normals.size() != n ||
      (tree.has_colors && leaves.colors.size() != n)) {
    throw Error("hybrid lists: the point tree has " + std::to_string(tree.leaf_count) +
                " leaves but " + std::to_string(n) +
                " leaf points (with normals and colours) were given; build both from one model");
  }
  HybridLod h;
  h.triangle_px_per_epsilon = options.triangle_px_per_epsilon;
  h.view_sphere = tree.view_sphere;
  h.positions = leaves.positions;
  h.normals = leaves.normals;
  if (tree.has_colors) h.colors = leaves.colors;
  h.suppress_below.assign(tree.node_count(), 0.0f);
  h.groups.resize(tree.chunks.size());
  if (n == 0 || tree.chunks.empty()) return h;

  // Each leaf's list entry.
  constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
  std::vector<std::uint32_t> entry_of(n, kNone);
  for (std::uint32_t e = 0; e < tree.node_count(); ++e) {
    if (tree.is_leaf[e] && tree.source[e] < n) entry_of[tree.source[e]] = e;
  }
  for (std::size_t v = 0; v < n; ++v) {
    if (entry_of[v] == kNone) {
      throw Error("hybrid lists: leaf " + std::to_string(v) +
                  " has no entry in the point tree; build both from one model");
    }
  }

  // e_t, and m_N bottom-up (a parent's index is smaller than its children's).
  const float per_edge = 1.0f / options.triangle_px_per_epsilon;
  const float inf = std::numeric_limits<float>::infinity();
  const std::size_t entries = tree.node_count();
  std::vector<float> m(entries, inf);
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const auto& tri = triangles[t];
    for (int k = 0; k < 3; ++k) {
      if (tri[k] >= n) {
        throw Error("hybrid lists: triangle " + std::to_string(t) + " refers to vertex " +
                    std::to_string(tri[k]) + " of " + std::to_string(n) +
                    "; the mesh's faces do not match its points");
      }
    }
    const Vec3f a = leaves.positions[tri[0]], b = leaves.positions[tri[1]],
                c = leaves.positions[tri[2]];
    const float own = std::max({length(b - a), length(c - b), length(a - c)}) * per_edge;
    for (int k = 0; k < 3; ++k) m[entry_of[tri[k]]] = std::min(m[entry_of[tri[k]]], own);
  }
  for (std::size_t e = entries; e-- > 1;) {
    const std::uint32_t p = tree.parent[e];
    if (p != kSptNoParent) m[p] = std::min(m[p], m[e]);
  }
  // s_N, then top-down the largest s on each path from the root (in m's place).
  for (std::size_t e = 0; e < entries; ++e) {
    const float s = m[e] == inf ? 0.0f
                                : std::min(std::max(tree.error[e], m[e]), tree.parent_error[e]);
    const bool suppressible = s > tree.error[e];
    h.suppress_below[e] = suppressible ? s : 0.0f;
    (tree.is_leaf[e] ? h.suppressible_leaves : h.suppressible_interior) += suppressible;
    const std::uint32_t p = tree.parent[e];
    m[e] = std::max(p == kSptNoParent ? 0.0f : m[p], h.suppress_below[e]);
  }

  // E_t, the groups, and the order within each group.
  std::vector<float> big_e(triangles.size());
  std::vector<std::uint32_t> group_of(triangles.size());
  std::vector<std::uint32_t> group_size(tree.chunks.size() + 1, 0);
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const auto& tri = triangles[t];
    big_e[t] = std::max({m[entry_of[tri[0]]], m[entry_of[tri[1]]], m[entry_of[tri[2]]]}) *
               kTriangleSlack;
    group_of[t] = chunk_of(tree, entry_of[tri[0]]);
    ++group_size[group_of[t] + 1];
  }
  std::partial_sum(group_size.begin(), group_size.end(), group_size.begin());
  std::vector<std::uint32_t> order(triangles.size());
  {
    std::vector<std::uint32_t> next(group_size.begin(), group_size.end() - 1);
    for (std::uint32_t t = 0; t < triangles.size(); ++t) order[next[group_of[t]]++] = t;
  }
  h.triangles.resize(triangles.size());
  h.triangle_error.resize(triangles.size());
  for (std::size_t g = 0; g < tree.chunks.size(); ++g) {
    HybridTriangleGroup& group = h.groups[g];
    group.begin = group_size[g];
    group.end = group_size[g + 1];
    std::stable_sort(order.begin() + group.begin, order.begin() + group.end,
                     [&](std::uint32_t x, std::uint32_t y) { return big_e[x] > big_e[y]; });
    group.bounds.center = tree.chunks[g].bounds.center;
    float r2 = 0;
    for (std::uint32_t k = group.begin; k < group.end; ++k) {
      const auto& tri = triangles[order[k]];
      h.triangles[k] = tri;
      h.triangle_error[k] = big_e[order[k]];
      for (int c = 0; c < 3; ++c) {
        const Vec3f d = leaves.positions[tri[c]] - group.bounds.center;
        r2 = std::max(r2, dot(d, d));
      }
    }
    group.bounds.radius = std::sqrt(r2) * kTriangleSlack;
  }
  return h;
}

}  // namespace pointillist
