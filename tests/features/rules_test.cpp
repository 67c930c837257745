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
  const auto [u, v] = tangent_frame(s.n);
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
  const auto [u, v] = tangent_frame(s.n);
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

namespace {

// Points and outward normals of a sphere around the splat at `c` (on the sphere), on a ring of
// radius `d` in its tangent plane lifted onto the sphere: what fit_shape sees of a smooth
// neighbourhood.
void sphere_ring(Vec3f centre, float radius, Vec3f c, float d, std::vector<Vec3f>& points,
                 std::vector<Vec3f>& normals) {
  const Vec3f n = normalized(c - centre);
  const TangentFrame f = tangent_frame(n);
  for (int k = 0; k < 8; ++k) {
    const float a = k * kPi / 4;
    const Vec3f p = centre + normalized(c + (f.u * std::cos(a) + f.v * std::sin(a)) * d - centre) * radius;
    points.push_back(p);
    normals.push_back(normalized(p - centre));
  }
}

float normal_curvature(const Shape& s, float a, float b) {
  return (s.xx * a * a + 2 * s.xy * a * b + s.yy * b * b) / (a * a + b * b);
}

TEST(FitShape, MatchesTheCurvatureOfASphereACylinderAndAPlane) {
  std::vector<Vec3f> p, n;
  const Vec3f c = Vec3f{1, 2, 3} + normalized(Vec3f{0.3f, 0.9f, -0.2f}) * 2.0f;
  sphere_ring({1, 2, 3}, 2.0f, c, 0.05f, p, n);
  const Shape sphere = fit_shape(c, normalized(c - Vec3f{1, 2, 3}), p, n);
  for (float deg : {0.0f, 30.0f, 90.0f, 135.0f}) {
    const float a = std::cos(deg_to_rad(deg)), b = std::sin(deg_to_rad(deg));
    EXPECT_NEAR(normal_curvature(sphere, a, b), 0.5f, 0.01f) << deg;
  }
  // A cylinder of radius 0.5 around the z axis, seen from the point (0.5, 0, 0): curvature 2
  // around it, 0 along it; and inward normals (a hole's wall) flip the sign.
  for (float sign : {1.0f, -1.0f}) {
    std::vector<Vec3f> cp, cn;
    for (int k = 0; k < 8; ++k) {
      const float a = k * kPi / 4, phi = 0.1f * std::cos(a), z = 0.05f * std::sin(a);
      cp.push_back({0.5f * std::cos(phi), 0.5f * std::sin(phi), z});
      cn.push_back(Vec3f{std::cos(phi), std::sin(phi), 0} * sign);
    }
    const Vec3f n0 = Vec3f{1, 0, 0} * sign;
    const Shape cyl = fit_shape({0.5f, 0, 0}, n0, cp, cn);
    const TangentFrame f = tangent_frame(n0);
    const auto along = [&](Vec3f w) { return normal_curvature(cyl, dot(w, f.u), dot(w, f.v)); };
    EXPECT_NEAR(along({0, 1, 0}), 2.0f * sign, 0.05f);
    EXPECT_NEAR(along({0, 0, 1}), 0.0f, 0.05f);
  }
  std::vector<Vec3f> flat, up(8, kY);
  for (int k = 0; k < 8; ++k) flat.push_back({std::cos(k * 0.7f), 0, std::sin(k * 0.7f)});
  const Shape plane = fit_shape({0, 0, 0}, kY, flat, up);
  EXPECT_EQ(plane.xx, 0.0f);
  EXPECT_EQ(plane.xy, 0.0f);
  EXPECT_EQ(plane.yy, 0.0f);
}

// The crease of a union of two spheres of radius 1 (centres x = ±0.6, T5): a splat of the left
// sphere just before the crease circle x = 0, its partner on the right sphere just after it.
// The face to keep is the disc's part outside the right sphere.
struct SphereUnion {
  Vec3f a{-0.6f, 0, 0}, b{0.6f, 0, 0};
  Disc s, p;
  SphereUnion(float offset) {
    const auto on = [](Vec3f centre, Vec3f dir) {
      return Disc{centre + normalized(dir), normalized(dir), kR};
    };
    s = on(a, {0.6f - offset, 0.8f, 0});
    p = on(b, {-0.6f + offset, 0.8f, 0});
    std::vector<Vec3f> pts, nrm;
    sphere_ring(b, 1.0f, p.c, 0.05f, pts, nrm);
    p.shape = fit_shape(p.c, p.n, pts, nrm);
  }
  float depth_in_b(Vec3f x) const { return 1.0f - length(x - b); }  // > 0 inside
};

TEST(ClassifyPartners, CurvedConcavePartnerLeavesNoGapAtTheCrease) {
  for (float offset : {0.03f, 0.06f}) {
    const SphereUnion u(offset);
    const std::vector<Vec3f> around = ring(u.s, [&](Vec3f x) { return u.depth_in_b(x) < 0; });
    Disc flat = u.p;
    flat.shape = {};
    const ClipResult tangent = classify_partners(u.s, {&flat, 1}, around, ClipRule::Classified);
    const ClipResult curved = classify_partners(u.s, {&u.p, 1}, around, ClipRule::Classified);
    ASSERT_EQ(curved.planes.size(), 1u);
    // Sample the disc: a point outside the right sphere that is discarded is a gap.
    const TangentFrame f = tangent_frame(u.s.n);
    int gaps_tangent = 0, gaps_curved = 0;
    float deepest_kept = 0;
    for (int i = -100; i <= 100; ++i) {
      for (int j = -100; j <= 100; ++j) {
        const float du = i * kR / 100, dv = j * kR / 100;
        if (du * du + dv * dv > kR * kR) continue;
        const Vec3f x = u.s.c + f.u * du + f.v * dv;
        const float inside = u.depth_in_b(x);
        if (inside < -1e-5f) {
          gaps_tangent += clip_discards(tangent.planes, tangent.mode, x);
          gaps_curved += clip_discards(curved.planes, curved.mode, x);
        } else if (!clip_discards(curved.planes, curved.mode, x)) {
          deepest_kept = std::max(deepest_kept, inside);
        }
      }
    }
    EXPECT_GT(gaps_tangent, 0) << offset;  // the tangent plane alone stops short
    EXPECT_EQ(gaps_curved, 0) << offset;
    // What it keeps past the crease is just under the partner's surface.
    EXPECT_LT(deepest_kept, 0.1f * kR) << offset;
  }
}

TEST(ClassifyPartners, CurvatureDoesNotMoveConvexPartners) {
  // The hole's rim: the wall (normals toward the axis) curves away from its tangent planes
  // too, but the crease is convex; the planes stay the tangent planes.
  Config c = hole_rim();
  const ClipResult before = classify(c, ClipRule::Classified);
  for (Disc& p : c.partners) p.shape = {-2.0f, 0, 0};
  const ClipResult after = classify(c, ClipRule::Classified);
  ASSERT_EQ(before.planes.size(), after.planes.size());
  for (std::size_t k = 0; k < before.planes.size(); ++k) EXPECT_EQ(before.planes[k].h, after.planes[k].h);
}

}  // namespace

namespace {

TEST(ClassifyPartners, NearlyParallelTangentsOfAHoleRimKeepTheFace) {
  // The wall's tangent planes 4° apart (lines within 5°: one crease by the pair rule), as
  // neighbouring partners along a hole's rim are: the face outside the circle must be kept
  // wherever it is (intersection of the cuts); their union took a sliver between the lines.
  Config c = hole_rim();
  c.partners.clear();
  for (float deg : {0.0f, 4.0f}) {
    const float a = deg_to_rad(deg);
    c.partners.push_back({{0.5f * std::cos(a), 0.17f, 0.5f * std::sin(a)},
                          {-std::cos(a), 0, -std::sin(a)}, kR});
  }
  const ClipResult clip = classify(c, ClipRule::Classified);
  ASSERT_EQ(clip.planes.size(), 2u);
  EXPECT_EQ(clip.mode, ClipMode::Intersection);
  // Between the two tangent points (azimuth 0° to 4°) the face outside the circle is kept but
  // for the corner of the two lines (at most R(1/cos 2° − 1) = 0.0003 past the circle); the
  // union of the cuts lost a sliver up to where the other line runs.
  const TangentFrame f = tangent_frame(c.s.n);
  int lost = 0, lost_by_union = 0;
  for (int i = -200; i <= 200; ++i) {
    for (int j = -200; j <= 200; ++j) {
      const Vec3f p = c.s.c + f.u * (i * kR / 200) + f.v * (j * kR / 200);
      const float azimuth = std::atan2(p.z, p.x);
      if (length(p - c.s.c) > kR || c.boundary(p) < 4e-4f || azimuth < 0 ||
          azimuth > deg_to_rad(4.0f)) {
        continue;
      }
      lost += clip_discards(clip.planes, clip.mode, p);
      lost_by_union += clip_discards(clip.planes, ClipMode::Union, p);
    }
  }
  EXPECT_EQ(lost, 0);
  EXPECT_GT(lost_by_union, 10);
  // A cylinder cap's rim (convex: the face inside the circle) with the same two lines keeps
  // the union of the cuts.
  Config cap = c;
  for (Disc& p : cap.partners) p.n = p.n * -1.0f;
  cap.s.c = {0.45f, 0.2f, 0};
  cap.kept = [](Vec3f p) { return p.x * p.x + p.z * p.z <= 0.25f; };
  EXPECT_EQ(classify(cap, ClipRule::Classified).mode, ClipMode::Union);
}

}  // namespace

TEST(FitResidual, ZeroOnACurvedSurfaceAndTheNoiseOnANoisyPlane) {
  // Exact samples of a sphere lie on the fitted second-order surface; samples of a plane moved
  // along its normal by a known amount σ lie √2·σ from the surface of a splat moved as much
  // (its own offset and each neighbour's, independent).
  std::vector<Vec3f> pts, nrm;
  const Vec3f centre{0, 0, 0}, at = normalized(Vec3f{0.3f, 0.8f, 0.2f});
  sphere_ring(centre, 1.0f, at, 0.05f, pts, nrm);
  const Shape shape = fit_shape(at, at, pts, nrm);
  EXPECT_LT(fit_residual(at, at, shape, pts), 1e-3f * 0.05f);
  // The noisy plane: ±σ offsets in a fixed pattern whose mean square is σ² (a square wave),
  // the splat itself at +σ: the distances are 0 and 2σ alternately, so √2·σ.
  constexpr float sigma = 0.004f;
  std::vector<Vec3f> noisy;
  for (int k = 0; k < 16; ++k) {
    const float a = k * kPi / 8;
    noisy.push_back({0.05f * std::cos(a), (k % 2 ? sigma : -sigma), 0.05f * std::sin(a)});
  }
  EXPECT_NEAR(fit_residual({0, sigma, 0}, kY, Shape{}, noisy), std::sqrt(2.0f) * sigma, 1e-5f);
  EXPECT_EQ(fit_residual({0, 0, 0}, kY, Shape{}, {}), 0.0f);
}

TEST(ClassifyPartners, NoiseMovesTheLineOutByItsMeasure) {
  // A cube edge (faces y = 1 and x = 1): the splat on the top face keeps x <= 1. With noise
  // measured at both discs, the line moves √(a² + b²) further out (a right angle: along
  // the partner's normal is along the splat's plane); without, it stays on the edge.
  const Disc s{{0.95f, 1, 0}, kY, kR}, p{{1, 0.95f, 0}, kX, kR};
  const std::vector<Vec3f> around = ring(s, [](Vec3f x) { return x.x < 1; });
  const auto edge = [&](float own, float partner) {
    Disc a = s, b = p;
    a.noise = own;
    b.noise = partner;
    const ClipResult clip = classify_partners(a, {&b, 1}, around, ClipRule::Classified);
    // Where along +x the clip starts: bisect on the line through the centre.
    float lo = 0.95f, hi = 0.95f + kR;
    for (int k = 0; k < 40; ++k) {
      const float mid = 0.5f * (lo + hi);
      (clip_discards(clip.planes, clip.mode, {mid, 1, 0}) ? hi : lo) = mid;
    }
    return lo;
  };
  EXPECT_NEAR(edge(0, 0), 1.0f, 1e-5f);
  EXPECT_NEAR(edge(0.003f, 0.004f), 1.0f + 0.005f, 1e-5f);
  // At most half a radius, however noisy.
  EXPECT_NEAR(edge(0.1f, 0.1f), 1.0f + 0.5f * kR, 1e-5f);
}

// A splat of the top face y = 1 near the edge x = 1, its partner the side face x = 1, and the
// side's discs (radius 0.1) in a row along the edge whose rims stop `gap` below it.
struct EdgeWithSideRow {
  Disc s{{0.95f, 1, 0}, kY, kR};
  Disc partner;
  std::vector<Disc> side;
  explicit EdgeWithSideRow(float gap) {
    for (int k = -4; k <= 4; ++k) side.push_back({{1, 1 - gap - kR, 0.05f * k}, kX, kR});
    partner = side[4];
  }
  ClipResult clip(float w_s = 0.9f) const {
    std::vector<Disc> around_side = side;
    ClipResult c = classify_partners(s, {&partner, 1}, ring(s, [](Vec3f x) { return x.x < 1; }),
                                     ClipRule::Classified);
    keep_uncovered(s, c, around_side, w_s);
    return c;
  }
  // Where along +x through the centre the clip starts.
  float line() const {
    const ClipResult c = clip();
    float lo = 0.95f, hi = 0.95f + kR;
    for (int k = 0; k < 40; ++k) {
      const float mid = 0.5f * (lo + hi);
      (clip_discards(c.planes, c.mode, {mid, 1, 0}) ? hi : lo) = mid;
    }
    return lo;
  }
};

TEST(KeepUncovered, TheLineMovesOutByTheOtherFacesGap) {
  // The side's discs reach the edge: the line stays on it. They stop 0.013 below it: the line
  // moves out by that gap rounded up to the steps of 0.5 r / 8 (0.00625): 0.0125... 0.01875.
  const float step = 0.5f * kR / 8;
  EXPECT_NEAR(EdgeWithSideRow(-0.01f).line(), 1.0f, 1e-5f);
  const float moved = EdgeWithSideRow(0.013f).line() - 1.0f;
  EXPECT_GE(moved, 0.013f - 1e-5f);
  EXPECT_LE(moved, 0.013f + step + 1e-5f);
  // The row's discs tilted 30° (normals outside the threshold) are not the side's surface,
  // which is then the partner alone: a small disc whose rim reaches the edge only near its
  // centre, 0.03 below the edge. The line moves out by a step there.
  EdgeWithSideRow tilted(0.013f);
  for (Disc& d : tilted.side) d.n = normalized(Vec3f{1, 0.577f, 0});
  tilted.partner = {{1, 0.97f, 0}, kX, 0.05f};
  tilted.side.push_back(tilted.partner);
  EXPECT_NEAR(tilted.line(), 1.0f + step, 1e-5f);
}

TEST(KeepUncovered, PastACornerTheOtherFaceHasEnded) {
  // The cube's corner (1, 1, 1): a top-face splat whose chord on the edge x = 1 runs past
  // z = 1. The side faces' discs reach their edges with the top face but end at their own
  // shared edge: the part of the x = 1 line past z = 1 is past the corner, not a gap, and the
  // lines stay.
  const Disc s{{0.97f, 1, 0.97f}, kY, kR};
  std::vector<Disc> others;
  for (int k = -4; k <= -1; ++k) {
    others.push_back({{1, 0.97f, 1 + 0.04f * k}, kX, 0.05f});
    others.push_back({{1 + 0.04f * k, 0.97f, 1}, kZ, 0.05f});
  }
  const Disc partners[2] = {others[6], others[7]};  // the discs nearest the corner
  ClipResult c = classify_partners(s, partners,
                                   ring(s, [](Vec3f x) { return x.x < 1 && x.z < 1; }),
                                   ClipRule::Classified);
  ASSERT_EQ(c.mode, ClipMode::Union);
  ASSERT_EQ(c.planes.size(), 2u);
  EXPECT_EQ(keep_uncovered(s, c, others, 0.9f), 0);
}
