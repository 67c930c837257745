#include "pointillist/scene/analytic.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace pointillist;

TEST(AnalyticScene, SphereSamplesLieOnTheSphereWithRadialNormals) {
  const auto s = sample_scene(sphere_scene(2.0f), 2000, 7);
  ASSERT_EQ(s.points.size(), 2000u);
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    const Vec3f p = s.points.positions[i];
    EXPECT_NEAR(length(p), 2.0f, 1e-5f);
    EXPECT_NEAR(dot(s.true_normals[i], p / length(p)), 1.0f, 1e-5f);
  }
}

TEST(AnalyticScene, TorusSamplesLieOnTheTubeAndAreUniformByArea) {
  const float R = 1.0f, r = 0.35f;
  const auto s = sample_scene(torus_scene(R, r), 20000, 3);
  int outer = 0;
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    const Vec3f p = s.points.positions[i];
    const float rho = std::sqrt(p.x * p.x + p.z * p.z);
    EXPECT_NEAR(std::hypot(rho - R, p.y), r, 1e-5f);
    if (rho > R) ++outer;
  }
  // Area of the outer half (rho > R) is (R + 2r/π)/(2R) of the total.
  const double expected = (R + 2 * r / 3.14159265) / (2 * R);
  EXPECT_NEAR(double(outer) / s.points.size(), expected, 0.015);
}

TEST(AnalyticScene, CubeSamplesLieOnFacesWithFaceNormals) {
  const auto s = sample_scene(cube_scene(1.0f), 3000, 11);
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    const Vec3f p = s.points.positions[i];
    const float m = std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)});
    EXPECT_NEAR(m, 1.0f, 1e-6f);
    EXPECT_NEAR(dot(s.true_normals[i], p), 1.0f, 1e-5f);  // n·p = half side on a face
    EXPECT_GE(s.edge_distance[i], 0.0f);
  }
}

TEST(AnalyticScene, SameSeedGivesSameSamples) {
  const auto a = sample_scene(demo_scene(), 500, 5);
  const auto b = sample_scene(demo_scene(), 500, 5);
  for (std::size_t i = 0; i < 500; ++i) EXPECT_EQ(a.points.positions[i], b.points.positions[i]);
}

TEST(AnalyticScene, RayCastHitsSphereTorusAndCubeAtKnownDistances) {
  const auto sphere = ray_cast(sphere_scene(1.0f), {0, 0, 5}, {0, 0, -1});
  ASSERT_TRUE(sphere);
  EXPECT_NEAR(sphere->t, 4.0f, 1e-5f);
  EXPECT_NEAR(sphere->normal.z, 1.0f, 1e-5f);
  // Along +x through the torus (axis y): enters the outer wall at x = R + r.
  const auto torus = ray_cast(torus_scene(1.0f, 0.25f), {5, 0, 0}, {-1, 0, 0});
  ASSERT_TRUE(torus);
  EXPECT_NEAR(torus->t, 5.0f - 1.25f, 1e-4f);
  EXPECT_NEAR(torus->normal.x, 1.0f, 1e-3f);
  // Straight down the axis of the torus there is nothing to hit.
  EXPECT_FALSE(ray_cast(torus_scene(1.0f, 0.25f), {0, 5, 0}, {0, -1, 0}));
  const auto cube = ray_cast(cube_scene(0.5f), {0.2f, 3, 0.1f}, {0, -1, 0});
  ASSERT_TRUE(cube);
  EXPECT_NEAR(cube->t, 2.5f, 1e-5f);
  EXPECT_NEAR(cube->normal.y, 1.0f, 1e-6f);
}

TEST(AnalyticScene, RayCastImageOfSphereCoversItsAnalyticDisc) {
  Camera cam{.eye = {0, 0, 4}, .target = {0, 0, 0}, .fov_deg = 30, .width = 64, .height = 64};
  const auto img = ray_cast_image(sphere_scene(1.0f), cam);
  const CameraFrame f = make_camera_frame(cam);
  // The silhouette of a unit sphere seen from distance 4 is a disc of angular radius asin(1/4).
  const float radius_px = f.focal_px * std::tan(std::asin(0.25f));
  int mismatches = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      const float dx = x + 0.5f - 32, dy = y + 0.5f - 32;
      const float rr = std::sqrt(dx * dx + dy * dy);
      if (std::abs(rr - radius_px) < 0.75f) continue;  // boundary pixels
      mismatches += (rr < radius_px) != bool(img.covered[y * 64 + x]);
    }
  EXPECT_EQ(mismatches, 0);
}
