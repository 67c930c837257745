// The triangle rasterizer both triangle renderers share: the mesh reference (mesh_reference.cpp,
// the image oracle) and the hybrid point/polygon mode of the fast renderer (triangle_draw.cpp).
// Edge functions in double precision with the top-left fill rule, perspective-correct
// interpolation of depth, normal and colour, shading per pixel with the splats' Shader.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>

#include "pointillist/core/camera.hpp"
#include "pointillist/core/math.hpp"
#include "shading.hpp"

namespace pointillist::render_detail {

// A triangle corner in eye space: x right, y up, depth z (> 0 in front); world normal, linear
// base colour 0..1.
struct EyeVertex {
  Vec3f p;
  Vec3f normal;
  Vec3f color;
};

// Perspective: 1/z and the attributes over z interpolate linearly on the screen. Orthographic:
// z and the attributes themselves do (inv_z then holds z, and "over z" means over 1).
struct ScreenVertex {
  double x, y;  // pixels
  double inv_z;
  Vec3f normal_over_z, color_over_z;
};

// A world point in the camera's eye space.
inline Vec3f eye_space(const CameraFrame& cam, Vec3f world) {
  const Vec3f d = world - cam.eye;
  return {dot(d, cam.right), dot(d, cam.up), dot(d, cam.forward)};
}

inline EyeVertex lerp(const EyeVertex& a, const EyeVertex& b, float t) {
  return {a.p + (b.p - a.p) * t, a.normal + (b.normal - a.normal) * t,
          a.color + (b.color - a.color) * t};
}

// Sutherland–Hodgman against z >= near; returns the vertex count (0, 3 or 4). A crossing edge is
// always interpolated from its inside end to its outside end, so two triangles that share the
// edge (traversing it in opposite directions) get the very same clipped point: no crack opens
// between them.
inline int clip_near(const std::array<EyeVertex, 3>& in, float near,
                     std::array<EyeVertex, 4>& out) {
  int n = 0;
  for (int i = 0; i < 3; ++i) {
    const EyeVertex& a = in[i];
    const EyeVertex& b = in[(i + 1) % 3];
    const bool a_in = a.p.z >= near, b_in = b.p.z >= near;
    if (a_in) out[n++] = a;
    if (a_in != b_in) {
      const EyeVertex& inside = a_in ? a : b;
      const EyeVertex& outside = a_in ? b : a;
      out[n++] = lerp(inside, outside, (near - inside.p.z) / (outside.p.z - inside.p.z));
    }
  }
  return n;
}

inline ScreenVertex project_vertex(const CameraFrame& cam, const EyeVertex& v) {
  if (cam.ortho) {
    return {0.5 * cam.width + cam.focal_px * double(v.p.x),
            0.5 * cam.height - cam.focal_px * double(v.p.y), double(v.p.z), v.normal, v.color};
  }
  const double inv_z = 1.0 / static_cast<double>(v.p.z);
  const float fz = static_cast<float>(inv_z);
  return {0.5 * cam.width + cam.focal_px * v.p.x * inv_z,
          0.5 * cam.height - cam.focal_px * v.p.y * inv_z, inv_z, v.normal * fz, v.color * fz};
}

// Rasterizes the screen triangle (a, b, c) in the rows [row_begin, row_end): a pixel is covered
// when its centre (i + 0.5, j + 0.5) is inside; centres exactly on an edge belong to top and
// left edges only, so triangles sharing an edge cover each of its pixels once. For a covered
// pixel with index idx = j·width + i and perspective-correct depth z, `test(idx, z)` says
// whether it may be drawn; then `write(idx, z, colour)` gets the pixel shaded with `shader` from
// the interpolated normal (flipped towards the eye) and base colour.
template <class Test, class Write>
void raster_triangle(const CameraFrame& cam, const Shader& shader, ScreenVertex a, ScreenVertex b,
                     ScreenVertex c, int row_begin, int row_end, const Test& test,
                     const Write& write) {
  double area = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
  if (!(area != 0.0) || !std::isfinite(area)) return;
  if (area < 0) {
    std::swap(b, c);
    area = -area;
  }
  // With this orientation (y down) the inside has all edge functions > 0; an edge is "top" when
  // horizontal going right and "left" when going up.
  const auto top_left = [](const ScreenVertex& p, const ScreenVertex& q) {
    const double dx = q.x - p.x, dy = q.y - p.y;
    return dy < 0 || (dy == 0 && dx > 0);
  };
  const bool tl_ab = top_left(a, b), tl_bc = top_left(b, c), tl_ca = top_left(c, a);
  const auto edge = [](const ScreenVertex& p, const ScreenVertex& q, double x, double y) {
    return (q.x - p.x) * (y - p.y) - (q.y - p.y) * (x - p.x);
  };
  const double w = cam.width;
  const double lo_x = std::max(0.0, std::ceil(std::min({a.x, b.x, c.x}) - 0.5));
  const double hi_x = std::min(w - 1, std::floor(std::max({a.x, b.x, c.x}) - 0.5));
  const double lo_y = std::max(double(row_begin), std::ceil(std::min({a.y, b.y, c.y}) - 0.5));
  const double hi_y = std::min(double(row_end - 1), std::floor(std::max({a.y, b.y, c.y}) - 0.5));
  if (!(lo_x <= hi_x && lo_y <= hi_y)) return;
  const double inv_area = 1.0 / area;
  const float half_w = 0.5f * static_cast<float>(cam.width);
  const float half_h = 0.5f * static_cast<float>(cam.height);
  for (int j = static_cast<int>(lo_y); j <= static_cast<int>(hi_y); ++j) {
    const double py = j + 0.5;
    for (int i = static_cast<int>(lo_x); i <= static_cast<int>(hi_x); ++i) {
      const double px = i + 0.5;
      const double e_ab = edge(a, b, px, py), e_bc = edge(b, c, px, py), e_ca = edge(c, a, px, py);
      const bool inside = (e_ab > 0 || (e_ab == 0 && tl_ab)) &&
                          (e_bc > 0 || (e_bc == 0 && tl_bc)) &&
                          (e_ca > 0 || (e_ca == 0 && tl_ca));
      if (!inside) continue;
      const double wa = e_bc * inv_area, wb = e_ca * inv_area, wc = e_ab * inv_area;
      const double inv_z = wa * a.inv_z + wb * b.inv_z + wc * c.inv_z;
      const float z = static_cast<float>(cam.ortho ? inv_z : 1.0 / inv_z);
      const std::size_t idx = static_cast<std::size_t>(j) * cam.width + i;
      if (!test(idx, z)) continue;
      const float attribute_scale = cam.ortho ? 1.0f : z;
      const float fa = static_cast<float>(wa), fb = static_cast<float>(wb),
                  fc = static_cast<float>(wc);
      const Vec3f n =
          (a.normal_over_z * fa + b.normal_over_z * fb + c.normal_over_z * fc) * attribute_scale;
      const Vec3f base =
          (a.color_over_z * fa + b.color_over_z * fb + c.color_over_z * fc) * attribute_scale;
      // Direction to the eye from the surface point seen through the pixel centre.
      const Vec3f ray =
          cam.ortho ? cam.forward
                    : cam.forward + cam.right * ((static_cast<float>(px) - half_w) / cam.focal_px) -
                          cam.up * ((static_cast<float>(py) - half_h) / cam.focal_px);
      write(idx, z, shader.shade(normalized(n, -ray), -ray / length(ray), base));
    }
  }
}

}  // namespace pointillist::render_detail
