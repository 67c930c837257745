// The leaves of a bounding-sphere hierarchy as a point set.
#include "pointillist/lod/sphere_tree.hpp"

namespace pointillist {

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

}  // namespace pointillist
