// Occlusion culling's per-model hierarchies (renderer_state.hpp): a sphere tree cut down to
// culling leaves, and a Sequential Point Tree's ranges under one root.
#include <algorithm>
#include <functional>
#include <numeric>
#include <cmath>
#include <limits>
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


SoftwareQueries::Rect chunk_pixel_rect(const SplatChunk& chunk, const CameraFrame& cam) {
  if (chunk.count == 0) return {};
  // A splat covers pixel centres within its disc, or the pixel of its centre.
  float x0 = std::numeric_limits<float>::infinity(), y0 = x0, x1 = -x0, y1 = -x0;
  for (std::size_t i = 0; i < chunk.count; ++i) {
    const float r = 0.5f * chunk.size_px[i] + 1.0f;
    x0 = std::min(x0, chunk.x_px[i] - r);
    x1 = std::max(x1, chunk.x_px[i] + r);
    y0 = std::min(y0, chunk.y_px[i] - r);
    y1 = std::max(y1, chunk.y_px[i] + r);
  }
  const auto clampi = [](float v, int hi) {
    return static_cast<int>(std::clamp(v, 0.0f, static_cast<float>(hi)));
  };
  return {clampi(std::floor(x0), cam.width), clampi(std::floor(y0), cam.height),
          clampi(std::ceil(x1) + 1, cam.width), clampi(std::ceil(y1) + 1, cam.height)};
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

void build_scene_hierarchy(std::span<const SceneInstance> scene,
                           const std::function<const ModelCullTree&(std::uint32_t)>& cull_tree,
                           const std::function<Sphere(std::uint32_t, const ModelCullTree::Node&)>&
                               model_bound,
                           SceneHierarchy& h) {
  // BVH over the instances' world spheres: median split on the longest axis of the centres.
  std::vector<std::uint32_t> order(scene.size());
  std::iota(order.begin(), order.end(), 0u);
  std::vector<Sphere> world(scene.size());
  for (std::size_t i = 0; i < scene.size(); ++i) {
    const ModelCullTree& t = cull_tree(static_cast<std::uint32_t>(i));
    world[i] = t.nodes.empty()
                   ? Sphere{scene[i].transform.translate, 0.0f}
                   : world_sphere(scene[i].transform, model_bound(static_cast<std::uint32_t>(i),
                                                                   t.nodes[0]));
  }
  h.instance_root.assign(scene.size(), UINT32_MAX);
  struct Build {
    std::uint32_t node, lo, hi;
  };
  const auto add_node = [&](std::uint32_t parent) {
    h.h.nodes.push_back({});
    h.h.nodes.back().parent = parent;
    h.meta.push_back({});
    return static_cast<std::uint32_t>(h.h.nodes.size() - 1);
  };
  // Splits first (parents before children), spheres afterwards bottom-up.
  std::vector<std::vector<std::uint32_t>> kids;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> leaf_instance;  // (bvh node, instance)
  std::vector<Build> todo{{add_node(UINT32_MAX), 0, static_cast<std::uint32_t>(scene.size())}};
  kids.emplace_back();
  while (!todo.empty()) {
    const Build b = todo.back();
    todo.pop_back();
    if (b.hi - b.lo == 1) {
      leaf_instance.emplace_back(b.node, order[b.lo]);
      continue;
    }
    Aabb box;
    for (std::uint32_t k = b.lo; k < b.hi; ++k) box.extend(world[order[k]].center);
    const Vec3f e = box.hi - box.lo;
    const int axis = e.x >= e.y && e.x >= e.z ? 0 : (e.y >= e.z ? 1 : 2);
    const std::uint32_t mid = b.lo + (b.hi - b.lo) / 2;
    std::nth_element(order.begin() + b.lo, order.begin() + mid, order.begin() + b.hi,
                     [&](std::uint32_t a, std::uint32_t b2) {
                       const float ca = world[a].center[axis], cb = world[b2].center[axis];
                       return ca < cb || (ca == cb && a < b2);
                     });
    for (const auto& [lo, hi] : {std::pair{mid, b.hi}, std::pair{b.lo, mid}}) {
      const std::uint32_t child = add_node(b.node);
      kids.emplace_back();
      kids[b.node].push_back(child);
      todo.push_back({child, lo, hi});
    }
  }
  // Children lists of the BVH nodes (in split order: lower half first).
  for (std::uint32_t n = 0; n < kids.size(); ++n) std::reverse(kids[n].begin(), kids[n].end());
  // Each instance's model nodes, below its BVH leaf (which is the model's root itself).
  for (const auto& leaf : leaf_instance) {
    // Named copies: lambdas below use them (clang 14 cannot capture structured bindings).
    const std::uint32_t bvh_leaf = leaf.first, i = leaf.second;
    const ModelCullTree& t = cull_tree(i);
    if (t.nodes.empty()) continue;
    const std::uint32_t base = static_cast<std::uint32_t>(h.h.nodes.size()) - 1;
    // Local node 0 is the BVH leaf; local k > 0 is base + k.
    const auto global = [&](std::uint32_t local) { return local == 0 ? bvh_leaf : base + local; };
    h.meta[bvh_leaf] = {i, 0};
    h.instance_root[i] = bvh_leaf;
    for (std::uint32_t k = 1; k < t.nodes.size(); ++k) {
      h.h.nodes.push_back({});
      h.meta.push_back({i, k});
      kids.emplace_back();
    }
    for (std::uint32_t k = 0; k < t.nodes.size(); ++k) {
      const ModelCullTree::Node& mn = t.nodes[k];
      CullHierarchy::Node& hn = h.h.nodes[global(k)];
      const Sphere s = world_sphere(scene[i].transform, model_bound(i, mn));
      hn.bound = {s.center, s.radius};
      hn.culling_leaves = mn.culling_leaves;
      if (k > 0) hn.parent = global(mn.parent);
      for (std::uint32_t j = 0; j < mn.child_count; ++j) {
        kids[global(k)].push_back(global(t.children[mn.first_child + j]));
      }
    }
  }
  // Flatten children; BVH spheres and leaf counts bottom-up (children after parents).
  for (std::uint32_t n = 0; n < h.h.nodes.size(); ++n) {
    h.h.nodes[n].first_child = static_cast<std::uint32_t>(h.h.children.size());
    h.h.nodes[n].child_count = static_cast<std::uint32_t>(kids[n].size());
    h.h.children.insert(h.h.children.end(), kids[n].begin(), kids[n].end());
  }
  for (std::uint32_t n = static_cast<std::uint32_t>(h.h.nodes.size()); n-- > 0;) {
    if (h.meta[n].instance != UINT32_MAX) continue;
    CullHierarchy::Node& hn = h.h.nodes[n];
    if (hn.child_count == 0) continue;  // an instance without nodes
    Sphere s{h.h.nodes[kids[n][0]].bound.center, h.h.nodes[kids[n][0]].bound.radius};
    hn.culling_leaves = 0;
    for (const std::uint32_t k : kids[n]) {
      s = enclose(s, {h.h.nodes[k].bound.center, h.h.nodes[k].bound.radius});
      hn.culling_leaves += h.h.nodes[k].culling_leaves;
    }
    hn.bound = {s.center, s.radius};
  }
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
