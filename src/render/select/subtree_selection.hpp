// Selection of parts of a model (occlusion culling draws the culling leaves it finds visible,
// group by group): subtrees of a hierarchy held in memory, list ranges of a Sequential Point
// Tree. Internal to render.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "pointillist/lod/sequential_point_tree.hpp"
#include "pointillist/lod/sphere_tree.hpp"
#include "pointillist/render/spt_render.hpp"
#include "pointillist/render/splat_stream.hpp"
#include "select/traversal_common.hpp"
#include "shading.hpp"

namespace pointillist::render_detail {

// A subtree to walk: its root and the per-node tests still to do when the whole traversal
// reaches it.
struct SubtreeRoot {
  std::uint32_t node;
  std::uint8_t tests;
};

// Walks the subtrees `roots` of `nodes` one after the other into `chunk` (emptied first; its
// buffers sized with colours and discs as asked), shaded as select_splats shades: the splats the
// whole traversal would draw from those subtrees, in the same order. Adds to `counters`. With
// `ends`, appends the chunk's splat count after each root (where each subtree's splats end).
void select_subtrees(std::span<const SphereNode> nodes, std::span<const SubtreeRoot> roots,
                     const ViewConstants& v, bool with_colors, SplatChunk& chunk,
                     Counters& counters, std::vector<std::uint32_t>* ends = nullptr);

// Sequential Point Trees (spt_selection.cpp): the sphere holding every splat of the top list,
// whether a chunk's bounds are outside the view (the selection's chunk culling), and the
// selection of list range [begin, end) with bounding sphere `bounds` as select_splats_spt
// selects it, appended to `out` (its buffers grown as needed). Adds to `stats`.
Sphere spt_top_bounds(const SequentialPointTree& tree);
bool spt_chunk_outside(const CameraFrame& camera, const Sphere& bounds);
void select_spt_range(const SequentialPointTree& tree, std::uint32_t begin, std::uint32_t end,
                      const Sphere& bounds, const CameraFrame& camera,
                      const RenderSettings& settings, float epsilon_px, const Shader& shader,
                      bool with_discs, SplatChunk& out, SptSelectionStats& stats);

}  // namespace pointillist::render_detail
