// Sequential Point Trees (Dachsbacher, Vogelgsang & Stamminger, "Sequential Point Trees",
// SIGGRAPH 2003): a point hierarchy whose nodes carry a geometric error, flattened into a list
// sorted so that a renderer selects its level of detail with one branch-free pass over
// contiguous arrays instead of a recursive traversal. This part builds the hierarchy, its errors
// and the sorted list; rendering is elsewhere.
//
// Hierarchy. An octree over the bounding cube of the positions (the cube with corner
// `bounds.lo` and side = the largest side of `bounds`), subdivided until each leaf holds one
// point. A node with a single non-empty octant is collapsed into that octant, so every interior
// node has 2..8 children. Points that fall into the same finest cell (2^21 cells per axis) are
// split by input order, as evenly as possible, into at most 8 groups. Leaves are the input
// splats. An interior node is a disc: centre = mean of its children's centres, normal = the
// normalized mean of their normals, diameter = that of the sphere around the centre enclosing
// the children's spheres (child radius = child diameter / 2).
//
// Errors (world units), over the children i with centre c_i, unit normal n_i, radius r_i, for a
// node with centre c, normal n, diameter d:
//   perpendicular e_p = max_i((c_i − c)·n + s_i) − min_i((c_i − c)·n − s_i),
//                       s_i = r_i·sqrt(1 − (n_i·n)²)  (thickness of the tilted child disc);
//   tangential    e_t = max(0, d − w), w = the smallest, over 8 directions u_j in the node's
//                       plane, width of the children's discs along u_j (extent of
//                       [(c_i − c)·u_j ± r_i·sqrt(1 − (n_i·u_j)²)] over i, i.e. of the discs
//                       projected into the node's plane). u_j = cos(jπ/8)·t1 + sin(jπ/8)·t2,
//                       t1 = the world axis least aligned with n (ties: x before y before z)
//                       made orthogonal to n, t2 = n × t1. e_t is how far the node's disc
//                       overshoots the area its children cover;
//   geometric     e_g = sqrt(e_p² + e_t²), then raised by the two rules below.
// Colour rule (the paper's colour extension, one choice of it): when the tree has colours and
// the node's mean colour differs from one child's mean colour by more than
// `color_tolerance` (Euclidean distance of RGB scaled to [0, 1]), e_g := max(e_g, d). The node
// is then drawn only where its whole disc is smaller than the error bound (d / r <= ε), i.e.
// where its blurred colour covers at most about one pixel.
// Monotonicity rule: e_g := max(e_g, e_g of every child), applied bottom-up, so e_g never
// decreases from a leaf to the root. Without it a child could have r_min > r_max (an empty
// interval) and, at eye distances inside that gap, a node and one of its grandchildren would
// be drawn together.
// Leaves have e_g = 0.
//
// Selection. With ε the allowed error per unit of eye distance (world error / eye distance,
// e.g. threshold_px / f with f = (H/2) / tan(fov/2) as in ARCHITECTURE.md), a node has
//   r_min = error / ε,   r_max = parent_error / ε   (parent_error = e_g of the parent, +inf at
//                                                    the root; leaves have r_min = 0)
// and is drawn iff its eye distance r (distance from the eye to the node's centre, world units)
// lies in [r_min, r_max). Comparing r·ε with error and parent_error gives the same intervals up
// to rounding. Because e_g is monotonic along every leaf-to-root path, for one value of r
// exactly one node on each such path is drawn, so no leaf is left uncovered and no node is drawn
// together with an ancestor. Renderers use each node's own distance, so at interval borders a
// parent and its child may differ in r and slightly overlap or leave a gap; the splats' overlap
// hides this (as in the paper). e_g is stored rather than r_min, so ε can change every frame
// without a rebuild.
//
// Sequential list. The nodes are stored as parallel arrays (one entry per node) and grouped
// into contiguous ranges, each sorted by r_max descending (parent_error descending; ties in
// pre-order, so within a range a node never comes after its descendants):
//   [0, top_end)                 the top list: interior nodes whose points span more than
//                                one octree cell at depth `chunk_level`;
//   chunks[k].begin .. end       chunk k: one subtree whose points lie in one octree cell at
//                                depth chunk_level; its root is its first node. Chunks follow
//                                each other in Morton order of their cells and cover
//                                [top_end, node_count()) without gaps.
// With chunk_level = 0 the top list is empty and the single chunk is the paper's list: all
// nodes sorted by r_max descending, root first. A renderer can stop a range at the first node
// with r_max <= the smallest eye distance to the range's bounding sphere (for chunks,
// `bounds`): no later node of the range can be drawn.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "pointillist/core/math.hpp"
#include "pointillist/core/point_set.hpp"
#include "pointillist/core/progress.hpp"
#include "pointillist/core/thread_pool.hpp"

namespace pointillist {

// `parent` value of the root.
constexpr std::uint32_t kSptNoParent = 0xffffffffu;

// One spatial chunk: a subtree, stored as the node range [begin, end).
struct SptChunk {
  std::uint32_t begin = 0;
  std::uint32_t end = 0;
  Sphere bounds;  // the chunk root's sphere: encloses the sphere of every node of the chunk
};

struct SequentialPointTree {
  // Structure of arrays, one entry per node, in list order (see the file comment).
  std::vector<float> center_x, center_y, center_z;  // disc centre (world units)
  std::vector<float> normal_x, normal_y, normal_z;  // unit disc normal
  std::vector<float> diameter;                      // disc / bounding-sphere diameter (world units)
  std::vector<float> error;           // e_g (world units); r_min = error / ε; 0 for leaves
  std::vector<float> parent_error;    // e_g of the parent; r_max = parent_error / ε; +inf at root
  std::vector<Rgb8> colors;           // mean colour of the subtree; empty when !has_colors
  std::vector<std::uint8_t> is_leaf;  // 1 for input splats, 0 for interior nodes
  std::vector<std::uint32_t> parent;  // list index of the parent (always smaller); root:
                                      // kSptNoParent
  std::vector<std::uint32_t> source;  // leaves: index of the input splat; interior nodes:
                                      // kSptNoParent

  std::uint32_t top_end = 0;  // the top list is [0, top_end)
  std::vector<SptChunk> chunks;
  std::uint32_t chunk_level = 0;  // octree depth of the chunk cells
  bool has_colors = false;
  std::uint64_t leaf_count = 0;
  Aabb bounds;         // box around all sample positions (not radii)
  Sphere view_sphere;  // centre of `bounds`, largest distance to a sample (orbit camera)

  std::size_t node_count() const { return diameter.size(); }
};

struct SequentialPointTreeOptions {
  // Octree depth of the chunk cells, 0..10. 0 gives one chunk (the whole tree, globally sorted);
  // larger values give up to 8^chunk_level smaller chunks for frustum culling, at the cost of
  // more ranges to visit per frame.
  std::uint32_t chunk_level = 3;
  // Largest colour difference (Euclidean distance of RGB scaled to [0, 1], at most sqrt(3))
  // between a node's mean colour and a child's before the node is kept from being drawn large
  // (colour rule above). Lower keeps colour edges sharper but draws more, smaller splats;
  // +infinity turns the rule off. Ignored without colours.
  float color_tolerance = 0.1f;
  // Subtrees of at most this many points are built by one task; larger ranges are split first.
  // Only changes speed, never the result.
  std::size_t parallel_grain_points = std::size_t{1} << 14;
};

// Builds the sequential point tree over `points` (positions, normals and radii required; colors
// optional). O(n log n), parallel on `pool`, the same bits for any thread count and grain.
// Progress phases "hierarchy" and "sequential list". Throws Error when points is empty, when
// normals or radii are missing or of the wrong length, on more than 2^31 points, or when a
// position, normal or radius is not finite (radius also negative), naming the point; throws
// OptionError when chunk_level > 10 or color_tolerance is negative or NaN.
SequentialPointTree build_sequential_point_tree(const PointSet& points, ThreadPool& pool,
                                                Progress& progress = Progress::none(),
                                                const SequentialPointTreeOptions& options = {});

// A disc: centre (world units), unit normal, radius (world units).
struct SptDisc {
  Vec3f center;
  Vec3f normal;
  float radius = 0;
};

// A node made from its children, as in the build: centre, normal and diameter as in the file
// comment, and the errors e_p and e_t (world units, before the colour and monotonicity rules).
// When the children's normals cancel out, the node takes the first child's normal.
struct SptNodeGeometry {
  Vec3f center;
  Vec3f normal;
  float diameter = 0;
  float perpendicular_error = 0;  // e_p
  float tangential_error = 0;     // e_t
};

// Combines 1 or more child discs (finite, radii >= 0) into their parent node. Computed in double
// precision; the diameter is rounded up so it encloses the children.
SptNodeGeometry spt_combine_children(std::span<const SptDisc> children);

}  // namespace pointillist
