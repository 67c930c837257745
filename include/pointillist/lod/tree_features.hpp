// Sharp-feature data of a sphere tree's nodes (spec Q15): every leaf carries its splat's surface
// id and clip planes; an inner node the common surface id of its subtree, or kMixedSurface when
// the subtree holds several, and no planes (coarse levels draw as without features).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "pointillist/features/features.hpp"
#include "pointillist/lod/sequential_point_tree.hpp"
#include "pointillist/lod/sphere_tree.hpp"

namespace pointillist {

struct TreeFeatures {
  std::vector<std::uint32_t> surface;      // per node
  std::vector<ClipMode> clip_mode;         // per node (None for inner nodes)
  std::vector<std::uint32_t> clip_offset;  // per node + 1, into clip_planes
  std::vector<ClipPlane> clip_planes;
  std::uint32_t surface_count = 0;  // ids are 0 .. surface_count − 1 (or kMixedSurface)
  FeatureOptions options;           // what they were computed with
  FeatureStats stats;

  bool empty() const { return surface.empty(); }
  std::span<const ClipPlane> planes(std::size_t node) const {
    return {clip_planes.data() + clip_offset[node], clip_planes.data() + clip_offset[node + 1]};
  }
};

// Spreads `leaves` (features of the tree's leaves in node order, as sphere_tree_leaves lists
// them) over the nodes. Throws Error when the counts differ.
TreeFeatures tree_features(std::span<const SphereNode> nodes, const FeatureData& leaves);

// The same features on the entries of `spt`, a Sequential Point Tree built from the leaves of the
// sphere tree `nodes` (sphere_tree_leaves order): a leaf entry takes its splat's surface id and
// planes, an interior entry the common id of its subtree, or kMixedSurface, and no planes.
// Throws Error when the SPT's leaves are not the tree's.
TreeFeatures spt_features(const SequentialPointTree& spt, std::span<const SphereNode> nodes,
                          const TreeFeatures& features);

// compute_features on the tree's leaves (sphere_tree_leaves), then tree_features.
TreeFeatures compute_tree_features(const SphereTreeView& tree, ThreadPool& pool,
                                   const FeatureOptions& options = {},
                                   Progress& progress = Progress::none());

}  // namespace pointillist
