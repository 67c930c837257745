// QSplat traversal: chooses the nodes of a bounding-sphere hierarchy to draw for one view.
#pragma once

#include <cstdint>

#include "pointillist/core/camera.hpp"
#include "pointillist/core/thread_pool.hpp"
#include "pointillist/lod/sphere_tree.hpp"
#include "pointillist/render/settings.hpp"
#include "pointillist/render/splat_stream.hpp"

namespace pointillist {

struct SelectionStats {
  std::uint64_t splats = 0;           // splats written to the stream
  std::uint64_t nodes_visited = 0;    // nodes whose sphere was tested
  std::uint64_t culled_frustum = 0;   // subtrees outside the frustum or behind the eye, and drawn
                                      // nodes dropped for being behind (or a hair in front of) it
  std::uint64_t culled_backface = 0;  // subtrees whose normal cone faces away, and drawn nodes
                                      // dropped for facing away
  std::uint64_t culled_occluded = 0;  // subtrees an occlusion test found hidden (paged models
                                      // under occlusion culling: PagedRenderer::select)
};

// An occlusion test a paged selection asks before it opens a node whose children lie in
// another page (PagedRenderer::select): hidden(context, centre, radius), the node's sphere in
// model space, is true only when nothing of the subtree can show. Called from several
// selection tasks at once.
struct SubtreeOcclusion {
  bool (*hidden)(const void* context, Vec3f center, float radius) = nullptr;
  const void* context = nullptr;
};

// Walks `tree` depth first (Rusinkiewicz & Levoy 2000, section 3.2) and writes the splats to draw
// into `stream` (its buffers are reused). Uses settings.threshold_px, frustum_culling and
// backface_culling; the other settings are the rasterizer's.
//
// A node is drawn when it is a leaf, or when its centre is in front of the eye (z > 0) and its
// projected diameter 2·r·f/z is at most threshold_px; otherwise its children are visited. Whatever
// the culling flags, a drawn node is dropped when its centre is not in front of the eye (z ≤ 0),
// when its projected position or size exceeds 1e9 px (only a hair in front of the eye), and when
// it has a normal cone (cone_sin < 1, so its normal means something) and its normal points away
// from the eye: n·(eye − c) < 0 (QSplat's per-splat test; this is a one-sided renderer). Culling
// only skips subtrees all of whose drawable nodes would be dropped or fall outside the image, so
// for a hierarchy whose spheres and normal cones are conservative, culling never changes the
// image:
//  * frustum: a sphere with z ≤ −r, or at distance ≤ −r outside one of the four side planes, is
//    skipped with its subtree; a sphere entirely inside is not tested again below;
//  * backface (node cone_sin < 1, v = eye − c, k = v·n, s = cone_sin): the subtree is skipped when
//    k + r < −s·(|v| + r) (every normal of the cone faces away from the eye as seen from every
//    point of the sphere; |v| + r instead of QSplat's |v| makes the bound hold for the whole
//    sphere), and is not tested again below when k − r > s·(|v| + r).
// The stream order is the depth-first order, the same for any thread count. Throws OptionError
// when threshold_px is not a positive finite number.
void select_splats(const SphereTreeView& tree, const CameraFrame& camera,
                   const RenderSettings& settings, ThreadPool& pool, SplatStream& stream,
                   SelectionStats& stats);

}  // namespace pointillist
