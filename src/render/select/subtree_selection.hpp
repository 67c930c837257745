// Selection of one subtree of a hierarchy held in memory (occlusion culling draws the culling
// leaves it finds visible one by one). Internal to render.
#pragma once

#include <cstdint>
#include <span>

#include "pointillist/lod/sphere_tree.hpp"
#include "pointillist/render/splat_stream.hpp"
#include "select/traversal_common.hpp"

namespace pointillist::render_detail {

// A subtree to walk: its root and the per-node tests still to do when the whole traversal
// reaches it.
struct SubtreeRoot {
  std::uint32_t node;
  std::uint8_t tests;
};

// Walks the subtrees `roots` of `nodes` one after the other into `chunk` (emptied first; its
// buffers sized with colours and discs as asked), shaded as select_splats shades: the splats the
// whole traversal would draw from those subtrees, in the same order. Adds to `counters`.
void select_subtrees(std::span<const SphereNode> nodes, std::span<const SubtreeRoot> roots,
                     const ViewConstants& v, bool with_colors, SplatChunk& chunk,
                     Counters& counters);

}  // namespace pointillist::render_detail
