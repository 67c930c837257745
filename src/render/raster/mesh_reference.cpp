// Reference triangle rasterizer (edge functions with the top-left fill rule, perspective-correct
// interpolation). Double precision edge functions keep the coverage exact for test geometry.
#include "pointillist/render/mesh_reference.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <chrono>
#include <cmath>
#include <limits>

#include "shading.hpp"
#include "raster/triangle_raster.hpp"

namespace pointillist {

using render_detail::EyeVertex;
using render_detail::Shader;

void render_mesh_reference(const PointSet& mesh, const Camera& camera,
                           const RenderSettings& settings, Frame& frame) {
  const auto start = std::chrono::steady_clock::now();
  const CameraFrame cam = make_camera_frame(camera);
  const Shader shader(settings, cam);
  const std::size_t pixels = static_cast<std::size_t>(cam.width) * cam.height;
  frame.width = cam.width;
  frame.height = cam.height;
  frame.color.assign(pixels, settings.background);
  frame.depth.assign(pixels, std::numeric_limits<float>::infinity());

  const bool has_normals = mesh.normals.size() == mesh.positions.size();
  const bool has_colors = mesh.colors.size() == mesh.positions.size();
  std::vector<Vec3f> eye(mesh.positions.size());
  float max_depth = 0;
  for (std::size_t i = 0; i < eye.size(); ++i) {
    eye[i] = render_detail::eye_space(cam, mesh.positions[i]);
    max_depth = std::max(max_depth, eye[i].z);
  }
  const float near = 1e-5f * max_depth;
  // Strict depth test: the earlier triangle wins a tie.
  const auto test = [&](std::size_t idx, float z) { return z < frame.depth[idx]; };
  const auto write = [&](std::size_t idx, float z, Rgb8 c) {
    frame.depth[idx] = z;
    frame.color[idx] = c;
  };
  for (const auto& t : mesh.triangles) {
    assert(t[0] < eye.size() && t[1] < eye.size() && t[2] < eye.size());
    std::array<EyeVertex, 3> v;
    const Vec3f face = normalized(cross(mesh.positions[t[1]] - mesh.positions[t[0]],
                                        mesh.positions[t[2]] - mesh.positions[t[0]]));
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t i = t[k];
      Vec3f c = settings.base_color;
      if (has_colors) {
        c = Vec3f{float(mesh.colors[i].r), float(mesh.colors[i].g), float(mesh.colors[i].b)} *
            (1.0f / 255.0f);
      }
      v[k] = {eye[i], has_normals ? mesh.normals[i] : face, c};
    }
    std::array<EyeVertex, 4> clipped;
    const int n = render_detail::clip_near(v, near, clipped);
    if (n < 3) continue;
    const auto s0 = render_detail::project_vertex(cam, clipped[0]);
    for (int k = 1; k + 1 < n; ++k) {
      render_detail::raster_triangle(cam, shader, s0, render_detail::project_vertex(cam, clipped[k]),
                                     render_detail::project_vertex(cam, clipped[k + 1]), 0,
                                     cam.height, test, write);
    }
  }

  frame.stats = {};
  frame.stats.width = cam.width;
  frame.stats.height = cam.height;
  frame.stats.threads = 1;
  frame.stats.ms_total = frame.stats.ms_raster =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace pointillist
