// closest_point of the analytic scenes against the shapes' distance formulas, in rotated and
// translated frames.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <utility>

#include "pointillist/scene/analytic.hpp"

using namespace pointillist;

namespace {

// A shape whose local frame is rotated by `angle_deg` about `axis` (Rodrigues), moved to
// `center`.
AnalyticShape posed(ShapeKind kind, float a, float b, Vec3f center, Vec3f axis, float angle_deg) {
  axis = normalized(axis);
  const double t = angle_deg * 3.14159265358979323846 / 180.0;
  const auto rot = [&](Vec3f v) {
    return v * float(std::cos(t)) + cross(axis, v) * float(std::sin(t)) +
           axis * float(dot(axis, v) * (1 - std::cos(t)));
  };
  AnalyticShape s{kind, center, a, b};
  s.axis_x = rot({1, 0, 0});
  s.axis_y = rot({0, 1, 0});
  s.axis_z = rot({0, 0, 1});
  return s;
}

Vec3f to_world(const AnalyticShape& s, Vec3f local) {
  return s.center + s.axis_x * local.x + s.axis_y * local.y + s.axis_z * local.z;
}
Vec3f dir_to_world(const AnalyticShape& s, Vec3f d) {
  return s.axis_x * d.x + s.axis_y * d.y + s.axis_z * d.z;
}
Vec3f to_local(const AnalyticShape& s, Vec3f p) {
  const Vec3f d = p - s.center;
  return {dot(d, s.axis_x), dot(d, s.axis_y), dot(d, s.axis_z)};
}

// Unsigned distance to each shape by its textbook formula, in local coordinates (double).
double formula_distance(const AnalyticShape& s, Vec3f p) {
  const Vec3f l = to_local(s, p);
  const double x = l.x, y = l.y, z = l.z;
  switch (s.kind) {
    case ShapeKind::Sphere: return std::abs(std::sqrt(x * x + y * y + z * z) - s.a);
    case ShapeKind::Torus: return std::abs(std::hypot(std::hypot(x, z) - s.a, y) - s.b);
    case ShapeKind::Cube: {
      const double q[3] = {std::abs(x) - s.a, std::abs(y) - s.a, std::abs(z) - s.a};
      const double outside = std::sqrt(std::pow(std::max(q[0], 0.0), 2) +
                                       std::pow(std::max(q[1], 0.0), 2) +
                                       std::pow(std::max(q[2], 0.0), 2));
      return std::abs(outside + std::min(std::max({q[0], q[1], q[2]}), 0.0));
    }
  }
  return 0;
}

// The returned point must be as far from p as the distance says, and lie on the surface.
void expect_consistent(const AnalyticScene& scene, Vec3f p, const AnalyticClosest& c) {
  EXPECT_NEAR(distance(p, c.point), c.distance, 2e-6f);
  double on_surface = 1e30;
  for (const auto& s : scene.shapes) {
    on_surface = std::min(on_surface, formula_distance(s, c.point));
  }
  EXPECT_NEAR(on_surface, 0.0, 2e-6);
  EXPECT_NEAR(length(c.normal), 1.0f, 1e-5f);
}

}  // namespace

TEST(AnalyticClosest, SphereDistanceIsRadialOffsetInAMovedFrame) {
  const AnalyticShape sphere = posed(ShapeKind::Sphere, 0.8f, 0, {1, -2, 0.5f}, {1, 2, 3}, 40);
  const AnalyticScene scene{{sphere}};
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> uni(-2.0f, 2.0f);
  for (int i = 0; i < 500; ++i) {
    const Vec3f p = sphere.center + Vec3f{uni(rng), uni(rng), uni(rng)};
    const AnalyticClosest c = closest_point(scene, p);
    const Vec3f radial = normalized(p - sphere.center);
    EXPECT_NEAR(c.distance, std::abs(distance(p, sphere.center) - 0.8f), 2e-6f);
    EXPECT_NEAR(distance(c.point, sphere.center + radial * 0.8f), 0.0f, 2e-6f);
    EXPECT_NEAR(std::abs(dot(c.normal, radial)), 1.0f, 1e-5f);
    expect_consistent(scene, p, c);
  }
}

TEST(AnalyticClosest, CubeFaceEdgeCornerAndInsidePoints) {
  const AnalyticShape cube = posed(ShapeKind::Cube, 0.5f, 0, {-0.3f, 0.7f, 2}, {0.3f, 1, 0.2f}, 35);
  const AnalyticScene scene{{cube}};
  struct Case {
    Vec3f local, closest_local, normal_local;
    float distance;
  };
  const Case cases[] = {
      {{0.8f, 0.1f, -0.2f}, {0.5f, 0.1f, -0.2f}, {1, 0, 0}, 0.3f},                   // face
      {{0.9f, 0.8f, 0.1f}, {0.5f, 0.5f, 0.1f}, {0.8f, 0.6f, 0}, 0.5f},               // edge
      {{-0.7f, 0.9f, -1.1f}, {-0.5f, 0.5f, -0.5f}, {-0.2f, 0.4f, -0.6f}, 0.7483315f},  // corner
      {{0.1f, -0.35f, 0.2f}, {0.1f, -0.5f, 0.2f}, {0, -1, 0}, 0.15f},                // inside
      {{0.2f, 0.1f, 0.45f}, {0.2f, 0.1f, 0.5f}, {0, 0, 1}, 0.05f},                   // inside
  };
  for (const Case& k : cases) {
    const Vec3f p = to_world(cube, k.local);
    const AnalyticClosest c = closest_point(scene, p);
    EXPECT_NEAR(c.distance, k.distance, 2e-6f);
    EXPECT_NEAR(distance(c.point, to_world(cube, k.closest_local)), 0.0f, 2e-6f);
    EXPECT_NEAR(dot(c.normal, dir_to_world(cube, normalized(k.normal_local))), 1.0f, 1e-5f);
  }
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> uni(-1.2f, 1.2f);
  for (int i = 0; i < 1000; ++i) {
    const Vec3f p = to_world(cube, {uni(rng), uni(rng), uni(rng)});
    const AnalyticClosest c = closest_point(scene, p);
    EXPECT_NEAR(c.distance, formula_distance(cube, p), 2e-6);
    expect_consistent(scene, p, c);
  }
}

TEST(AnalyticClosest, TorusPointsOnItsPlaneAndOffIt) {
  const AnalyticShape torus = posed(ShapeKind::Torus, 1.2f, 0.3f, {2, 1, -1}, {1, 0, 1}, 60);
  const AnalyticScene scene{{torus}};
  // In the torus' own plane at angle φ about its axis, the distance is ||ρ − a| − b|.
  for (const float phi : {0.0f, 1.0f, 2.5f, 4.0f}) {
    const Vec3f radial{std::cos(phi), 0, std::sin(phi)};
    const std::pair<float, float> rho_and_distance[] = {
        {2.0f, 0.5f}, {1.2f, 0.3f}, {1.4f, 0.1f}, {0.5f, 0.4f}, {0.9f, 0.0f}, {0.0f, 0.9f}};
    for (const auto& [rho, expected] : rho_and_distance) {
      const Vec3f p = to_world(torus, radial * rho);
      const AnalyticClosest c = closest_point(scene, p);
      EXPECT_NEAR(c.distance, expected, 2e-6f) << "rho " << rho << " phi " << phi;
      expect_consistent(scene, p, c);
    }
  }
  // Above the plane: √((ρ − a)² + y²) − b.
  const Vec3f p = to_world(torus, {1.2f + 0.3f, 0.4f, 0});
  const AnalyticClosest above = closest_point(scene, p);
  EXPECT_NEAR(above.distance, 0.5f - 0.3f, 2e-6f);
  EXPECT_NEAR(dot(above.normal, dir_to_world(torus, {0.6f, 0.8f, 0})), 1.0f, 1e-5f);
  std::mt19937 rng(13);
  std::uniform_real_distribution<float> uni(-2.0f, 2.0f);
  for (int i = 0; i < 1000; ++i) {
    const Vec3f q = torus.center + Vec3f{uni(rng), uni(rng), uni(rng)};
    const AnalyticClosest c = closest_point(scene, q);
    EXPECT_NEAR(c.distance, formula_distance(torus, q), 2e-6);
    expect_consistent(scene, q, c);
  }
}

TEST(AnalyticClosest, SceneTakesTheNearestShape) {
  const AnalyticScene scene = demo_scene();
  std::mt19937 rng(17);
  std::uniform_real_distribution<float> x(-4, 4), yz(-2, 2);
  for (int i = 0; i < 2000; ++i) {
    const Vec3f p{x(rng), yz(rng), yz(rng)};
    double expected = 1e30;
    for (const auto& s : scene.shapes) expected = std::min(expected, formula_distance(s, p));
    const AnalyticClosest c = closest_point(scene, p);
    EXPECT_NEAR(c.distance, expected, 3e-6);
    expect_consistent(scene, p, c);
  }
}

TEST(AnalyticClosest, EmptySceneIsInfinitelyFar) {
  EXPECT_EQ(closest_point(AnalyticScene{}, {1, 2, 3}).distance,
            std::numeric_limits<float>::infinity());
}
