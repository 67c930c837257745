// Occlusion culling's per-model hierarchies (renderer_state.hpp): a sphere tree cut down to
// culling leaves, and a Sequential Point Tree's ranges under one root.
#include <algorithm>
#include <vector>

#include "renderer_state.hpp"

namespace pointillist {

namespace render_detail {

// The smallest sphere around `a` and `b` (a sphere holding both).
Sphere enclose(const Sphere& a, const Sphere& b) {
  const Vec3f d = b.center - a.center;
  const float dist = length(d);
  if (dist + b.radius <= a.radius) return a;
  if (dist + a.radius <= b.radius) return b;
  const float r = 0.5f * (dist + a.radius + b.radius);
  return {a.center + d * ((r - a.radius) / dist), r * (1.0f + 1e-6f)};
}

Sphere world_sphere(const InstanceTransform& t, const Sphere& s) {
  return {t.apply(s.center), s.radius * t.scale * (1.0f + 1e-6f)};
}
Sphere world_sphere(const InstanceTransform& t, const SphereNode& n) {
  return world_sphere(t, Sphere{n.center, n.radius});
}


ModelCullTree build_cull_tree(std::span<const SphereNode> nodes, std::uint32_t leaf_points) {
  ModelCullTree t;
  t.leaf_points = leaf_points;
  if (nodes.empty()) return t;
  // Points below each node: children come after their parent, so one backward pass.
  std::vector<std::uint32_t> points(nodes.size(), 1);
  for (std::size_t i = nodes.size(); i-- > 0;) {
    const SphereNode& n = nodes[i];
    if (n.child_count == 0) continue;
    std::uint64_t sum = 0;
    for (std::uint32_t k = 0; k < n.child_count; ++k) sum += points[n.first_child + k];
    points[i] = static_cast<std::uint32_t>(std::min<std::uint64_t>(sum, UINT32_MAX));
  }
  // Depth first from the root; a node with more than leaf_points points is opened.
  struct Todo {
    std::uint32_t node, parent;
  };
  std::vector<Todo> stack{{0, UINT32_MAX}};
  while (!stack.empty()) {
    const Todo todo = stack.back();
    stack.pop_back();
    const std::uint32_t local = static_cast<std::uint32_t>(t.nodes.size());
    t.nodes.push_back({todo.node, todo.parent, 0, 0, 1, points[todo.node]});
    if (todo.parent != UINT32_MAX) t.children.push_back(local);  // placeholder order fixed below
    const SphereNode& n = nodes[todo.node];
    if (n.child_count > 0 && points[todo.node] > leaf_points) {
      for (std::uint32_t k = n.child_count; k-- > 0;) stack.push_back({n.first_child + k, local});
    }
  }
  // Children lists: each node's children in order, contiguous.
  t.children.assign(t.nodes.size() > 0 ? t.nodes.size() - 1 : 0, 0);
  std::vector<std::uint32_t> count(t.nodes.size(), 0);
  for (std::size_t i = 1; i < t.nodes.size(); ++i) ++count[t.nodes[i].parent];
  std::uint32_t next = 0;
  for (std::size_t i = 0; i < t.nodes.size(); ++i) {
    t.nodes[i].first_child = next;
    next += count[i];
  }
  std::vector<std::uint32_t> filled(t.nodes.size(), 0);
  for (std::size_t i = 1; i < t.nodes.size(); ++i) {
    ModelCullTree::Node& p = t.nodes[t.nodes[i].parent];
    t.children[p.first_child + filled[t.nodes[i].parent]++] = static_cast<std::uint32_t>(i);
  }
  for (std::size_t i = 0; i < t.nodes.size(); ++i) t.nodes[i].child_count = count[i];
  // Culling leaves below each node (children after parents: backward).
  for (std::size_t i = t.nodes.size(); i-- > 0;) {
    ModelCullTree::Node& n = t.nodes[i];
    if (n.child_count == 0) continue;
    n.culling_leaves = 0;
    for (std::uint32_t k = 0; k < n.child_count; ++k) {
      n.culling_leaves += t.nodes[t.children[n.first_child + k]].culling_leaves;
    }
  }
  return t;
}

ModelCullTree build_spt_cull_tree(const SequentialPointTree& spt) {
  ModelCullTree t;
  t.nodes.push_back({kSptTopList + 1, UINT32_MAX, 0, 0, 0,
                     static_cast<std::uint32_t>(spt.node_count())});
  const auto leaf = [&](std::uint32_t range, std::uint32_t entries) {
    t.children.push_back(static_cast<std::uint32_t>(t.nodes.size()));
    t.nodes.push_back({range, 0, 0, 0, 1, entries});
  };
  if (spt.top_end > 0) leaf(kSptTopList, spt.top_end);
  for (std::uint32_t k = 0; k < spt.chunks.size(); ++k) {
    leaf(k, spt.chunks[k].end - spt.chunks[k].begin);
  }
  t.nodes[0].child_count = static_cast<std::uint32_t>(t.nodes.size() - 1);
  t.nodes[0].culling_leaves = t.nodes[0].child_count;
  return t;
}

}  // namespace render_detail

}  // namespace pointillist
