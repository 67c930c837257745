// Surface error (eval/surface_error.hpp) against brute-force oracles and configurations with known
// answers: discs off the unit sphere, disc carpets on a meshed plane patch with and without a hole,
// tilted normals.
#include "pointillist/eval/surface_error.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include "pointillist/core/error.hpp"

using namespace pointillist;

namespace {

constexpr double kPiD = 3.14159265358979323846;

struct Mesh {
  std::vector<Vec3f> positions;
  std::vector<std::array<std::uint32_t, 3>> triangles;
};

// An octahedron, each triangle split into four `levels` times, vertices pushed onto the unit
// sphere and jittered (so no two triangles are alike).
Mesh subdivided_octahedron(int levels, std::uint64_t seed) {
  Mesh m;
  m.positions = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  m.triangles = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                 {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  for (int level = 0; level < levels; ++level) {
    std::vector<std::array<std::uint32_t, 3>> next;
    for (const auto& [a, b, c] : m.triangles) {
      const auto mid = [&](std::uint32_t i, std::uint32_t j) {
        m.positions.push_back((m.positions[i] + m.positions[j]) * 0.5f);
        return std::uint32_t(m.positions.size() - 1);  // edges' midpoints duplicated: harmless
      };
      const std::uint32_t ab = mid(a, b), bc = mid(b, c), ca = mid(c, a);
      next.insert(next.end(), {{a, ab, ca}, {ab, b, bc}, {ca, bc, c}, {ab, bc, ca}});
    }
    m.triangles = std::move(next);
  }
  std::mt19937 rng{std::uint32_t(seed)};
  std::uniform_real_distribution<float> jitter(0.97f, 1.03f);
  for (Vec3f& p : m.positions) p = normalized(p) * jitter(rng);
  return m;
}

// The unit square [0, 1]² at z = 0 as cells × cells quads of two triangles.
Mesh plane_patch(int cells) {
  Mesh m;
  for (int j = 0; j <= cells; ++j) {
    for (int i = 0; i <= cells; ++i) m.positions.push_back({float(i) / cells, float(j) / cells, 0});
  }
  const auto at = [&](int i, int j) { return std::uint32_t(j * (cells + 1) + i); };
  for (int j = 0; j < cells; ++j) {
    for (int i = 0; i < cells; ++i) {
      m.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      m.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  }
  return m;
}

struct Splats {
  std::vector<Vec3f> centers, normals;
  std::vector<float> radii;
  void add(Vec3f c, Vec3f n, float r) {
    centers.push_back(c);
    normals.push_back(n);
    radii.push_back(r);
  }
};

// Discs of radius 0.008 at z = 0 on the 0.01 grid over [0, 1]² (101 × 101): every point of the
// square is within 0.01·√2/2 ≈ 0.00707 of a centre, so the carpet has no holes. Centres with
// grid indices i in [hole_lo, hole_hi] and j in [hole_lo + 30, hole_hi + 30] are left out.
Splats disc_carpet(int hole_lo = 1, int hole_hi = 0) {
  Splats s;
  for (int j = 0; j <= 100; ++j) {
    for (int i = 0; i <= 100; ++i) {
      if (i >= hole_lo && i <= hole_hi && j >= hole_lo + 30 && j <= hole_hi + 30) continue;
      s.add({i * 0.01f, j * 0.01f, 0}, {0, 0, 1}, 0.008f);
    }
  }
  return s;
}

struct Vec3d {
  double x, y, z;
};
Vec3d d3(Vec3f v) { return {v.x, v.y, v.z}; }
Vec3d operator-(Vec3d a, Vec3d b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
Vec3d operator+(Vec3d a, Vec3d b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
Vec3d operator*(Vec3d a, double s) { return {a.x * s, a.y * s, a.z * s}; }
double dot(Vec3d a, Vec3d b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
Vec3d cross(Vec3d a, Vec3d b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
double norm(Vec3d a) { return std::sqrt(dot(a, a)); }

double segment_distance(Vec3d p, Vec3d a, Vec3d b) {
  const Vec3d ab = b - a;
  const double t = std::clamp(dot(p - a, ab) / dot(ab, ab), 0.0, 1.0);
  return norm(p - (a + ab * t));
}

// Distance to a triangle by projection onto its plane: the plane distance when the foot falls
// inside (all three edge tests agree), else the nearest edge.
double triangle_distance(Vec3d p, Vec3d a, Vec3d b, Vec3d c) {
  const Vec3d n = cross(b - a, c - a);
  const Vec3d foot = p - n * (dot(p - a, n) / dot(n, n));
  const bool inside = dot(cross(b - a, foot - a), n) >= 0 && dot(cross(c - b, foot - b), n) >= 0 &&
                      dot(cross(a - c, foot - c), n) >= 0;
  if (inside) return std::abs(dot(p - a, n)) / norm(n);
  return std::min(
      {segment_distance(p, a, b), segment_distance(p, b, c), segment_distance(p, c, a)});
}

// Distance from s to the disc (c, n unit, r) as the spec defines it, and whether it covers s.
double disc_distance(Vec3d s, Vec3d c, Vec3d n, double r, double tolerance, bool* covers) {
  const double h = dot(s - c, n);
  const double t = norm((s - c) - n * h);
  if (t <= r && std::abs(h) <= tolerance) *covers = true;
  return t <= r ? std::abs(h) : std::sqrt(h * h + (t - r) * (t - r));
}

Vec3f random_unit(std::mt19937& rng) {
  std::normal_distribution<float> g;
  return normalized(Vec3f{g(rng), g(rng), g(rng)});
}

}  // namespace

TEST(SurfaceErrorReference, MeshClosestMatchesBruteForceOverAllTriangles) {
  const Mesh m = subdivided_octahedron(4, 3);  // 2048 triangles
  ASSERT_EQ(m.triangles.size(), 2048u);
  ThreadPool pool(2);
  const SurfaceReference ref = SurfaceReference::mesh(m.positions, m.triangles, pool);
  std::mt19937 rng(21);
  std::uniform_real_distribution<float> uni(-1.6f, 1.6f), near(0.9f, 1.1f);
  for (int q = 0; q < 1500; ++q) {
    // A third far off, the rest near the surface (inside and outside), where pruning matters.
    const Vec3f p = q % 3 == 0 ? Vec3f{uni(rng), uni(rng), uni(rng)} * 2.0f
                               : random_unit(rng) * near(rng);
    double brute = 1e30;
    for (const auto& [a, b, c] : m.triangles) {
      brute = std::min(brute, triangle_distance(d3(p), d3(m.positions[a]), d3(m.positions[b]),
                                                d3(m.positions[c])));
    }
    const SurfaceReference::Closest c = ref.closest(p);
    EXPECT_NEAR(c.distance, brute, 1e-6 * brute + 1e-12) << "query " << q;
    EXPECT_NEAR(distance(c.point, p), c.distance, 1e-6f * c.distance + 5e-7f);
    EXPECT_NEAR(length(c.normal), 1.0f, 1e-5f);
  }
}

TEST(SurfaceErrorReference, MeshClosestOfOneTriangleInEveryRegion) {
  // One obtuse triangle: queries all around it fall in each vertex, edge and face region.
  const Mesh m{{{0.1f, 0.2f, 0.3f}, {1.3f, 0.1f, 0.2f}, {0.2f, 0.5f, 0.4f}}, {{0, 1, 2}}};
  ThreadPool pool(1);
  const SurfaceReference ref = SurfaceReference::mesh(m.positions, m.triangles, pool);
  std::mt19937 rng(22);
  std::uniform_real_distribution<float> uni(-1.0f, 2.0f);
  for (int q = 0; q < 3000; ++q) {
    const Vec3f p{uni(rng), uni(rng) * 0.5f, uni(rng) * 0.5f};
    const double expected =
        triangle_distance(d3(p), d3(m.positions[0]), d3(m.positions[1]), d3(m.positions[2]));
    EXPECT_NEAR(ref.closest(p).distance, expected, 1e-6 * expected + 1e-12) << "query " << q;
  }
}

TEST(SurfaceErrorReference, MeshSamplesLieOnTheTrianglesUniformlyByArea) {
  // Two triangles in z = 0 of areas 0.5 (x < 0) and 1.5 (x > 0): a quarter of the samples lie
  // on the first.
  const Mesh m{{{-1, 0, 0}, {0, 0, 0}, {0, 1, 0}, {3, 0, 0}}, {{0, 1, 2}, {1, 3, 2}}};
  ThreadPool pool(1);
  const SurfaceReference ref = SurfaceReference::mesh(m.positions, m.triangles, pool);
  const std::vector<Vec3f> s = ref.samples(40000, 5);
  ASSERT_EQ(s.size(), 40000u);
  int left = 0;
  for (const Vec3f p : s) {
    EXPECT_EQ(p.z, 0.0f);
    EXPECT_GE(p.y, 0.0f);
    left += p.x < 0 ? 1 : 0;
    EXPECT_LE(p.y, p.x < 0 ? p.x + 1 + 1e-6f : 1 - p.x / 3 + 1e-6f);  // below the hypotenuse
  }
  EXPECT_NEAR(left / 40000.0, 0.25, 4 * std::sqrt(0.25 * 0.75 / 40000));  // 4 sigma
  // Uniform within a triangle: the right one's share of x < 1 is 1 − (2/3)² = 5/9.
  int right_near = 0, right = 0;
  for (const Vec3f p : s) {
    right += p.x >= 0 ? 1 : 0;
    right_near += p.x >= 0 && p.x < 1 ? 1 : 0;
  }
  EXPECT_NEAR(double(right_near) / right, 5.0 / 9.0, 4 * std::sqrt((5.0 / 9) * (4.0 / 9) / right));
  EXPECT_EQ(ref.samples(100, 5), ref.samples(100, 5));
  EXPECT_NE(ref.samples(100, 5), ref.samples(100, 6));
  EXPECT_NEAR(ref.diagonal(), std::sqrt(16.0 + 1.0), 1e-6);
}

TEST(SurfaceErrorReference, PointsMeasureToTheirLocalPlane) {
  std::vector<Vec3f> grid;
  for (int j = 0; j < 30; ++j) {
    for (int i = 0; i < 30; ++i) grid.push_back({i * 0.1f, j * 0.1f, 0.3f});
  }
  ThreadPool pool(2);
  const SurfaceReference ref = SurfaceReference::points(grid, pool);
  std::mt19937 rng(2);
  std::uniform_real_distribution<float> uni(0.0f, 2.9f);
  for (int q = 0; q < 200; ++q) {
    const Vec3f p{uni(rng), uni(rng), q % 2 ? 0.7f : -0.2f};
    const SurfaceReference::Closest c = ref.closest(p);
    EXPECT_NEAR(c.distance, q % 2 ? 0.4f : 0.5f, 1e-5f);
    EXPECT_NEAR(std::abs(c.normal.z), 1.0f, 1e-5f);
    EXPECT_NEAR(distance(c.point, Vec3f{p.x, p.y, 0.3f}), 0.0f, 1e-5f);
  }
  EXPECT_NEAR(ref.diagonal(), std::sqrt(2 * 2.9 * 2.9), 1e-5);
}

TEST(SurfaceErrorReference, PointsUseThePlaneOfTheNearestPoint) {
  // Two planes, z = 0 on x < 1 and z = 0.2 on x > 2 (20 × 20 points each): a query above x = 2.2
  // takes the upper plane, one above x = 0.8 the lower one, though both planes extend there.
  std::vector<Vec3f> pts;
  for (int j = 0; j < 20; ++j) {
    for (int i = 0; i < 20; ++i) {
      pts.push_back({i * 0.05f, j * 0.05f, 0.0f});
      pts.push_back({2.0f + i * 0.05f, j * 0.05f, 0.2f});
    }
  }
  ThreadPool pool(1);
  const SurfaceReference ref = SurfaceReference::points(pts, pool, 8);
  EXPECT_NEAR(ref.closest({2.2f, 0.5f, 1.0f}).distance, 0.8f, 1e-5f);
  EXPECT_NEAR(ref.closest({0.8f, 0.5f, 1.0f}).distance, 1.0f, 1e-5f);
  EXPECT_NEAR(ref.closest({1.4f, 0.5f, -0.5f}).distance, 0.5f, 1e-5f);  // nearer (0.95, y, 0)
}

TEST(SurfaceErrorReference, PointSamplesAreEveryCeilNOverCountTh) {
  std::vector<Vec3f> pts;
  for (int i = 0; i < 900; ++i) pts.push_back({float(i % 30), float(i / 30), float(i % 7) * 0.01f});
  ThreadPool pool(1);
  const SurfaceReference ref = SurfaceReference::points(pts, pool);
  EXPECT_EQ(ref.samples(2000, 1), pts);
  EXPECT_EQ(ref.samples(900, 1), pts);
  const std::vector<Vec3f> every9 = ref.samples(100, 1);  // ceil(900 / 100) = 9
  ASSERT_EQ(every9.size(), 100u);
  for (std::size_t i = 0; i < every9.size(); ++i) EXPECT_EQ(every9[i], pts[9 * i]);
  const std::vector<Vec3f> every4 = ref.samples(299, 1);  // ceil(900 / 299) = 4
  ASSERT_EQ(every4.size(), 225u);
  EXPECT_EQ(every4[1], pts[4]);
}

TEST(SurfaceErrorReference, AnalyticUsesTheSceneAndItsSamples) {
  const SurfaceReference ref = SurfaceReference::analytic(sphere_scene(1.0f));
  EXPECT_NEAR(ref.diagonal(), std::sqrt(12.0), 1e-6);
  EXPECT_EQ(ref.samples(50, 4), sample_scene(sphere_scene(1.0f), 50, 4).points.positions);
  EXPECT_NEAR(ref.closest({0, 3, 0}).distance, 2.0f, 1e-6f);
}

TEST(SurfaceErrorReference, RejectsReferencesThatCannotBeMeasured) {
  ThreadPool pool(1);
  const std::vector<Vec3f> pos{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  const std::vector<std::array<std::uint32_t, 3>> bad{{0, 1, 2}, {0, 1, 3}};
  try {
    (void)SurfaceReference::mesh(pos, bad, pool);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("triangle 1 of 2 refers to vertex 3 of 3"),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW((void)SurfaceReference::mesh(pos, {}, pool), Error);
  EXPECT_THROW((void)SurfaceReference::points(pos, pool, 2), OptionError);
  EXPECT_THROW((void)SurfaceReference::points(std::span(pos).first(2), pool), Error);
  EXPECT_THROW((void)SurfaceReference::analytic(AnalyticScene{}), Error);
}

TEST(SurfaceError, DiscsOffTheUnitSphereAreOnePercentAway) {
  const auto dirs = sample_scene(sphere_scene(1.0f), 5000, 8);
  Splats s;
  for (const Vec3f n : dirs.true_normals) s.add(n * 1.01f, n, 0.05f);
  ThreadPool pool(2);
  const SurfaceError e = surface_error(SurfaceReference::analytic(sphere_scene(1.0f)), s.centers,
                                       s.normals, s.radii, pool, {.backward_samples = 20000});
  EXPECT_NEAR(e.forward.mean, 0.01, 1e-5);
  EXPECT_NEAR(e.forward.max, 0.01, 1e-5);
  EXPECT_NEAR(e.forward.rms, 0.01, 1e-5);
  EXPECT_NEAR(e.normal_mean_deg, 0.0, 1e-3);
  EXPECT_NEAR(e.normal_p95_deg, 0.0, 1e-3);
  EXPECT_EQ(e.splats, 5000u);
  EXPECT_EQ(e.samples, 20000u);
  EXPECT_NEAR(e.diagonal, std::sqrt(12.0), 1e-6);
  // A sample u is at least 0.01 from every disc's plane: (u − 1.01 v)·v = u·v − 1.01 ≤ −0.01.
  EXPECT_GE(e.backward.mean, 0.01 - 1e-6);
  EXPECT_DOUBLE_EQ(e.hausdorff, std::max(e.forward.max, e.backward.max));
}

TEST(SurfaceError, DenseDiscsOnAPlanePatchCoverItsMesh) {
  const Mesh m = plane_patch(20);
  const Splats s = disc_carpet();
  ThreadPool pool(2);
  const SurfaceError e = surface_error(SurfaceReference::mesh(m.positions, m.triangles, pool),
                                       s.centers, s.normals, s.radii, pool,
                                       {.backward_samples = 200000});
  EXPECT_EQ(e.hole_fraction, 0.0);
  EXPECT_LT(e.backward.max, 1e-6);
  EXPECT_LT(e.forward.max, 1e-6);
  EXPECT_LT(e.hausdorff, 1e-6);
  EXPECT_NEAR(e.normal_p95_deg, 0.0, 1e-6);
}

TEST(SurfaceError, RemovedSquareShowsAsHolesOfItsArea) {
  // Centres 0.30..0.50 × 0.60..0.80 removed. Uncovered: at least the square 0.298..0.502 ×
  // 0.598..0.802 (every kept centre is more than 0.008 away in x or y), at most 0.29625..0.50375
  // squared (kept columns 0.01 apart cover at least √(0.008² − 0.005²) = 0.00625 beyond them).
  const Mesh m = plane_patch(20);
  const Splats s = disc_carpet(30, 50);
  ThreadPool pool(2);
  const std::size_t n = 400000;
  const SurfaceError e = surface_error(SurfaceReference::mesh(m.positions, m.triangles, pool),
                                       s.centers, s.normals, s.radii, pool,
                                       {.backward_samples = n});
  const double lo = 0.204 * 0.204, hi = 0.2075 * 0.2075;
  const double sigma = std::sqrt(hi * (1 - hi) / n);
  EXPECT_GT(e.hole_fraction, lo - 4 * sigma);
  EXPECT_LT(e.hole_fraction, hi + 4 * sigma);
  // The hole's centre (0.4, 0.7) is 0.11 from the nearest kept centres: 0.102 from their rims.
  EXPECT_LE(e.backward.max, 0.102 + 1e-6);
  EXPECT_GT(e.backward.max, 0.099);
  EXPECT_LT(e.forward.max, 1e-6);
}

TEST(SurfaceError, NormalsTiltedByTenDegreesMeasureTenDegrees) {
  const Mesh m = plane_patch(4);
  Splats s = disc_carpet();
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> phi(0, 2 * float(kPiD));
  const float t = float(10 * kPiD / 180);
  for (std::size_t i = 0; i < s.normals.size(); ++i) {
    const float a = phi(rng), sign = i % 2 ? 1.0f : -1.0f;  // the angle is unsigned
    s.normals[i] = Vec3f{std::sin(t) * std::cos(a), std::sin(t) * std::sin(a), std::cos(t)} * sign;
  }
  ThreadPool pool(2);
  const SurfaceError e = surface_error(SurfaceReference::mesh(m.positions, m.triangles, pool),
                                       s.centers, s.normals, s.radii, pool,
                                       {.backward_samples = 1000});
  EXPECT_NEAR(e.normal_mean_deg, 10.0, 1e-4);
  EXPECT_NEAR(e.normal_p95_deg, 10.0, 1e-4);
}

TEST(SurfaceError, NormalPercentileIsTheNearestRank) {
  // 210 splats tilted 0.05°, 0.10°, …, 10.5° in shuffled order: mean 5.275°, and the 95th
  // percentile by nearest rank is the ⌈199.5⌉ = 200th smallest, 10°.
  const Mesh m = plane_patch(1);
  Splats s;
  std::vector<int> steps(210);
  for (int k = 0; k < 210; ++k) steps[k] = k + 1;
  std::shuffle(steps.begin(), steps.end(), std::mt19937(6));
  for (int k = 0; k < 210; ++k) {
    const double t = steps[k] * 0.05 * kPiD / 180;
    s.add({(k % 21) * 0.045f, (k / 21) * 0.09f, 0}, {float(std::sin(t)), 0, float(std::cos(t))},
          0.05f);
  }
  ThreadPool pool(2);
  const SurfaceError e = surface_error(SurfaceReference::mesh(m.positions, m.triangles, pool),
                                       s.centers, s.normals, s.radii, pool,
                                       {.backward_samples = 1000});
  EXPECT_NEAR(e.normal_mean_deg, 5.275, 1e-4);
  EXPECT_NEAR(e.normal_p95_deg, 10.0, 1e-4);
}

TEST(SurfaceError, CoverIsFoundBehindNearerDiscs) {
  // On the patch [0, 0.01]² (diagonal 0.01·√2), specks (radius 1e-6) every 0.001 are every
  // sample's nearest disc (at most 0.001·√2/2 away) but cover almost nothing; four discs 0.05
  // above the patch cover it all when the tolerance reaches 0.05 (5 × diagonal ≈ 0.071), though
  // none is ever the nearest (their own leaf of the hierarchy lies 0.05 away).
  Mesh m = plane_patch(2);
  for (Vec3f& p : m.positions) p = p * 0.01f;
  Splats s;
  for (int j = 0; j <= 10; ++j) {
    for (int i = 0; i <= 10; ++i) s.add({i * 0.001f, j * 0.001f, 0}, {0, 0, 1}, 1e-6f);
  }
  for (const float dx : {-0.001f, 0.001f}) {
    for (const float dy : {-0.001f, 0.001f}) {
      s.add({0.005f + dx, 0.005f + dy, 0.05f}, {0, 0, 1}, 0.02f);
    }
  }
  ThreadPool pool(2);
  const SurfaceReference ref = SurfaceReference::mesh(m.positions, m.triangles, pool);
  const SurfaceError e = surface_error(ref, s.centers, s.normals, s.radii, pool,
                                       {.backward_samples = 20000, .hole_tolerance = 5});
  EXPECT_EQ(e.hole_fraction, 0.0);
  EXPECT_LE(e.backward.max, 0.0005 * std::sqrt(2.0));
  EXPECT_GT(e.backward.max, 0.0006);
  const SurfaceError strict = surface_error(ref, s.centers, s.normals, s.radii, pool,
                                            {.backward_samples = 20000, .hole_tolerance = 3});
  EXPECT_GT(strict.hole_fraction, 0.99);  // 0.05 above the patch is beyond 3 × diagonal ≈ 0.042
}

TEST(SurfaceError, BackwardMatchesBruteForceOverRandomDiscs) {
  // Discs of varied radii and normals scattered near a torus: nearest disc and coverage of every
  // sample against a scan of all discs, forward distances against the torus formula.
  const AnalyticScene scene = torus_scene(1.0f, 0.35f);
  const SurfaceReference ref = SurfaceReference::analytic(scene);
  const auto base = sample_scene(scene, 400, 12);
  std::mt19937 rng(12);
  std::uniform_real_distribution<float> offset(-0.05f, 0.05f), radius(0.02f, 0.25f);
  Splats s;
  for (std::size_t i = 0; i < 400; ++i) {
    const Vec3f c = base.points.positions[i] + Vec3f{offset(rng), offset(rng), offset(rng)};
    const Vec3f n = i % 4 == 0 ? random_unit(rng)
                               : normalized(base.true_normals[i] + random_unit(rng) * 0.3f);
    s.add(c, n, radius(rng));
  }
  const std::size_t m = 3000;
  ThreadPool pool(2);
  const SurfaceError e = surface_error(ref, s.centers, s.normals, s.radii, pool,
                                       {.backward_samples = m, .seed = 7});
  const std::vector<Vec3f> samples = ref.samples(m, 7);
  const double tolerance = 0.01 * ref.diagonal();
  double sum = 0, sum2 = 0, max = 0;
  std::size_t uncovered = 0;
  for (const Vec3f p : samples) {
    double best = 1e30;
    bool covered = false;
    for (std::size_t i = 0; i < s.centers.size(); ++i) {
      best = std::min(best, disc_distance(d3(p), d3(s.centers[i]), d3(normalized(s.normals[i])),
                                          s.radii[i], tolerance, &covered));
    }
    sum += best;
    sum2 += best * best;
    max = std::max(max, best);
    uncovered += covered ? 0 : 1;
  }
  EXPECT_NEAR(e.backward.mean, sum / m, 1e-5 * sum / m);
  EXPECT_NEAR(e.backward.rms, std::sqrt(sum2 / m), 1e-5 * std::sqrt(sum2 / m));
  EXPECT_NEAR(e.backward.max, max, 1e-5 * max);
  EXPECT_NEAR(e.hole_fraction, double(uncovered) / m, 1.5 / m);  // a borderline sample may flip
  EXPECT_GT(e.hole_fraction, 0.05);  // the scene tests both outcomes
  EXPECT_LT(e.hole_fraction, 0.95);
  double forward_sum = 0, forward_max = 0;
  for (const Vec3f c : s.centers) {
    const double ring = std::hypot(double(c.x), double(c.z)) - 1.0;
    const double d = std::abs(std::hypot(ring, double(c.y)) - 0.35);
    forward_sum += d;
    forward_max = std::max(forward_max, d);
  }
  EXPECT_NEAR(e.forward.mean, forward_sum / 400, 1e-6);
  EXPECT_NEAR(e.forward.max, forward_max, 1e-6);
}

TEST(SurfaceError, SameResultForOneAndTwoThreads) {
  const auto base = sample_scene(demo_scene(), 12000, 3);  // more splats than one block
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> offset(-0.02f, 0.02f), radius(0.005f, 0.05f);
  Splats s;
  for (std::size_t i = 0; i < base.points.size(); ++i) {
    s.add(base.points.positions[i] + Vec3f{offset(rng), offset(rng), offset(rng)},
          normalized(base.true_normals[i] + random_unit(rng) * 0.2f), radius(rng));
  }
  const SurfaceReference ref = SurfaceReference::analytic(demo_scene());
  ThreadPool one(1), two(2);
  const SurfaceErrorOptions options{.backward_samples = 60000};
  const SurfaceError a = surface_error(ref, s.centers, s.normals, s.radii, one, options);
  const SurfaceError b = surface_error(ref, s.centers, s.normals, s.radii, two, options);
  EXPECT_EQ(a.forward.max, b.forward.max);
  EXPECT_EQ(a.forward.mean, b.forward.mean);
  EXPECT_EQ(a.forward.rms, b.forward.rms);
  EXPECT_EQ(a.backward.max, b.backward.max);
  EXPECT_EQ(a.backward.mean, b.backward.mean);
  EXPECT_EQ(a.backward.rms, b.backward.rms);
  EXPECT_EQ(a.hole_fraction, b.hole_fraction);
  EXPECT_EQ(a.normal_mean_deg, b.normal_mean_deg);
  EXPECT_EQ(a.normal_p95_deg, b.normal_p95_deg);
  EXPECT_GT(a.hole_fraction, 0.0);  // not a trivial configuration
  EXPECT_GT(a.normal_mean_deg, 1.0);
}

TEST(SurfaceError, RejectsMismatchedOrEmptySplats) {
  const SurfaceReference ref = SurfaceReference::analytic(sphere_scene(1.0f));
  ThreadPool pool(1);
  const std::vector<Vec3f> c{{1, 0, 0}, {0, 1, 0}}, n{{1, 0, 0}, {0, 1, 0}};
  const std::vector<Vec3f> zero{{1, 0, 0}, {0, 0, 0}};
  const std::vector<float> r{0.1f};
  try {
    (void)surface_error(ref, c, n, r, pool);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("2 centres, 2 normals and 1 radii"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW((void)surface_error(ref, {}, {}, {}, pool), Error);
  const std::vector<float> r2{0.1f, 0.1f};
  EXPECT_THROW((void)surface_error(ref, c, zero, r2, pool), Error);
  EXPECT_THROW((void)surface_error(ref, c, n, r2, pool, {.backward_samples = 0}), OptionError);
}
