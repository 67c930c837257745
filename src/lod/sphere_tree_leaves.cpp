// The leaves of a bounding-sphere hierarchy as a point set, and their largest radius.
#include <algorithm>
#include "pointillist/lod/sphere_tree.hpp"

#include <string>

#include "pointillist/core/error.hpp"

namespace pointillist {

float largest_leaf_radius(const SphereTreeView& tree) {
  float largest = 0;
  for (const SphereNode& n : tree.nodes) {
    if (n.child_count == 0) largest = std::max(largest, n.radius);
  }
  return largest;
}

PointSet sphere_tree_leaves(const SphereTreeView& tree) {
  PointSet p;
  p.positions.reserve(tree.leaf_count);
  p.normals.reserve(tree.leaf_count);
  p.radii.reserve(tree.leaf_count);
  if (tree.has_colors) p.colors.reserve(tree.leaf_count);
  for (const SphereNode& n : tree.nodes) {
    if (n.child_count != 0) continue;
    p.positions.push_back(n.center);
    p.normals.push_back(n.normal);
    p.radii.push_back(n.radius);
    if (tree.has_colors) p.colors.push_back(n.color);
  }
  return p;
}

std::vector<std::array<std::uint32_t, 3>> leaf_triangles(
    const SphereTreeView& tree, std::span<const std::uint32_t> split_order,
    std::span<const std::array<std::uint32_t, 3>> triangles) {
  const std::size_t n = split_order.size();
  if (tree.leaf_count != n) {
    throw Error("mesh faces onto the hierarchy: " + std::to_string(tree.leaf_count) +
                " leaves but a split order of " + std::to_string(n) + " points");
  }
  // Leaves in depth-first order are the split order's ranges in order (children are the parts
  // of their parent's range, in order); node order is breadth-first.
  std::vector<std::uint32_t> leaf_index(tree.nodes.size(), 0);
  {
    std::uint32_t k = 0;
    for (std::size_t i = 0; i < tree.nodes.size(); ++i) {
      if (tree.nodes[i].child_count == 0) leaf_index[i] = k++;
    }
  }
  std::vector<std::uint32_t> leaf_of_point(n, 0);
  std::vector<std::uint32_t> stack;
  if (!tree.nodes.empty()) stack.push_back(0);
  std::uint32_t rank = 0;
  while (!stack.empty()) {
    const std::uint32_t i = stack.back();
    stack.pop_back();
    const SphereNode& node = tree.nodes[i];
    if (node.child_count == 0) {
      if (rank >= n) throw Error("mesh faces onto the hierarchy: more leaves than points");
      leaf_of_point[split_order[rank++]] = leaf_index[i];
      continue;
    }
    for (int c = node.child_count - 1; c >= 0; --c) stack.push_back(node.first_child + c);
  }
  std::vector<std::array<std::uint32_t, 3>> out(triangles.size());
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      if (triangles[t][k] >= n) {
        throw Error("mesh faces onto the hierarchy: face " + std::to_string(t) +
                    " refers to point " + std::to_string(triangles[t][k]) + " of " +
                    std::to_string(n));
      }
      out[t][k] = leaf_of_point[triangles[t][k]];
    }
  }
  return out;
}

}  // namespace pointillist
