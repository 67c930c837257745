// Reference triangle rasterizer (edge functions with the top-left fill rule, perspective-correct
// interpolation). Double precision edge functions keep the coverage exact for test geometry.
#include "pointillist/render/mesh_reference.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <chrono>
#include <cmath>
#include <limits>

#include "pointillist/core/error.hpp"
#include "shading.hpp"
#include "raster/triangle_raster.hpp"

namespace pointillist {

using render_detail::EyeVertex;
using render_detail::Shader;

namespace {

// The meshes of `scene` (each instance's model's mesh at its transform) into `frame`.
void draw_meshes(std::span<const SceneInstance> scene, const Camera& camera,
                 const RenderSettings& settings, Frame& frame) {
  const auto start = std::chrono::steady_clock::now();
  const CameraFrame cam = make_camera_frame(camera);
  const Shader shader(settings, cam);
  const std::size_t pixels = static_cast<std::size_t>(cam.width) * cam.height;
  frame.width = cam.width;
  frame.height = cam.height;
  frame.color.assign(pixels, settings.background);
  frame.depth.assign(pixels, std::numeric_limits<float>::infinity());

  // Every instance's vertices in eye space (and its normals in world space); one near plane for
  // all: 1e-5 × the largest vertex depth.
  std::vector<std::vector<Vec3f>> eye(scene.size()), normals(scene.size());
  float max_depth = 0;
  for (std::size_t m = 0; m < scene.size(); ++m) {
    const PointSet& mesh = *scene[m].model->mesh;
    const InstanceTransform& tr = scene[m].transform;
    const bool identity = tr.is_identity();
    eye[m].resize(mesh.positions.size());
    for (std::size_t i = 0; i < eye[m].size(); ++i) {
      eye[m][i] = render_detail::eye_space(cam, identity ? mesh.positions[i] : tr.apply(mesh.positions[i]));
      max_depth = std::max(max_depth, eye[m][i].z);
    }
    if (!identity && mesh.normals.size() == mesh.positions.size()) {
      normals[m].resize(mesh.normals.size());
      for (std::size_t i = 0; i < mesh.normals.size(); ++i) normals[m][i] = tr.rotate(mesh.normals[i]);
    }
  }
  const float near = 1e-5f * max_depth;
  // Strict depth test: the earlier triangle wins a tie.
  const auto test = [&](std::size_t idx, float z) { return z < frame.depth[idx]; };
  const auto write = [&](std::size_t idx, float z, Rgb8 c) {
    frame.depth[idx] = z;
    frame.color[idx] = c;
  };
  for (std::size_t m = 0; m < scene.size(); ++m) {
    const PointSet& mesh = *scene[m].model->mesh;
    const InstanceTransform& tr = scene[m].transform;
    const std::vector<Vec3f>& ev = eye[m];
    const bool has_normals = mesh.normals.size() == mesh.positions.size();
    const bool has_colors = mesh.colors.size() == mesh.positions.size();
    const std::vector<Vec3f>& world_normals = normals[m].empty() ? mesh.normals : normals[m];
    for (const auto& t : mesh.triangles) {
      assert(t[0] < ev.size() && t[1] < ev.size() && t[2] < ev.size());
      std::array<EyeVertex, 3> v;
      Vec3f face = normalized(cross(mesh.positions[t[1]] - mesh.positions[t[0]],
                                    mesh.positions[t[2]] - mesh.positions[t[0]]));
      if (!tr.is_identity()) face = tr.rotate(face);
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t i = t[k];
        Vec3f c = settings.base_color;
        if (has_colors) {
          c = Vec3f{float(mesh.colors[i].r), float(mesh.colors[i].g), float(mesh.colors[i].b)} *
              (1.0f / 255.0f);
        }
        v[k] = {ev[i], has_normals ? world_normals[i] : face, c};
      }
      std::array<EyeVertex, 4> clipped;
      const int n = render_detail::clip_near(v, near, clipped);
      if (n < 3) continue;
      const auto s0 = render_detail::project_vertex(cam, clipped[0]);
      for (int k = 1; k + 1 < n; ++k) {
        render_detail::raster_triangle(cam, shader, s0,
                                       render_detail::project_vertex(cam, clipped[k]),
                                       render_detail::project_vertex(cam, clipped[k + 1]), 0,
                                       cam.height, test, write);
      }
    }
  }

  frame.stats = {};
  frame.stats.width = cam.width;
  frame.stats.height = cam.height;
  frame.stats.threads = 1;
  frame.stats.ms_total = frame.stats.ms_raster =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

void render_mesh_reference(const PointSet& mesh, const Camera& camera,
                           const RenderSettings& settings, Frame& frame) {
  const RenderModel model{.mesh = &mesh};
  const SceneInstance scene[] = {{&model, {}}};
  draw_meshes(scene, camera, settings, frame);
}

void render_mesh_reference(std::span<const SceneInstance> scene, const Camera& camera,
                           const RenderSettings& settings, Frame& frame) {
  for (const SceneInstance& inst : scene) {
    if (!inst.model->mesh || !inst.model->mesh->is_mesh()) {
      throw OptionError(inst.model->name + ": --mode reference draws a mesh's triangles, and "
                        "this input has none; give the source meshes (.ply, .obj)");
    }
  }
  draw_meshes(scene, camera, settings, frame);
}

}  // namespace pointillist
