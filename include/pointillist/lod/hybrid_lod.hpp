// Hybrid point/polygon level of detail over a Sequential Point Tree (the extension the SPT slides
// propose without stating a rule; our rule, spec occlusion-simplification-hybrid.md §3.3): near
// the eye a mesh's triangles replace the points they cover, far away points replace triangles,
// and no hole opens where the two meet.
//
// Units. Everything is kept as the SPT keeps its errors: a world length e that a renderer with
// error bound ε (= epsilon_px / f, world error per unit of eye distance) turns into the eye
// distance e / ε. A triangle t with longest edge ℓ_t "wants" to be drawn while ℓ_t projects to
// more than τ pixels, τ = triangle_px_per_epsilon · epsilon_px: that is while its eye distance
// is below ℓ_t·f/τ, i.e. e_t / ε with e_t = ℓ_t / triangle_px_per_epsilon.
//
// The spec's rule, for every leaf v (a mesh vertex) with SPT interval [0, pe_v) (pe_v its
// parent's error):
//   e'_v = min(min over the triangles t around v of e_t, pe_v)     (v has no triangle: e'_v = 0)
// and v is drawn as a point only while e'_v ≤ r_v·ε < pe_v: nearer than e'_v / ε it is
// suppressed. A triangle t gets E_t = max over its vertices of e'_v and is drawn while
//   r_t·ε < E_t,   r_t = the smallest eye distance of its three vertices.
// Why no hole opens: where a vertex v is suppressed, r_v·ε < e'_v ≤ E_t for every t around v, and
// r_t ≤ r_v, so every triangle around v is drawn. Where no vertex of a triangle is suppressed,
// the triangle is covered by points exactly as in the pure SPT. A point and a triangle both drawn
// overlap harmlessly under the z-buffer.
//
// Our extension to interior entries. With the rule on leaves alone, an interior node whose leaves
// all gave way to triangles is still drawn wherever its interval says, and its large splat,
// flat at its centre's depth, pokes through the triangles (on the dragon at 0.45 radii half the
// splats drawn were such nodes). So every entry N (leaf or not) with error e_N, parent error pe_N
// and bounding radius ρ_N (0 for a leaf: a vertex is a point) gets
//   s_N = min(max(e_N, m_N), pe_N),   m_N = min of e_t over the triangles touching N's leaves,
// kept only when s_N > e_N (else N is never suppressed: s_N = 0), and N is suppressed while
//   (r_N + ρ_N)·ε < s_N
// (leaves: the rule above). A triangle gets E_t = max over its vertices v of the largest s_N on
// the path from v to the root. No hole opens: where N is suppressed, every leaf v under it has
// r_v ≤ r_N + ρ_N, so r_t·ε ≤ r_v·ε < s_N ≤ E_t for every triangle t touching v.
//
// The triangles are grouped by the SPT chunk of their first vertex and, within a group, sorted by
// E_t descending (ties by input order), so a renderer scans each visible group's prefix with E_t
// above the group's nearest eye distance times ε, as it scans the SPT's ranges.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "pointillist/core/math.hpp"
#include "pointillist/core/point_set.hpp"
#include "pointillist/lod/sequential_point_tree.hpp"

namespace pointillist {

struct HybridLodOptions {
  // τ / epsilon_px: a triangle replaces points while its longest edge projects to more than this
  // many times the SPT's error bound in pixels (4: at --epsilon 1, edges longer than 4 px). > 0.
  // Smaller draws triangles from farther away (fewer points, more triangles).
  float triangle_px_per_epsilon = 4.0f;
};

// One group of triangles: those whose first vertex lies in SPT chunk k (group k).
struct HybridTriangleGroup {
  std::uint32_t begin = 0, end = 0;  // range of HybridLod::triangles
  Sphere bounds;                     // encloses every vertex of the group's triangles
};

struct HybridLod {
  // s_N of every SPT entry (0: never suppressed): an entry in its interval is drawn only while
  // (r_N + ρ_N)·ε ≥ s_N.
  std::vector<float> suppress_below;
  // Triangles over the leaves (indices into the leaf arrays below), grouped and sorted as in the
  // file comment, with their E_t.
  std::vector<std::array<std::uint32_t, 3>> triangles;
  std::vector<float> triangle_error;
  std::vector<HybridTriangleGroup> groups;  // one per SPT chunk, in chunk order
  // The leaves: positions, unit normals, colours (empty without colours).
  std::vector<Vec3f> positions, normals;
  std::vector<Rgb8> colors;
  float triangle_px_per_epsilon = 4.0f;
  Sphere view_sphere;  // the tree's: holds every vertex (one near plane for all the triangles)
  std::uint64_t suppressible_leaves = 0;    // leaves with s > 0 (give way to triangles when near)
  std::uint64_t suppressible_interior = 0;  // interior entries with s > 0

  std::size_t triangle_count() const { return triangles.size(); }
};

// Builds the hybrid lists for `tree` (built by build_sequential_point_tree over `leaves`, whose
// `source` indices are indices into `leaves`) and `triangles` over the same leaves. O(n log n).
// Throws Error when a triangle refers to a leaf that does not exist, or when tree and leaves do
// not match; OptionError for a non-positive or non-finite triangle_px_per_epsilon.
HybridLod build_hybrid_lod(const SequentialPointTree& tree, const PointSet& leaves,
                           std::span<const std::array<std::uint32_t, 3>> triangles,
                           const HybridLodOptions& options = {});

}  // namespace pointillist
