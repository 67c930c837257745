// Point-set simplification: counts, each method against an oracle of its definition (the voxel
// cells by a map of cells, the random subset by membership), even spread on a plane (no
// method leaves a region empty), exact analytic distances where methods differ, colours
// averaged, determinism for any thread count, and clear errors.
#include "pointillist/prep/simplify.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <set>
#include <tuple>

#include "pointillist/core/error.hpp"
#include "pointillist/scene/analytic.hpp"

using namespace pointillist;

namespace {

constexpr SimplifyMethod kAll[] = {SimplifyMethod::Random,       SimplifyMethod::VoxelCentroid,
                                   SimplifyMethod::VoxelNearest, SimplifyMethod::Hierarchical,
                                   SimplifyMethod::Incremental,  SimplifyMethod::Quadric};

// Random samples of the unit square in z = 0, normals +z, a colour from the position.
PointSet plane(std::size_t n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  PointSet p;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3f at{u(rng), u(rng), 0.0f};
    p.positions.push_back(at);
    p.normals.push_back({0, 0, 1});
    p.colors.push_back({static_cast<std::uint8_t>(at.x * 255), 100, 7});
  }
  return p;
}

PointSet analytic_points(const AnalyticScene& scene, std::size_t n) {
  SurfaceSamples s = sample_scene(scene, n, 3);
  s.points.normals = s.true_normals;
  return s.points;
}

PointSet run(const PointSet& in, SimplifyMethod method, std::size_t target, unsigned threads = 2,
             float voxel = 0) {
  ThreadPool pool(threads);
  SimplifyOptions o;
  o.method = method;
  o.target = target;
  o.voxel_size = voxel;
  return simplify_points(in, o, pool);
}

// Exact distance from p to the default torus (major 1, minor 0.35, axis y, at the origin).
double torus_distance(Vec3f p) {
  const double q = std::hypot(double(p.x), double(p.z)) - 1.0;
  return std::abs(std::hypot(q, double(p.y)) - 0.35);
}
// Exact distance from p to the surface of the cube of half side 1 at the origin.
double cube_distance(Vec3f p) {
  const double q[3] = {std::abs(p.x) - 1.0, std::abs(p.y) - 1.0, std::abs(p.z) - 1.0};
  const double outside = std::hypot(std::max(q[0], 0.0), std::max(q[1], 0.0), std::max(q[2], 0.0));
  const double inside = std::min(std::max({q[0], q[1], q[2]}), 0.0);
  return std::abs(outside + inside);
}

}  // namespace

TEST(Simplify, EveryMethodReachesTheTarget) {
  const PointSet in = analytic_points(torus_scene(), 40000);
  for (SimplifyMethod m : kAll) {
    const PointSet out = run(in, m, 2000);
    SCOPED_TRACE(std::string(simplify_method_name(m)));
    if (m == SimplifyMethod::VoxelCentroid || m == SimplifyMethod::VoxelNearest) {
      EXPECT_NEAR(double(out.size()), 2000.0, 10.0);  // within 0.5 %
    } else {
      EXPECT_EQ(out.size(), 2000u);
    }
    ASSERT_EQ(out.normals.size(), out.size());
    ASSERT_EQ(out.radii.size(), out.size());
    for (const Vec3f& n : out.normals) ASSERT_NEAR(length(n), 1.0f, 1e-4f);
  }
}

TEST(Simplify, VoxelCentroidsAreTheCellMeansOfAMapOfCells) {
  const PointSet in = plane(5000, 1);
  const float size = 0.1f;
  const PointSet out = run(in, SimplifyMethod::VoxelCentroid, 1, 2, size);
  // Oracle: cells keyed by integer coordinates from the box's low corner.
  Vec3f lo{INFINITY, INFINITY, INFINITY};
  for (const Vec3f& p : in.positions) lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
  std::map<std::tuple<int, int, int>, std::pair<std::array<double, 3>, int>> cells;
  for (const Vec3f& p : in.positions) {
    auto& c = cells[{int(std::floor((p.x - lo.x) / size)), int(std::floor((p.y - lo.y) / size)),
                     int(std::floor((p.z - lo.z) / size))}];
    c.first[0] += p.x, c.first[1] += p.y, c.first[2] += p.z;
    ++c.second;
  }
  ASSERT_EQ(out.size(), cells.size());
  std::multiset<std::tuple<long, long>> want, got;
  for (const auto& [key, c] : cells) {
    want.insert({std::lround(c.first[0] / c.second * 1e4), std::lround(c.first[1] / c.second * 1e4)});
  }
  for (const Vec3f& p : out.positions) got.insert({std::lround(p.x * 1e4), std::lround(p.y * 1e4)});
  EXPECT_EQ(got, want);
}

TEST(Simplify, VoxelNearestKeepsInputPointsOnePerCell) {
  const PointSet in = plane(5000, 2);
  const PointSet out = run(in, SimplifyMethod::VoxelNearest, 1, 2, 0.1f);
  EXPECT_EQ(out.size(), 100u);  // a 10 × 10 grid over the square, every cell occupied
  std::set<std::pair<float, float>> input;
  for (const Vec3f& p : in.positions) input.insert({p.x, p.y});
  std::set<std::pair<int, int>> cells;
  for (const Vec3f& p : out.positions) {
    EXPECT_TRUE(input.count({p.x, p.y})) << p.x << ", " << p.y;
    cells.insert({int(p.x / 0.1f), int(p.y / 0.1f)});
  }
  EXPECT_GE(cells.size(), 95u);  // one per cell (a point on a cell's edge may round either way)
}

TEST(Simplify, RandomKeepsADistinctSubsetOfTheInput) {
  const PointSet in = plane(3000, 3);
  const PointSet out = run(in, SimplifyMethod::Random, 700);
  ASSERT_EQ(out.size(), 700u);
  std::set<std::pair<float, float>> input, seen;
  for (const Vec3f& p : in.positions) input.insert({p.x, p.y});
  for (const Vec3f& p : out.positions) {
    EXPECT_TRUE(input.count({p.x, p.y}));
    EXPECT_TRUE(seen.insert({p.x, p.y}).second) << "a point kept twice";
  }
}

TEST(Simplify, NoMethodLeavesAPartOfAPlaneEmpty) {
  // 1000 of 40000 points on the unit square: spacing about 0.032. Every input point must have an
  // output point within 2.5 spacings (brute force), or that method left a hole.
  const PointSet in = plane(40000, 4);
  for (SimplifyMethod m : kAll) {
    if (m == SimplifyMethod::Random) continue;  // random gaps are its nature
    SCOPED_TRACE(std::string(simplify_method_name(m)));
    const PointSet out = run(in, m, 1000);
    float worst = 0;
    for (std::size_t i = 0; i < in.size(); i += 7) {
      float best = INFINITY;
      for (const Vec3f& q : out.positions) best = std::min(best, length_squared(q - in.positions[i]));
      worst = std::max(worst, std::sqrt(best));
    }
    EXPECT_LT(worst, 2.5f * std::sqrt(1.0f / 1000.0f));
  }
}

TEST(Simplify, QuadricsKeepTheCubesEdgesWhereCentroidsCutThem) {
  // Centroids of cells across an edge sit inside the cube; contracted pairs stay on its faces.
  const PointSet in = analytic_points(cube_scene(1.0f), 60000);
  const PointSet voxel = run(in, SimplifyMethod::VoxelCentroid, 3000);
  const PointSet quadric = run(in, SimplifyMethod::Quadric, 3000);
  const auto rms = [](const PointSet& p) {
    double sum = 0;
    for (const Vec3f& q : p.positions) sum += cube_distance(q) * cube_distance(q);
    return std::sqrt(sum / double(p.size()));
  };
  EXPECT_LT(rms(quadric), 0.5 * rms(voxel));
}

TEST(Simplify, CentroidsOfACurvedSurfaceLieInsideItAndQuadricsCloser) {
  const PointSet in = analytic_points(torus_scene(), 100000);
  const auto rms = [](const PointSet& p) {
    double sum = 0;
    for (const Vec3f& q : p.positions) sum += torus_distance(q) * torus_distance(q);
    return std::sqrt(sum / double(p.size()));
  };
  const double voxel = rms(run(in, SimplifyMethod::VoxelCentroid, 5000));
  const double quadric = rms(run(in, SimplifyMethod::Quadric, 5000));
  const double nearest = rms(run(in, SimplifyMethod::VoxelNearest, 5000));
  EXPECT_GT(voxel, 1e-5);        // the chord's sag: centroids are off the surface
  EXPECT_LT(nearest, 1e-6);      // input points are on it
  EXPECT_LT(quadric, voxel);
}

TEST(Simplify, ColoursAreTheMembersMean) {
  PointSet in;
  for (int i = 0; i < 4; ++i) {
    in.positions.push_back({0.01f * i, 0, 0});
    in.normals.push_back({0, 0, 1});
    in.colors.push_back({static_cast<std::uint8_t>(i * 10), 200, 0});  // mean 15
  }
  const PointSet out = run(in, SimplifyMethod::VoxelCentroid, 1, 1, 1.0f);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out.colors[0].r, 15);
  EXPECT_EQ(out.colors[0].g, 200);
  const PointSet q = run(in, SimplifyMethod::Quadric, 1);
  ASSERT_EQ(q.size(), 1u);
  EXPECT_EQ(q.colors[0].r, 15);
}

TEST(Simplify, DoesNotDependOnTheThreadCount) {
  const PointSet in = analytic_points(torus_scene(), 20000);
  for (SimplifyMethod m : kAll) {
    SCOPED_TRACE(std::string(simplify_method_name(m)));
    const PointSet a = run(in, m, 1500, 1), b = run(in, m, 1500, 2);
    ASSERT_EQ(a.positions.size(), b.positions.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
      ASSERT_EQ(a.positions[i], b.positions[i]) << i;
      ASSERT_EQ(a.normals[i], b.normals[i]) << i;
    }
  }
}

TEST(Simplify, RefusesInputItCannotUse) {
  ThreadPool pool(1);
  PointSet no_normals;
  no_normals.positions = {{0, 0, 0}, {1, 0, 0}};
  SimplifyOptions o;
  o.target = 1;
  EXPECT_THROW(simplify_points(no_normals, o, pool), Error);
  PointSet bad = plane(10, 5);
  bad.positions[3].y = NAN;
  EXPECT_THROW(simplify_points(bad, o, pool), Error);
  o.target = 0;
  EXPECT_THROW(simplify_points(plane(10, 5), o, pool), OptionError);
  EXPECT_THROW(parse_simplify_method("octree"), OptionError);
  // More points asked for than there are: the input comes back whole, with its radii.
  o.target = 50;
  PointSet with_radii = plane(10, 5);
  with_radii.radii.assign(10, 0.125f);
  const PointSet whole = simplify_points(with_radii, o, pool);
  EXPECT_EQ(whole.size(), 10u);
  EXPECT_EQ(whole.radii, with_radii.radii);
}
