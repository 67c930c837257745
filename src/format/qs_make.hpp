// QSplat 1.0's preprocessing (`qsplat_make`): per-vertex normals and splat radii of a mesh, and
// its midpoint-split bounding-sphere hierarchy, reproduced bit for bit (spec
// ../shared/specs/qsplat-qs-format.md §8.2-8.4, §8.6). Private to the format module.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "pointillist/core/math.hpp"
#include "pointillist/core/point_set.hpp"

namespace pointillist::qs_detail {

// A hierarchy node before quantization. Leaves are the kept input points.
struct MakeNode {
  Vec3f center;
  float radius = 0;
  Vec3f normal;        // unit
  float cone = 0;      // half-angle θ (radians) of a cone around `normal` holding all leaf normals
  Rgb8 color;
  std::array<std::uint32_t, 4> children{};
  std::uint8_t child_count = 0;
  bool has_grandchild = false;  // some child has children
};

struct MakeTree {
  std::vector<MakeNode> nodes;  // leaves first (kept points in input order), then interior nodes
  std::uint32_t root = 0;
  std::uint64_t leaf_count = 0;
};

// Leaves: for a mesh, QSplat's area-weighted vertex normals and largest smallest-enclosing-circle
// radii of the incident triangles (§8.2), keeping the vertices used by a face with a radius
// other than 0; for a point set without faces, its normals and radii (radius 0 dropped).
// Colors are copied when `with_colors`. Throws Error (naming `name`) for inconsistent input.
MakeTree make_leaves(const PointSet& points, bool with_colors, const std::string& name);

// Builds the hierarchy over tree.nodes (all leaves so far) as §8.3-8.4 describe and sets root.
// Needs at least 2 leaves.
void build_hierarchy(MakeTree& tree);

}  // namespace pointillist::qs_detail
