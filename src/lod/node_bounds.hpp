// Bounds of an interior QSplat node from its children (Rusinkiewicz & Levoy, "QSplat: A
// Multiresolution Point Rendering System for Large Meshes", SIGGRAPH 2000, section 3.1): a
// sphere enclosing the children's spheres, an area-weighted mean normal with a cone enclosing the
// children's cones, and the mean color. Private to the lod module.
#pragma once

#include <span>

#include "pointillist/lod/sphere_tree.hpp"

namespace pointillist::lod_detail {

// cone_sin value meaning "no bound" (half-angle >= 90°, or undefined).
constexpr float kNoConeBound = 2.0f;

// Fills center, radius, normal, cone_sin and color of `parent` from 1..4 `children` (first_child
// and child_count are left alone). Deterministic: depends only on the children, in order.
void combine_children(std::span<const SphereNode> children, SphereNode& parent);

}  // namespace pointillist::lod_detail
