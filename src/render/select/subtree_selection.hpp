// Selection of one subtree of a hierarchy held in memory (occlusion culling draws the culling
// leaves it finds visible one by one). Internal to render.
#pragma once

#include <cstdint>
#include <span>

#include "pointillist/lod/sphere_tree.hpp"
#include "pointillist/render/splat_stream.hpp"
#include "select/traversal_common.hpp"

namespace pointillist::render_detail {

// Walks the subtree of node `node` of `nodes`, with the per-node tests `tests` still to do (as
// the whole traversal would reach it), into `chunk` (emptied first; its buffers sized with
// colours and discs as asked), shaded as select_splats shades: the splats the whole traversal
// would draw from that subtree, in the same order. Adds to `counters`.
void select_subtree(std::span<const SphereNode> nodes, std::uint32_t node, std::uint8_t tests,
                    const ViewConstants& v, bool with_colors, SplatChunk& chunk,
                    Counters& counters);

}  // namespace pointillist::render_detail
