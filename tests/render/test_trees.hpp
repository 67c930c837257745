// Hierarchies for the render tests, built here by plain recursion so that the renderer's tests do
// not depend on src/lod: binary median splits, conservative spheres and normal cones.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <numeric>
#include <vector>

#include "pointillist/core/point_set.hpp"
#include "pointillist/lod/sphere_tree.hpp"

namespace pointillist::render_test {

// Lays out nodes given as (node, children) breadth first. `children[i]` lists the children of
// temporary node i; node 0 is the root.
inline SphereTree layout_breadth_first(const std::vector<SphereNode>& tmp,
                                       const std::vector<std::vector<std::uint32_t>>& children) {
  SphereTree tree;
  std::vector<std::uint32_t> order{0};
  for (std::size_t k = 0; k < order.size(); ++k) {
    for (std::uint32_t c : children[order[k]]) order.push_back(c);
  }
  std::vector<std::uint32_t> new_index(tmp.size());
  for (std::size_t k = 0; k < order.size(); ++k) new_index[order[k]] = static_cast<std::uint32_t>(k);
  tree.nodes.resize(order.size());
  std::uint32_t max_depth = 0;
  std::vector<std::uint32_t> depth(tmp.size(), 0);
  for (std::size_t k = 0; k < order.size(); ++k) {
    const std::uint32_t old = order[k];
    SphereNode n = tmp[old];
    n.child_count = static_cast<std::uint8_t>(children[old].size());
    n.first_child = children[old].empty() ? 0 : new_index[children[old][0]];
    for (std::uint32_t c : children[old]) depth[c] = depth[old] + 1;
    max_depth = std::max(max_depth, depth[old]);
    if (children[old].empty()) ++tree.leaf_count;
    tree.nodes[k] = n;
  }
  tree.depth = max_depth;
  return tree;
}

// Builds a hierarchy over points with normals and radii (colors optional): median split along
// the longest axis of the box of the centres until one point is left. Interior spheres enclose
// their children's spheres (with a relative margin of 1e-5); normal cones are computed in double
// and enlarged by 1e-4 radians.
inline SphereTree make_test_tree(const PointSet& pts) {
  std::vector<SphereNode> tmp;
  std::vector<std::vector<std::uint32_t>> children;
  std::vector<std::uint32_t> idx(pts.size());
  std::iota(idx.begin(), idx.end(), 0u);
  std::function<std::uint32_t(std::size_t, std::size_t)> build = [&](std::size_t b,
                                                                      std::size_t e) {
    const auto me = static_cast<std::uint32_t>(tmp.size());
    tmp.emplace_back();
    children.emplace_back();
    if (e - b == 1) {
      const std::uint32_t p = idx[b];
      SphereNode n;
      n.center = pts.positions[p];
      n.radius = pts.radii[p];
      n.normal = pts.normals[p];
      n.cone_sin = 0;
      if (pts.has_colors()) n.color = pts.colors[p];
      tmp[me] = n;
      return me;
    }
    Aabb box;
    for (std::size_t i = b; i < e; ++i) box.extend(pts.positions[idx[i]]);
    const int axis = box.longest_axis();
    const std::size_t mid = b + (e - b) / 2;
    std::nth_element(idx.begin() + b, idx.begin() + mid, idx.begin() + e,
                     [&](std::uint32_t l, std::uint32_t r) {
                       return pts.positions[l][axis] < pts.positions[r][axis];
                     });
    const std::uint32_t c0 = build(b, mid);
    const std::uint32_t c1 = build(mid, e);
    children[me] = {c0, c1};
    const SphereNode& a = tmp[c0];
    const SphereNode& z = tmp[c1];
    SphereNode n;
    Aabb cb;
    for (const SphereNode* ch : {&a, &z}) {
      cb.extend(ch->center - Vec3f{ch->radius, ch->radius, ch->radius});
      cb.extend(ch->center + Vec3f{ch->radius, ch->radius, ch->radius});
    }
    n.center = cb.center();
    double r = 0;
    for (const SphereNode* ch : {&a, &z}) r = std::max(r, double(distance(n.center, ch->center)) + ch->radius);
    n.radius = static_cast<float>(r * (1 + 1e-5));
    const Vec3f sum = a.normal * (a.radius * a.radius) + z.normal * (z.radius * z.radius);
    n.cone_sin = 2.0f;  // no bound unless computed below
    n.normal = {0, 0, 1};
    if (length(sum) > 1e-6f && a.cone_sin < 1 && z.cone_sin < 1) {
      n.normal = normalized(sum);
      double theta = 0;
      for (const SphereNode* ch : {&a, &z}) {
        const double c = std::clamp(double(dot(n.normal, ch->normal)), -1.0, 1.0);
        theta = std::max(theta, std::acos(c) + std::asin(double(ch->cone_sin)) + 1e-4);
      }
      if (theta < 1.5) n.cone_sin = static_cast<float>(std::sin(theta) + 1e-6);
    }
    n.color = {static_cast<std::uint8_t>((a.color.r + z.color.r) / 2),
               static_cast<std::uint8_t>((a.color.g + z.color.g) / 2),
               static_cast<std::uint8_t>((a.color.b + z.color.b) / 2)};
    tmp[me] = n;
    return me;
  };
  build(0, pts.size());
  SphereTree tree = layout_breadth_first(tmp, children);
  tree.has_colors = pts.has_colors();
  tree.bounds = bounding_box(pts.positions);
  tree.view_sphere = view_sphere(pts.positions);
  return tree;
}

}  // namespace pointillist::render_test
