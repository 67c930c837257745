// The cut of a sphere tree at one node size: what QSplat's traversal draws under a
// view-independent threshold (sphere_tree.hpp).
#include <algorithm>
#include <cmath>

#include "pointillist/lod/sphere_tree.hpp"

namespace pointillist {
namespace {

// The nodes of the cut at radius r, by a walk from the root: a node is taken when it is a leaf
// or no larger than r, else its children are visited.
template <typename Take>
void walk_cut(const SphereTree& tree, float r, Take&& take) {
  std::vector<std::uint32_t> stack = {0};
  while (!stack.empty()) {
    const std::uint32_t i = stack.back();
    stack.pop_back();
    const SphereNode& node = tree.nodes[i];
    if (node.child_count == 0 || node.radius <= r) {
      take(node);
      continue;
    }
    for (std::uint32_t c = node.child_count; c-- > 0;) stack.push_back(node.first_child + c);
  }
}

std::size_t cut_size(const SphereTree& tree, float r) {
  std::size_t count = 0;
  walk_cut(tree, r, [&](const SphereNode&) { ++count; });
  return count;
}

}  // namespace

PointSet sphere_tree_cut(const SphereTree& tree, std::size_t target) {
  PointSet out;
  if (tree.nodes.empty()) return out;
  // The cut grows as r shrinks: bisect r between 0 (every leaf) and the root's radius (the
  // root alone), in log scale, for the count nearest the target.
  float lo = tree.nodes[0].radius * 1e-7f, hi = tree.nodes[0].radius;
  float best = hi;
  std::size_t best_count = 1;
  const auto miss = [&](std::size_t c) { return std::abs(double(c) - double(target)); };
  for (int pass = 0; pass < 40 && hi > lo * 1.0001f; ++pass) {
    const float mid = std::sqrt(lo * hi);
    const std::size_t c = cut_size(tree, mid);
    if (miss(c) < miss(best_count)) best = mid, best_count = c;
    if (c == target) break;
    (c > target ? lo : hi) = mid;
  }
  walk_cut(tree, best, [&](const SphereNode& node) {
    out.positions.push_back(node.center);
    out.normals.push_back(node.normal);
    out.radii.push_back(node.radius);
    if (tree.has_colors) out.colors.push_back(node.color);
  });
  return out;
}

}  // namespace pointillist
