// The reference triangle rasterizer against analytic pixel sets and exact ray casting.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <limits>

#include "pointillist/core/error.hpp"
#include "pointillist/render/mesh_reference.hpp"
#include "pointillist/scene/analytic.hpp"
#include "render_test_util.hpp"

using namespace pointillist;
using namespace pointillist::render_test;

namespace {

// World point (eye space = world space for axis_camera) that projects to pixel coordinates
// (px, py) at depth z.
Vec3f unproject(const Camera& cam, double px, double py, double z) {
  const double f = focal_px(cam);
  return {static_cast<float>((px - 0.5 * cam.width) * z / f),
          static_cast<float>(-(py - 0.5 * cam.height) * z / f), static_cast<float>(-z)};
}

Frame draw(const PointSet& mesh, const Camera& cam, RenderSettings s = {}) {
  Frame f;
  render_mesh_reference(mesh, cam, s, f);
  return f;
}

}  // namespace

TEST(MeshReference, QuadCoversExactlyThePixelCentresInside) {
  const Camera cam = axis_camera(64, 48);
  PointSet quad;
  // Edges at x = 10.3 and 50.7, y = 5.2 and 40.6 pixels: no centre near an edge.
  quad.positions = {unproject(cam, 10.3, 5.2, 2), unproject(cam, 50.7, 5.2, 2),
                    unproject(cam, 50.7, 40.6, 2), unproject(cam, 10.3, 40.6, 2)};
  quad.triangles = {{0, 1, 2}, {0, 2, 3}};
  RenderSettings s;
  s.background = {1, 2, 3};
  const Frame f = draw(quad, cam, s);
  int wrong = 0;
  for (int j = 0; j < 48; ++j) {
    for (int i = 0; i < 64; ++i) {
      const bool want = i >= 10 && i <= 50 && j >= 5 && j <= 40;  // centres i + 0.5 inside
      wrong += want != covered(f, i, j);
      if (want) {
        EXPECT_NEAR(f.depth[j * 64 + i], 2.0f, 1e-5f);
      } else {
        EXPECT_EQ(f.color[j * 64 + i], (Rgb8{1, 2, 3}));
      }
    }
  }
  EXPECT_EQ(wrong, 0);
}

TEST(MeshReference, TopLeftRuleGivesEdgePixelsToOneTriangleOnly) {
  // Odd size: x = 0 projects to 32.5 (the centre of column 32), y = 0 to row 32's centre.
  const Camera cam = axis_camera(65, 65);
  const float a = 1.0f, z = -4.0f;
  PointSet left, right, top, bottom;
  left.positions = {{0, a, z}, {0, -a, z}, {-a, 0, z}};
  right.positions = {{0, a, z}, {0, -a, z}, {a, 0, z}};
  top.positions = {{-a, 0, z}, {a, 0, z}, {0, a, z}};      // above row 32 (y up)
  bottom.positions = {{-a, 0, z}, {a, 0, z}, {0, -a, z}};
  for (PointSet* m : {&left, &right, &top, &bottom}) m->triangles = {{0, 1, 2}};
  const Frame fl = draw(left, cam), fr = draw(right, cam), ft = draw(top, cam),
              fb = draw(bottom, cam);
  // Column 32 lies on the shared vertical edge: the right triangle's left edge owns it.
  EXPECT_FALSE(covered(fl, 32, 32));
  EXPECT_TRUE(covered(fl, 31, 32));
  EXPECT_TRUE(covered(fr, 32, 32));
  EXPECT_TRUE(covered(fr, 32, 30));
  // Row 32 lies on the shared horizontal edge: the lower triangle's top edge owns it.
  EXPECT_FALSE(covered(ft, 32, 32));
  EXPECT_TRUE(covered(ft, 32, 31));
  EXPECT_TRUE(covered(fb, 32, 32));
  // Together the pairs cover their diamond without gaps and without double ownership.
  for (int j = 0; j < 65; ++j) {
    for (int i = 0; i < 65; ++i) {
      EXPECT_FALSE(covered(fl, i, j) && covered(fr, i, j)) << i << "," << j;
      EXPECT_FALSE(covered(ft, i, j) && covered(fb, i, j)) << i << "," << j;
    }
  }
  int lr = 0, tb = 0;
  for (int j = 0; j < 65; ++j)
    for (int i = 0; i < 65; ++i) {
      lr += covered(fl, i, j) || covered(fr, i, j);
      tb += covered(ft, i, j) || covered(fb, i, j);
    }
  EXPECT_EQ(lr, tb);  // the same diamond, split two ways
}

TEST(MeshReference, DepthOfATiltedPlaneIsPerspectiveCorrect) {
  const Camera cam = axis_camera(64, 48);
  const CameraFrame cf = make_camera_frame(cam);
  // Plane through (0, 0, −3) with normal (0.5, 0.3, 1) (normalized), drawn as a big quad.
  const Vec3f n = normalized({0.5f, 0.3f, 1.0f});
  const Vec3f p0{0, 0, -3};
  const Vec3f u = normalized(cross(n, {0, 1, 0})), w = cross(n, u);
  PointSet quad;
  for (Vec3f c : {u + w, u - w, -u - w, -u + w}) quad.positions.push_back(p0 + c * 2.5f);
  quad.triangles = {{0, 1, 2}, {0, 2, 3}};
  const Frame f = draw(quad, cam);
  int checked = 0;
  for (int j = 0; j < 48; ++j) {
    for (int i = 0; i < 64; ++i) {
      if (!covered(f, i, j)) continue;
      // Ray through the pixel centre: eye + t·(x/f, −y/f, −1); depth = t.
      const double dx = (i + 0.5 - 32) / cf.focal_px, dy = -(j + 0.5 - 24) / cf.focal_px;
      const double t = (double(n.x) * p0.x + double(n.y) * p0.y + double(n.z) * p0.z) /
                       (n.x * dx + n.y * dy - n.z);
      EXPECT_NEAR(f.depth[j * 64 + i], t, 1e-5 * t);
      ++checked;
    }
  }
  EXPECT_GT(checked, 1000);
}

TEST(MeshReference, TessellatedSphereMatchesRayCastSilhouetteAndShading) {
  // UV sphere of radius 1 with exact vertex normals.
  PointSet mesh;
  const int rings = 48, segments = 96;
  for (int i = 0; i <= rings; ++i) {
    const double th = kPiD * i / rings;
    for (int j = 0; j < segments; ++j) {
      const double ph = 2 * kPiD * j / segments;
      const Vec3f p{float(std::sin(th) * std::cos(ph)), float(std::cos(th)),
                    float(std::sin(th) * std::sin(ph))};
      mesh.positions.push_back(p);
      mesh.normals.push_back(p);
    }
  }
  for (int i = 0; i < rings; ++i) {
    for (int j = 0; j < segments; ++j) {
      const std::uint32_t a = i * segments + j, b = i * segments + (j + 1) % segments;
      const std::uint32_t c = a + segments, d = b + segments;
      mesh.triangles.push_back({a, c, b});
      mesh.triangles.push_back({b, c, d});
    }
  }
  Camera cam;
  cam.eye = {0.3f, 0.4f, 4.0f};
  cam.target = {0, 0, 0};
  cam.width = 160;
  cam.height = 120;
  const Frame f = draw(mesh, cam);
  const RayCastImage ref = ray_cast_image(sphere_scene(1.0f), cam);
  int both = 0, either = 0;
  double sum_error = 0, max_error = 0;
  for (std::size_t i = 0; i < f.depth.size(); ++i) {
    const bool m = std::isfinite(f.depth[i]), r = ref.covered[i] != 0;
    both += m && r;
    either += m || r;
    if (m && r) {
      const double e = std::abs(double(f.depth[i]) - ref.depth[i]);
      sum_error += e;
      max_error = std::max(max_error, e);
    }
  }
  EXPECT_GT(double(both) / either, 0.99);
  // Quad centres lie inside the sphere by about 2·(1 − cos(π/96)) ≈ 1.1e-3 (more in depth at
  // grazing angles).
  EXPECT_LT(sum_error / both, 2e-3);
  EXPECT_LT(max_error, 0.1);
  // Where the ray hits the sphere head-on (normal = direction to the eye = headlight), the color is
  // 0.8·(0.08 + 0.85) + 0.25 = 0.994 → 253; allow for the tessellation's normal error.
  const CameraFrame cf = make_camera_frame(cam);
  const Vec3f towards_eye = normalized(cam.eye);
  const Vec3f centre_pixel = towards_eye;  // surface point nearest the eye
  const Vec3f d = centre_pixel - cam.eye;
  const float z = dot(d, cf.forward);
  const int px = int(cam.width / 2.0f + cf.focal_px * dot(d, cf.right) / z);
  const int py = int(cam.height / 2.0f - cf.focal_px * dot(d, cf.up) / z);
  const Rgb8 c = f.color[py * cam.width + px];
  EXPECT_NEAR(c.r, 253, 3);
  EXPECT_EQ(c.r, c.g);
  EXPECT_EQ(c.g, c.b);
}

// A scene of two transformed instances of a mesh is drawn as the one mesh made of both,
// transformed beforehand (the same triangles in the same order, so the same pixels).
TEST(MeshReference, SceneInstancesAreTheirMeshesAtTheirTransforms) {
  PointSet mesh;
  mesh.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0.5f}, {-1, 1, 0.2f}};
  mesh.normals = {normalized(Vec3f{0.1f, 0, 1}), normalized(Vec3f{0, 0.2f, 1}),
                  normalized(Vec3f{-0.1f, 0, 1}), normalized(Vec3f{0, -0.3f, 1})};
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  InstanceTransform a, b;
  a.translate = {-0.8f, 0, -5};
  b.translate = {0.9f, 0.2f, -6};
  b.scale = 1.5f;
  const float c = std::cos(0.4f), s = std::sin(0.4f);
  b.rotation[0] = {c, 0, s};
  b.rotation[1] = {0, 1, 0};
  b.rotation[2] = {-s, 0, c};
  const RenderModel model{.mesh = &mesh, .name = "quad"};
  const SceneInstance scene[] = {{&model, a}, {&model, b}};
  PointSet merged;
  for (const InstanceTransform* t : {&a, &b}) {
    const auto base = static_cast<std::uint32_t>(merged.positions.size());
    for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
      merged.positions.push_back(t->apply(mesh.positions[i]));
      merged.normals.push_back(t->rotate(mesh.normals[i]));
    }
    for (const auto& tri : mesh.triangles) {
      merged.triangles.push_back({base + tri[0], base + tri[1], base + tri[2]});
    }
  }
  const Camera cam = axis_camera(96, 64);
  Frame want, got;
  render_mesh_reference(merged, cam, RenderSettings{}, want);
  render_mesh_reference(scene, cam, RenderSettings{}, got);
  int covered_pixels = 0;
  for (int j = 0; j < 64; ++j) {
    for (int i = 0; i < 96; ++i) covered_pixels += covered(want, i, j);
  }
  EXPECT_GT(covered_pixels, 500);
  EXPECT_TRUE(std::equal(want.color.begin(), want.color.end(), got.color.begin()));
  EXPECT_TRUE(std::equal(want.depth.begin(), want.depth.end(), got.depth.begin()));
  // A model without a mesh is named.
  const RenderModel cloud{.name = "cloud.ply"};
  const SceneInstance bad[] = {{&model, a}, {&cloud, {}}};
  try {
    render_mesh_reference(bad, cam, RenderSettings{}, got);
    FAIL() << "drew a model without a mesh";
  } catch (const OptionError& e) {
    EXPECT_NE(std::string(e.what()).find("cloud.ply"), std::string::npos);
  }
}
