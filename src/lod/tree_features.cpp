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

TreeFeatures spt_features(const SequentialPointTree& spt, std::span<const SphereNode> nodes,
                          const TreeFeatures& features) {
  std::vector<std::uint32_t> leaf_node;  // sphere-tree node of each leaf, in node order
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    if (nodes[k].child_count == 0) leaf_node.push_back(static_cast<std::uint32_t>(k));
  }
  const std::size_t count = spt.node_count();
  if (spt.source.size() != count || spt.parent.size() != count ||
      spt.leaf_count != leaf_node.size()) {
    throw Error("sharp features: the sequential point tree of " + std::to_string(spt.leaf_count) +
                " splats was not built from this tree's " + std::to_string(leaf_node.size()) +
                " leaves");
  }
  TreeFeatures out;
  out.options = features.options;
  out.stats = features.stats;
  out.surface_count = features.surface_count;
  out.surface.assign(count, kMixedSurface);
  out.clip_mode.assign(count, ClipMode::None);
  out.clip_offset.assign(count + 1, 0);
  // Ids: leaves first; then children come after their parent in the list, so a backward sweep
  // has folded every child into its parent before the parent passes its id on. `kUnset` marks
  // an interior entry no child has reached yet.
  constexpr std::uint32_t kUnset = kMixedSurface - 1;
  for (std::size_t i = 0; i < count; ++i) {
    if (spt.is_leaf[i]) {
      const std::uint32_t s = spt.source[i];
      if (s >= leaf_node.size()) {
        throw Error("sharp features: SPT entry " + std::to_string(i) + " names splat " +
                    std::to_string(s) + " of " + std::to_string(leaf_node.size()));
      }
      const std::uint32_t node = leaf_node[s];
      out.surface[i] = features.surface[node];
      out.clip_mode[i] = features.clip_mode[node];
    } else {
      out.surface[i] = kUnset;
    }
  }
  for (std::size_t i = count; i-- > 0;) {
    const std::uint32_t p = spt.parent[i];
    if (p == kSptNoParent) continue;
    std::uint32_t& id = out.surface[p];
    id = id == kUnset ? out.surface[i] : (id == out.surface[i] ? id : kMixedSurface);
  }
  for (std::size_t i = 0; i < count; ++i) {
    if (out.surface[i] == kUnset) out.surface[i] = kMixedSurface;
    if (spt.is_leaf[i]) {
      const auto planes = features.planes(leaf_node[spt.source[i]]);
      out.clip_planes.insert(out.clip_planes.end(), planes.begin(), planes.end());
    }
    out.clip_offset[i + 1] = static_cast<std::uint32_t>(out.clip_planes.size());
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
