// QSplat bounding-sphere hierarchy (Rusinkiewicz & Levoy, "QSplat: A Multiresolution Point
// Rendering System for Large Meshes", SIGGRAPH 2000).
//
// Nodes are stored breadth-first in one flat array: node 0 is the root, the children of a node
// are `child_count` consecutive nodes starting at `first_child`, and every node's children come
// after it, so the coarse levels are a prefix of the array. Leaves are single input splats.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "pointillist/core/math.hpp"
#include "pointillist/core/point_set.hpp"
#include "pointillist/core/progress.hpp"
#include "pointillist/core/thread_pool.hpp"

namespace pointillist {

struct TreeFeatures;  // lod/tree_features.hpp

// 40 bytes, no padding; written to .ptl files as is (little endian), so the layout is fixed.
struct SphereNode {
  Vec3f center;             // bounding sphere of the subtree (world units)
  float radius = 0;
  Vec3f normal;             // unit mean normal of the subtree (area weighted)
  // Normal cone: sine of the half-angle θ of a cone around `normal` that contains every normal
  // of the subtree. Backface culling of the subtree is possible only when θ < 90°; a value
  // >= 1 means "no bound" (θ >= 90°). Leaves have 0.
  float cone_sin = 0;
  std::uint32_t first_child = 0;  // index of the first child; 0 for leaves
  std::uint8_t child_count = 0;   // 0 for leaves, else 2..4
  Rgb8 color;                     // mean color of the subtree (meaningful when the tree has colors)
};
static_assert(sizeof(SphereNode) == 40, "SphereNode is a file layout");

// Non-owning view of a hierarchy, e.g. over a memory-mapped .ptl file.
struct SphereTreeView {
  std::span<const SphereNode> nodes;
  bool has_colors = false;
  std::uint64_t leaf_count = 0;
  std::uint32_t depth = 0;  // levels below the root (a single leaf has depth 0)
  Aabb bounds;              // box around all sample positions (not radii)
  Sphere view_sphere;       // centre of `bounds`, largest distance to a sample (orbit camera)
  std::array<double, 3> origin{};  // absolute position = origin + position (PointSet::origin)
  Vec3f up{0, 1, 0};               // the model's up axis (PointSet::up)
  // Sharp features of the nodes (surface ids, clip planes), or null.
  const TreeFeatures* features = nullptr;
};

// Owning hierarchy as built in memory.
struct SphereTree {
  std::vector<SphereNode> nodes;
  bool has_colors = false;
  std::uint64_t leaf_count = 0;
  std::uint32_t depth = 0;
  Aabb bounds;
  Sphere view_sphere;
  std::array<double, 3> origin{};
  Vec3f up{0, 1, 0};

  SphereTreeView view() const {
    return {nodes, has_colors, leaf_count, depth, bounds, view_sphere, origin, up};
  }
};

struct SphereTreeOptions {
  // Subtrees smaller than this many points are built by one task; larger ones split in parallel.
  // Only changes speed, never the result.
  std::size_t parallel_grain_points = 1 << 15;
  // From this many points the partition names points by their rank along a Morton curve, so the
  // flags it reads by point stay in cache (20 M points: 0.6-0.7x its time; below about 8 M the
  // ordering costs more than it saves). Only changes speed, never the result.
  std::size_t morton_labels_from = std::size_t{1} << 23;
  // The points' morton_order when the caller has it (prepare_splats makes it for a cloud:
  // PrepareOptions::morton_order): the partition then names points by it from 65,536 points
  // (it costs nothing), whatever morton_labels_from says. Any permutation of the points gives
  // the same tree; a spatial order makes it faster. Null: computed when needed.
  const std::vector<std::uint32_t>* morton_order = nullptr;
  // The points are already in the order the median splits put them in (a build's `split_order`
  // applied to its points): the partition is skipped, and the tree is the one that build made.
  bool presorted = false;
};

// Builds the hierarchy over `points` (positions, normals and radii required; colors optional).
// Splits at the median along the longest axis of the bounding box, recursively (ties broken by
// input index), and collapses the binary tree so every interior node has 2–4 children: a node's
// children are the quarters of its range (a half of one point is itself a child). The root
// alone may take just its two halves, when that aligns the collapse with the bottom of the tree
// and so needs fewer nodes; either way nodes / leaves <= 1.5. Leaves are the input splats
// (position, radius, normal, cone_sin 0, color). Interior spheres are the smallest spheres
// enclosing their children's spheres; normals are area-weighted means (weight r²) with a cone
// covering the children's cones (cone_sin >= 1: no bound); colors are rounded means of the
// children's. O(n log n), parallel, the same bits for any thread count. Progress phase
// "hierarchy". Throws Error when points is empty, when normals or radii are missing or of the
// wrong length, on more than 2^31 points, or when a position, normal or radius is not finite
// (radius also negative), naming the point.
// With `split_order`, also the order of the points that the splits found: leaf k of the tree in
// range order is points[split_order[k]] (a build over the points in that order with
// `presorted` gives the same tree without partitioning again).
SphereTree build_sphere_tree(const PointSet& points, ThreadPool& pool,
                             Progress& progress = Progress::none(),
                             const SphereTreeOptions& options = {},
                             std::vector<std::uint32_t>* split_order = nullptr);

// Whether build_sphere_tree gives the root of a hierarchy over n points only its two halves
// (else its four quarters): the levels below then pair binary levels 1-2, 3-4, ... (else 0-1,
// 2-3, ...), which a chunked build must follow to cut the same subtrees.
bool sphere_tree_root_halves(std::uint64_t n);

// The top of a hierarchy over subtrees built apart (the chunked conversion): the `roots` (the
// root nodes of the subtrees, in a spatially coherent order) become, in order, the last level of
// a breadth-first tree whose interior nodes have 2-4 children and bound them as
// build_sphere_tree's do; every root is at the same depth, ceil(log4(roots)). The roots keep
// their child_count (their children are not in this tree) and get first_child 0. bounds,
// view_sphere, leaf_count, origin and up are left for the caller. Throws Error for no roots or
// more than 2^20.
SphereTree build_top_tree(std::span<const SphereNode> roots, bool has_colors);

// The largest radius of the hierarchy's leaves (0 without nodes).
float largest_leaf_radius(const SphereTreeView& tree);

// The leaves of a hierarchy as splats: positions = leaf centres, normals, radii and (when the
// tree has them) colors, in node order. Lets another level-of-detail structure (e.g. a Sequential
// Point Tree) be built from a model file that stores a sphere tree.
PointSet sphere_tree_leaves(const SphereTreeView& tree);

// A mesh's faces renumbered onto the tree's leaves (sphere_tree_leaves order), for a tree built
// from the mesh's points by build_sphere_tree with `split_order`: leaf k in depth-first order is
// points[split_order[k]]. Throws Error when the tree's leaf count and split_order differ or a
// face refers to a point beyond them.
std::vector<std::array<std::uint32_t, 3>> leaf_triangles(
    const SphereTreeView& tree, std::span<const std::uint32_t> split_order,
    std::span<const std::array<std::uint32_t, 3>> triangles);

// What QSplat draws when it stops above the leaves, as points: the cut of `tree` at one sphere
// size, each node whose radius is at most r (or a leaf) under a parent larger than r, with r
// chosen (bisected) so that the cut has the number of nodes nearest `target`. A node gives its
// sphere's centre and radius, its mean normal and colour (the tree's colours, when it has them).
// This is what a view-independent threshold selects from the hierarchy, and measures how well
// its interior nodes stand for the surface (simplify --method qsplat-cut). Comments, origin and
// up are the caller's to set.
PointSet sphere_tree_cut(const SphereTree& tree, std::size_t target);

}  // namespace pointillist
