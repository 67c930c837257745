// The per-splat rules on hand-built configurations whose answers are known exactly: the region
// of the splat's plane that belongs to its face. Each test samples the disc and compares the
// clip test with that region.
#include "pointillist/features/rules.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>

using namespace pointillist;

namespace {

constexpr float kR = 0.1f;
constexpr Vec3f kX{1, 0, 0}, kY{0, 1, 0}, kZ{0, 0, 1};

// Share of a dense grid of points on the disc of `s` where the clip test disagrees with
// `kept` (points within 1e-4 of the region's boundary are skipped).
double wrong_share(const Disc& s, const ClipResult& clip, const std::function<bool(Vec3f)>& kept,
                   const std::function<float(Vec3f)>& boundary_distance) {
  const Vec3f helper = std::fabs(s.n.x) < 0.9f ? kX : kY;
  const Vec3f u = normalized(cross(s.n, helper)), v = cross(s.n, u);
  int total = 0, wrong = 0;
  constexpr int kSteps = 101;
  for (int a = 0; a < kSteps; ++a) {
    for (int b = 0; b < kSteps; ++b) {
      const float du = (2.0f * a / (kSteps - 1) - 1) * s.r, dv = (2.0f * b / (kSteps - 1) - 1) * s.r;
      if (du * du + dv * dv > s.r * s.r) continue;
      const Vec3f p = s.c + u * du + v * dv;
      if (std::fabs(boundary_distance(p)) < 1e-4f) continue;
      ++total;
      wrong += clip_discards(clip.planes, clip.mode, p) == kept(p);
    }
  }
  return static_cast<double>(wrong) / total;
}

// Continuous neighbours of a splat on a plane: a ring around it within the face's region.
std::vector<Vec3f> ring(const Disc& s, const std::function<bool(Vec3f)>& inside) {
  const Vec3f helper = std::fabs(s.n.x) < 0.9f ? kX : kY;
  const Vec3f u = normalized(cross(s.n, helper)), v = cross(s.n, u);
  std::vector<Vec3f> out;
  for (int k = 0; k < 8; ++k) {
    const float a = k * kPi / 4;
    const Vec3f p = s.c + (u * std::cos(a) + v * std::sin(a)) * (0.9f * s.r);
    if (inside(p)) out.push_back(p);
  }
  return out;
}

TEST(DiscCrossing, PerpendicularDiscsAtACubeEdgeCross) {
  EXPECT_EQ(disc_crossing({{0.95f, 1, 0}, kY, kR}, {{1, 0.95f, 0}, kX, kR}), Crossing::Cross);
}

TEST(DiscCrossing, DiscsSideBySideAlongTheLineDoNotCross) {
  // The planes meet on x = 0.05, y = 0; the chords are z in ±0.087 and 0.5 ± 0.1.
  EXPECT_EQ(disc_crossing({{0, 0, 0}, kY, kR}, {{0.05f, 0, 0.5f}, kX, kR}), Crossing::Apart);
  // A line that misses one disc altogether.
  EXPECT_EQ(disc_crossing({{0, 0, 0}, kY, kR}, {{0.2f, 0.05f, 0}, kX, kR}), Crossing::Apart);
}

TEST(DiscCrossing, TouchingChordsCount) {
  // Chords [−0.5, 0.5] and [0.5, 1.5] along z share their end point (closed intervals, Q6;
  // values exact in binary).
  EXPECT_EQ(disc_crossing({{0, 0, 0}, kY, 0.5f}, {{0, 0, 1}, kX, 0.5f}), Crossing::Cross);
  EXPECT_EQ(disc_crossing({{0, 0, 0}, kY, 0.5f}, {{0, 0, 1.0001f}, kX, 0.5f}), Crossing::Apart);
}

TEST(DiscCrossing, AntiparallelAndParallelPlanesAreNeverPartners) {
  // The two faces of a slab thinner than a splat (Smiling Face): n_a × n_b = 0.
  EXPECT_EQ(disc_crossing({{0, 0, 0.01f}, kZ, kR}, {{0.02f, 0, -0.01f}, -kZ, kR}),
            Crossing::Parallel);
  EXPECT_EQ(disc_crossing({{0, 0, 0}, kZ, kR}, {{0.02f, 0, 0.01f}, kZ, kR}), Crossing::Parallel);
}

TEST(SideTest, ACreaseEndsAndAnIntersectionPassesThrough) {
  const Disc top{{0.95f, 1, 0}, kY, kR};
  const Disc side{{1, 0.95f, 0}, kX, kR};
  const auto on_top = [](Vec3f p) { return p.x <= 1; };
  EXPECT_TRUE(surface_ends_at(top, ring(top, on_top), side));
  // Two planes crossing on x = 0: the y = 0 plane continues on both sides.
  const Disc floor{{0.01f, 0, 0}, kY, kR};
  const Disc wall{{0, 0.01f, 0}, kX, kR};
  EXPECT_FALSE(surface_ends_at(floor, ring(floor, [](Vec3f) { return true; }), wall));
  // A T-junction: the wall standing on the floor ends there, the floor does not.
  EXPECT_TRUE(surface_ends_at(wall, ring(wall, [](Vec3f p) { return p.y >= 0; }), floor));
}

TEST(LinsenTest, TellsABoundaryFromAnInteriorSplat) {
  const Disc s{{0, 0, 0}, kY, kR};
  EXPECT_FALSE(linsen_boundary(s, ring(s, [](Vec3f) { return true; }), 90));
  EXPECT_TRUE(linsen_boundary(s, ring(s, [](Vec3f p) { return p.x <= 0.001f; }), 90));
  EXPECT_TRUE(linsen_boundary(s, {}, 90));
}

struct Config {
  Disc s;
  std::vector<Disc> partners;  // nearest first
  std::function<bool(Vec3f)> kept;
  std::function<float(Vec3f)> boundary;
};

ClipResult classify(const Config& c, ClipRule rule) {
  return classify_partners(c.s, c.partners, ring(c.s, c.kept), rule);
}

// Cube corner (1, 1, 1), top-face splat: the quadrant x <= 1, z <= 1 (union).
Config cube_corner() {
  return {{{0.95f, 1, 0.95f}, kY, kR},
          {{{1, 0.95f, 0.95f}, kX, kR}, {{0.95f, 0.95f, 1}, kZ, kR}},
          [](Vec3f p) { return p.x <= 1 && p.z <= 1; },
          [](Vec3f p) { return std::min(std::fabs(p.x - 1), std::fabs(p.z - 1)); }};
}

// The reflex vertex of an L-shaped top face (the quadrant x > 0, z > 0 is cut away): three
// quadrants are kept (intersection).
Config reflex_vertex() {
  return {{{-0.03f, 1, -0.03f}, kY, kR},
          {{{0, 0.97f, 0.05f}, kX, kR}, {{0.05f, 0.97f, 0}, kZ, kR}},
          [](Vec3f p) { return !(p.x > 0 && p.z > 0); },
          [](Vec3f p) { return std::min(std::fabs(p.x), std::fabs(p.z)); }};
}

// A room's floor corner, walls facing into the room (concave).
Config room_corner() {
  return {{{0.03f, 0, 0.03f}, kY, kR},
          {{{0, 0.03f, 0.05f}, kX, kR}, {{0.05f, 0.03f, 0}, kZ, kR}},
          [](Vec3f p) { return p.x >= 0 && p.z >= 0; },
          [](Vec3f p) { return std::min(std::fabs(p.x), std::fabs(p.z)); }};
}

// The top face of a plate around a hole of radius 0.5 (T4): the wall's tangent planes at −10°,
// 0° and 10°, normals toward the axis; the kept region is outside the circle (intersection).
Config hole_rim() {
  Config c;
  c.s = {{0.55f, 0.2f, 0}, kY, kR};
  for (float deg : {0.0f, -10.0f, 10.0f}) {
    const float a = deg_to_rad(deg);
    c.partners.push_back({{0.5f * std::cos(a), 0.17f, 0.5f * std::sin(a)},
                          {-std::cos(a), 0, -std::sin(a)}, kR});
  }
  c.kept = [](Vec3f p) { return p.x * p.x + p.z * p.z >= 0.25f; };
  c.boundary = [](Vec3f p) { return std::sqrt(p.x * p.x + p.z * p.z) - 0.5f; };
  return c;
}

// The step's mixed corner (0, 0, 1) (T8): the floor meets the riser above it (concave) and the
// front face below it (convex), where eqs. 4.13–4.15 are undefined.
Config mixed_corner() {
  return {{{0.03f, 0, 0.97f}, kY, kR},
          {{{0, 0.03f, 0.97f}, kX, kR}, {{0.03f, -0.03f, 1}, kZ, kR}, {{-0.03f, 0.03f, 1}, kZ, kR}},
          [](Vec3f p) { return p.x >= 0 && p.z <= 1; },
          [](Vec3f p) { return std::min(std::fabs(p.x), std::fabs(p.z - 1)); }};
}

// A straight cube edge with two coplanar partners: (4.13) is exactly 0.
Config coplanar_edge() {
  return {{{0.95f, 1, 0}, kY, kR},
          {{{1, 0.95f, -0.05f}, kX, kR}, {{1, 0.95f, 0.05f}, kX, kR}},
          [](Vec3f p) { return p.x <= 1; },
          [](Vec3f p) { return std::fabs(p.x - 1); }};
}

TEST(ClassifyPartners, KeepsExactlyTheFaceOnPlanarConfigurations) {
  const std::pair<const char*, Config> cases[] = {{"cube corner", cube_corner()},
                                                  {"reflex vertex", reflex_vertex()},
                                                  {"room corner", room_corner()},
                                                  {"mixed corner", mixed_corner()},
                                                  {"coplanar edge", coplanar_edge()}};
  for (const auto& [name, c] : cases) {
    const ClipResult clip = classify(c, ClipRule::Classified);
    EXPECT_NE(clip.mode, ClipMode::None) << name;
    EXPECT_EQ(wrong_share(c.s, clip, c.kept, c.boundary), 0.0) << name;
  }
}

TEST(ClassifyPartners, ChoosesUnionAtConvexAndIntersectionAtReflexCorners) {
  EXPECT_EQ(classify(cube_corner(), ClipRule::Classified).mode, ClipMode::Union);
  EXPECT_EQ(classify(room_corner(), ClipRule::Classified).mode, ClipMode::Union);
  EXPECT_EQ(classify(reflex_vertex(), ClipRule::Classified).mode, ClipMode::Intersection);
  EXPECT_EQ(classify(hole_rim(), ClipRule::Classified).mode, ClipMode::Intersection);
  // Coplanar partners collapse to one plane.
  EXPECT_EQ(classify(coplanar_edge(), ClipRule::Classified).planes.size(), 1u);
}

TEST(ClassifyPartners, CurvedRimIsApproximatedByItsTangentPlanes) {
  const Config c = hole_rim();
  const ClipResult clip = classify(c, ClipRule::Classified);
  EXPECT_LT(wrong_share(c.s, clip, c.kept, c.boundary), 0.01);
  // The dissertation's rule agrees where it is defined (N_cp concave, S ∪ N_cp convex).
  const ClipResult b3 = classify(c, ClipRule::Dissertation);
  EXPECT_FALSE(b3.undefined_4_15);
  EXPECT_EQ(b3.mode, ClipMode::Intersection);
  EXPECT_LT(wrong_share(c.s, b3, c.kept, c.boundary), 0.01);
}

TEST(ClassifyPartners, DissertationRuleMatchesWhereDefinedAndReportsWhereNot) {
  for (const Config& c : {cube_corner(), reflex_vertex(), room_corner()}) {
    const ClipResult b3 = classify(c, ClipRule::Dissertation);
    EXPECT_FALSE(b3.undefined_4_15);
    EXPECT_EQ(wrong_share(c.s, b3, c.kept, c.boundary), 0.0);
  }
  // The named failures: the mixed corner and coplanar partners leave the rule undefined, and
  // the faithful version does not clip there.
  for (const Config& c : {mixed_corner(), coplanar_edge()}) {
    const ClipResult b3 = classify(c, ClipRule::Dissertation);
    EXPECT_TRUE(b3.undefined_4_15);
    EXPECT_EQ(b3.mode, ClipMode::None);
    EXPECT_TRUE(classify(c, ClipRule::Classified).undefined_4_15);  // reported by any rule
  }
}

TEST(ClassifyPartners, IndependentUnionPunchesAHoleAtAReflexVertex) {
  // Zwicker-style clipping (B1) discards the kept quadrants beside the cut-away one.
  const Config c = reflex_vertex();
  EXPECT_GT(wrong_share(c.s, classify(c, ClipRule::Independent), c.kept, c.boundary), 0.2);
  // Nearest partner only (B2) keeps one plane.
  EXPECT_EQ(classify(cube_corner(), ClipRule::NearestPartner).planes.size(), 1u);
}

TEST(ClassifyPartners, PlanesAreScaledToInPlaneDistances) {
  // A partner plane at 45° to the splat: within the splat's plane, the value is the distance
  // to the line where the planes meet.
  const float s2 = std::sqrt(0.5f);
  const Disc s{{0, 0, 0}, kY, kR};
  const Disc p{{0.05f, 0, 0}, {s2, s2, 0}, kR};
  const ClipResult clip = classify_partners(s, {&p, 1}, {}, ClipRule::Classified);
  ASSERT_EQ(clip.planes.size(), 1u);
  EXPECT_NEAR(plane_side(clip.planes[0], {0.02f, 0, 0.3f}), 0.03f, 1e-6f);
  EXPECT_NEAR(plane_side(clip.planes[0], {0.09f, 0, -0.2f}), -0.04f, 1e-6f);
}

}  // namespace
