#include "pointillist/lod/tree_features.hpp"

#include <string>

#include "pointillist/core/error.hpp"

namespace pointillist {

TreeFeatures tree_features(std::span<const SphereNode> nodes, const FeatureData& leaves) {
  TreeFeatures out;
  out.options = leaves.options;
  out.stats = leaves.stats;
  out.surface_count = static_cast<std::uint32_t>(leaves.stats.segments);
  out.surface.assign(nodes.size(), kMixedSurface);
  out.clip_mode.assign(nodes.size(), ClipMode::None);
  out.clip_offset.assign(nodes.size() + 1, 0);
  std::size_t leaf = 0;
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    if (nodes[k].child_count == 0) {
      if (leaf >= leaves.size()) break;
      out.surface[k] = leaves.surface_id[leaf];
      out.clip_mode[k] = leaves.clip_mode[leaf];
      const auto planes = leaves.planes(leaf);
      out.clip_planes.insert(out.clip_planes.end(), planes.begin(), planes.end());
      ++leaf;
    }
    out.clip_offset[k + 1] = static_cast<std::uint32_t>(out.clip_planes.size());
  }
  std::size_t tree_leaves = 0;
  for (const SphereNode& n : nodes) tree_leaves += n.child_count == 0;
  if (tree_leaves != leaves.size()) {
    throw Error("sharp features of " + std::to_string(leaves.size()) + " splats do not fit a tree of " +
                std::to_string(tree_leaves) + " leaves");
  }
  // Children come after their parent: a backward sweep sees every child before its parent.
  for (std::size_t k = nodes.size(); k-- > 0;) {
    const SphereNode& n = nodes[k];
    if (n.child_count == 0) continue;
    std::uint32_t id = out.surface[n.first_child];
    for (std::uint32_t c = 1; c < n.child_count; ++c) {
      if (out.surface[n.first_child + c] != id) id = kMixedSurface;
    }
    out.surface[k] = id;
  }
  return out;
}

TreeFeatures compute_tree_features(const SphereTreeView& tree, ThreadPool& pool,
                                   const FeatureOptions& options, Progress& progress) {
  const PointSet leaves = sphere_tree_leaves(tree);
  const FeatureData data =
      compute_features(leaves.positions, leaves.normals, leaves.radii, pool, options, progress);
  return tree_features(tree.nodes, data);
}

}  // namespace pointillist
