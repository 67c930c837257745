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

namespace pointillist {
namespace {

using render_detail::Shader;

struct EyeVertex {
  Vec3f p;      // eye-space x (right), y (up), and depth z (> 0 in front)
  Vec3f normal;  // world space
  Vec3f color;   // linear 0..1
};

// Perspective: 1/z and the attributes over z interpolate linearly on the screen. Orthographic:
// z and the attributes themselves do (inv_z then holds z, and "over z" means over 1).
struct ScreenVertex {
  double x, y;    // pixels
  double inv_z;
  Vec3f normal_over_z, color_over_z;
};

EyeVertex lerp(const EyeVertex& a, const EyeVertex& b, float t) {
  return {a.p + (b.p - a.p) * t, a.normal + (b.normal - a.normal) * t,
          a.color + (b.color - a.color) * t};
}

// Sutherland–Hodgman against z >= near; returns the vertex count (0, 3 or 4).
int clip_near(const std::array<EyeVertex, 3>& in, float near, std::array<EyeVertex, 4>& out) {
  int n = 0;
  for (int i = 0; i < 3; ++i) {
    const EyeVertex& a = in[i];
    const EyeVertex& b = in[(i + 1) % 3];
    const bool a_in = a.p.z >= near, b_in = b.p.z >= near;
    if (a_in) out[n++] = a;
    if (a_in != b_in) out[n++] = lerp(a, b, (near - a.p.z) / (b.p.z - a.p.z));
  }
  return n;
}

struct Raster {
  const CameraFrame& cam;
  const Shader& shader;
  Frame& frame;

  ScreenVertex project(const EyeVertex& v) const {
    if (cam.ortho) {
      return {0.5 * cam.width + cam.focal_px * double(v.p.x),
              0.5 * cam.height - cam.focal_px * double(v.p.y), double(v.p.z), v.normal, v.color};
    }
    const double inv_z = 1.0 / static_cast<double>(v.p.z);
    const float fz = static_cast<float>(inv_z);
    return {0.5 * cam.width + cam.focal_px * v.p.x * inv_z,
            0.5 * cam.height - cam.focal_px * v.p.y * inv_z, inv_z, v.normal * fz,
            v.color * fz};
  }

  void triangle(ScreenVertex a, ScreenVertex b, ScreenVertex c) const {
    double area = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
    if (!(area != 0.0) || !std::isfinite(area)) return;
    if (area < 0) {
      std::swap(b, c);
      area = -area;
    }
    // With this orientation (y down) the inside has all edge functions > 0; an edge is "top"
    // when horizontal going right and "left" when going up.
    const auto top_left = [](const ScreenVertex& p, const ScreenVertex& q) {
      const double dx = q.x - p.x, dy = q.y - p.y;
      return dy < 0 || (dy == 0 && dx > 0);
    };
    const bool tl_ab = top_left(a, b), tl_bc = top_left(b, c), tl_ca = top_left(c, a);
    const auto edge = [](const ScreenVertex& p, const ScreenVertex& q, double x, double y) {
      return (q.x - p.x) * (y - p.y) - (q.y - p.y) * (x - p.x);
    };
    const double w = cam.width, h = cam.height;
    const double lo_x = std::max(0.0, std::ceil(std::min({a.x, b.x, c.x}) - 0.5));
    const double hi_x = std::min(w - 1, std::floor(std::max({a.x, b.x, c.x}) - 0.5));
    const double lo_y = std::max(0.0, std::ceil(std::min({a.y, b.y, c.y}) - 0.5));
    const double hi_y = std::min(h - 1, std::floor(std::max({a.y, b.y, c.y}) - 0.5));
    if (!(lo_x <= hi_x && lo_y <= hi_y)) return;
    const float half_w = 0.5f * static_cast<float>(cam.width);
    const float half_h = 0.5f * static_cast<float>(cam.height);
    for (int j = static_cast<int>(lo_y); j <= static_cast<int>(hi_y); ++j) {
      const double py = j + 0.5;
      for (int i = static_cast<int>(lo_x); i <= static_cast<int>(hi_x); ++i) {
        const double px = i + 0.5;
        const double e_ab = edge(a, b, px, py), e_bc = edge(b, c, px, py),
                     e_ca = edge(c, a, px, py);
        const bool inside = (e_ab > 0 || (e_ab == 0 && tl_ab)) &&
                            (e_bc > 0 || (e_bc == 0 && tl_bc)) &&
                            (e_ca > 0 || (e_ca == 0 && tl_ca));
        if (!inside) continue;
        const double wa = e_bc / area, wb = e_ca / area, wc = e_ab / area;
        const double inv_z = wa * a.inv_z + wb * b.inv_z + wc * c.inv_z;
        const float z = static_cast<float>(cam.ortho ? inv_z : 1.0 / inv_z);
        const float attribute_scale = cam.ortho ? 1.0f : z;
        const std::size_t idx = static_cast<std::size_t>(j) * cam.width + i;
        if (!(z < frame.depth[idx])) continue;
        const float fa = static_cast<float>(wa), fb = static_cast<float>(wb),
                    fc = static_cast<float>(wc);
        const Vec3f n = (a.normal_over_z * fa + b.normal_over_z * fb + c.normal_over_z * fc) *
                        attribute_scale;
        const Vec3f base = (a.color_over_z * fa + b.color_over_z * fb + c.color_over_z * fc) *
                           attribute_scale;
        // Direction to the eye from the surface point seen through the pixel centre.
        const Vec3f ray =
            cam.ortho ? cam.forward
                      : cam.forward + cam.right * ((static_cast<float>(px) - half_w) / cam.focal_px) -
                            cam.up * ((static_cast<float>(py) - half_h) / cam.focal_px);
        frame.depth[idx] = z;
        frame.color[idx] = shader.shade(normalized(n, -ray), -ray / length(ray), base);
      }
    }
  }
};

}  // namespace

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
    const Vec3f d = mesh.positions[i] - cam.eye;
    eye[i] = {dot(d, cam.right), dot(d, cam.up), dot(d, cam.forward)};
    max_depth = std::max(max_depth, eye[i].z);
  }
  const float near = 1e-5f * max_depth;
  const Raster raster{cam, shader, frame};
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
    const int n = clip_near(v, near, clipped);
    if (n < 3) continue;
    const ScreenVertex s0 = raster.project(clipped[0]);
    for (int k = 1; k + 1 < n; ++k) {
      raster.triangle(s0, raster.project(clipped[k]), raster.project(clipped[k + 1]));
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
