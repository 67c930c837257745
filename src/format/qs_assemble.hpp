// From decoded .qs fragment trees to one SphereTree the renderer can trust: fragments joined
// under one root, spheres and normal cones made to enclose their children. Private to the format
// module.
#pragma once

#include <vector>

#include "qs_layout.hpp"
#include "pointillist/format/qs.hpp"

namespace pointillist::qs_detail {

// Joins the fragment trees (each breadth-first, roots first) into one breadth-first tree: one
// tree is taken as is; several get levels of added nodes above their roots (2-4 children each,
// all roots on one level). Roots get the normalized mean normal and truncated mean color of
// their children. Then, bottom-up, every interior node's radius is enlarged until it encloses
// its children's spheres and its normal cone widened until it covers theirs (counted in
// stats.spheres_enlarged / cones_widened; added nodes are not counted). Fills bounds,
// view_sphere, leaf_count, depth and has_colors (when only some fragments have colours, the
// others are grey 204).
SphereTree assemble_tree(std::vector<DecodedTree>&& trees, QsStats& stats);

}  // namespace pointillist::qs_detail
