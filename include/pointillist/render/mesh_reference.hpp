// Reference z-buffered triangle rasterizer: the oracle for splat rendering (silhouettes, image
// quality). Correct and simple rather than fast.
#pragma once

#include <span>

#include "pointillist/core/camera.hpp"
#include "pointillist/core/point_set.hpp"
#include "pointillist/render/render.hpp"
#include "pointillist/render/renderer.hpp"

namespace pointillist {

// Draws mesh.triangles (over mesh.positions) seen by `camera` into frame.color and frame.depth
// (resized to the camera's image; frame.splats and frame.scratch are left alone; frame.stats
// gets the size, threads = 1 and the times, and zero counts).
//  * Coverage: a pixel is covered when its centre (i + 0.5, j + 0.5) is inside the projected
//    triangle; centres exactly on an edge belong to top and left edges only (the usual top-left
//    rule), so triangles sharing an edge cover each of its pixels once. Triangles are clipped
//    against a near plane at 1e-5 × the largest vertex depth; both sides are drawn.
//  * Depth: the perspective-correct eye-space depth of the surface at the pixel centre; strict
//    depth test (the earlier triangle wins a tie).
//  * Shading: the splat renderer's model (RenderSettings) per pixel, with the normal interpolated
//    perspective-correctly from mesh.normals when present, else the face normal
//    normalize((b − a) × (c − a)); base color interpolated from mesh.colors when present, else
//    settings.base_color.
// settings.threshold_px, shape and the culling flags are ignored. Throws OptionError for an
// invalid camera or light; asserts that every triangle index is in range.
void render_mesh_reference(const PointSet& mesh, const Camera& camera,
                           const RenderSettings& settings, Frame& frame);

// The same for a scene: every instance's model's mesh (RenderModel::mesh) drawn at its transform
// (positions by InstanceTransform::apply, normals and face normals rotated) into one frame, in
// instance order (a tie goes to the earlier triangle of the earlier instance); one near plane,
// 1e-5 × the largest vertex depth of all instances. Throws OptionError naming a model without a
// mesh.
void render_mesh_reference(std::span<const SceneInstance> scene, const Camera& camera,
                           const RenderSettings& settings, Frame& frame);

}  // namespace pointillist
