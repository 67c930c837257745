// The triangles of the hybrid point/polygon mode (lod/hybrid_lod.hpp): their selection for a
// camera, and their drawing into the fast rasterizer's image after the splats, with the shared
// triangle rasterizer (raster/triangle_raster.hpp).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "pointillist/core/camera.hpp"
#include "pointillist/core/thread_pool.hpp"
#include "pointillist/lod/hybrid_lod.hpp"
#include "pointillist/render/settings.hpp"
#include "raster/triangle_raster.hpp"

namespace pointillist {
struct InstanceTransform;
}

namespace pointillist::render_detail {

struct TriangleSelectionStats {
  std::uint64_t triangles = 0;      // selected
  std::uint64_t scanned = 0;        // list entries tested
  std::uint64_t groups_culled = 0;  // groups outside the view frustum
};

// Appends to `out` the triangles of `lod` to draw for `camera` (in the model's frame): for every
// group whose sphere meets the frustum (when settings.frustum_culling), the prefix with
// E_t > r_lo·ε is scanned and triangle t kept iff r_t·ε < E_t (r_t the smallest eye distance
// of its vertices; orthographic: 1), no frustum plane has all three vertices outside, and (with
// settings.culls_backfaces(), as for the splats) not both every corner's normal and the
// triangle's plane (oriented by those normals) face away from the eye. A vertex that faces the
// eye never loses its triangles to the last rule.
// Group order, then list order: the same for any thread count.
void select_triangles(const HybridLod& lod, const CameraFrame& camera,
                      const RenderSettings& settings, float epsilon_px, ThreadPool& pool,
                      std::vector<std::uint32_t>& out, TriangleSelectionStats& stats);

// One instance's selected triangles; `transform` null for a model drawn where it stands.
struct TriangleBatch {
  const HybridLod* lod = nullptr;
  const InstanceTransform* transform = nullptr;
  std::span<const std::uint32_t> selected;
};

struct ScreenTriangle {
  ScreenVertex v[3];
  float y_lo, y_hi;  // rows touched (pixels)
};

struct TriangleScratch {
  std::vector<std::vector<ScreenTriangle>> parts;
  std::vector<ScreenTriangle> screen;
};

// Draws the batches' triangles into `color` and `depth` (the image the fast rasterizer wrote):
// near-clipped, projected, rasterized with per-pixel shading; a pixel takes the nearer depth and,
// at equal depth, the smaller packed colour (the splats' rule), so the image does not depend on
// the order of the triangles or on the thread count. Returns the screen triangles drawn.
std::uint64_t draw_triangles(std::span<const TriangleBatch> batches, const CameraFrame& camera,
                             const RenderSettings& settings, ThreadPool& pool,
                             TriangleScratch& scratch, std::span<Rgb8> color,
                             std::span<float> depth);

}  // namespace pointillist::render_detail
