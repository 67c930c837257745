// PCA normals and their MST orientation against the exact normals of analytic surfaces.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <map>
#include <numeric>
#include <random>
#include <set>

#include "pointillist/core/error.hpp"
#include "pointillist/prep/normals.hpp"
#include "pointillist/prep/prepare.hpp"
#include "pointillist/scene/analytic.hpp"

using namespace pointillist;

namespace {

double angle_deg(Vec3f a, Vec3f b) {
  const double c =
      std::clamp(double(dot(a, b)) / (double(length(a)) * double(length(b))), -1.0, 1.0);
  return std::acos(c) * 180.0 / 3.14159265358979323846;
}

struct NormalErrors {
  double mean_deg = 0;     // mean of the unoriented angle (the PCA line against the true normal)
  std::size_t inward = 0;  // normals with dot(estimate, true) <= 0
  std::size_t not_unit = 0;
};

NormalErrors compare(const std::vector<Vec3f>& estimated, const std::vector<Vec3f>& truth) {
  NormalErrors e;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const double a = angle_deg(estimated[i], truth[i]);
    e.mean_deg += std::min(a, 180.0 - a);
    e.inward += dot(estimated[i], truth[i]) <= 0.0f;
    e.not_unit += std::abs(length(estimated[i]) - 1.0f) > 1e-5f;
  }
  e.mean_deg /= double(truth.size());
  return e;
}

}  // namespace

TEST(PcaNormals, SphereNormalsAreAccurateAndAllOutward) {
  const SurfaceSamples s = sample_scene(sphere_scene(1.0f), 20'000, 1);
  ThreadPool pool(2);
  const std::vector<Vec3f> n = pca_normals(s.points.positions, pool);
  ASSERT_EQ(n.size(), s.points.size());
  const NormalErrors e = compare(n, s.true_normals);
  EXPECT_LT(e.mean_deg, 1.0);
  EXPECT_EQ(e.inward, 0u);
  EXPECT_EQ(e.not_unit, 0u);
}

TEST(PcaNormals, TorusNormalsAreAccurateAndAllOutward) {
  // The inner half of a torus is saddle-shaped and faces the centroid: orientation must come
  // from propagation, not from the direction away from the centre.
  const SurfaceSamples s = sample_scene(torus_scene(1.0f, 0.35f), 40'000, 2);
  ThreadPool pool(2);
  const NormalErrors e = compare(pca_normals(s.points.positions, pool), s.true_normals);
  EXPECT_LT(e.mean_deg, 1.0);
  EXPECT_EQ(e.inward, 0u);
}

TEST(PcaNormals, CubeFacesAreExactAwayFromEdgesAndAllOutward) {
  const AnalyticScene scene = cube_scene(1.0f);
  const std::size_t count = 30'000;
  const SurfaceSamples s = sample_scene(scene, count, 3);
  ThreadPool pool(2);
  const std::vector<Vec3f> n = pca_normals(s.points.positions, pool);
  // With `spacing` the side of the square each sample owns, 16 neighbours of a random sample
  // lie within about 2.3 spacings (rarely more than 3.5); beyond 4 spacings from every edge
  // a neighbourhood is flat and its normal is exact up to rounding.
  const double spacing = std::sqrt(surface_area(scene) / double(count));
  std::size_t interior = 0, off = 0, inward = 0;
  for (std::size_t i = 0; i < count; ++i) {
    inward += dot(n[i], s.true_normals[i]) <= 0.0f;
    if (s.edge_distance[i] > 4.0 * spacing) {
      ++interior;
      off += angle_deg(n[i], s.true_normals[i]) > 1.0;
    }
  }
  EXPECT_GT(interior, count / 2);
  EXPECT_EQ(off, 0u) << "of " << interior << " points away from edges";
  EXPECT_EQ(inward, 0u);
}

TEST(PcaNormals, EachSeparateShapeIsOrientedOutward) {
  // Sphere, torus and cube apart from each other: three components of the neighbour graph,
  // each seeded on its own.
  const SurfaceSamples s = sample_scene(demo_scene(), 40'000, 4);
  ThreadPool pool(2);
  const std::vector<Vec3f> n = pca_normals(s.points.positions, pool);
  // Each shape faces outward as a whole. A point pair on one of the cube's edges can still flip
  // (PCA planes there straddle two faces): over 60 samplings of this scene (30 k to 150 k
  // points) one pair flipped with a 15-neighbour orientation graph and one with 10. So the
  // sphere and the torus must have no inward normal, the cube at most two, each within two
  // sample spacings of an edge.
  const double spacing = std::sqrt(surface_area(demo_scene()) / double(n.size()));
  std::size_t inward[3] = {0, 0, 0}, total[3] = {0, 0, 0}, inward_off_edges = 0;
  for (std::size_t i = 0; i < n.size(); ++i) {
    ++total[s.shape_ids[i]];
    if (dot(n[i], s.true_normals[i]) <= 0.0f) {
      ++inward[s.shape_ids[i]];
      inward_off_edges += !(s.edge_distance[i] < 2.0 * spacing);
    }
  }
  for (int shape = 0; shape < 3; ++shape) {
    EXPECT_GT(total[shape], 1000u);
    EXPECT_LE(inward[shape], shape == 2 ? 2u : 0u)
        << "shape " << shape << " of " << total[shape] << " points";
  }
  EXPECT_EQ(inward_off_edges, 0u);
}

TEST(PcaNormals, IsolatedClustersAreSeededAwayFromTheCentroid) {
  // Two small flat patches far apart, facing each other across the centroid: each must get
  // normals pointing away from the centroid (x < 0 patch: -x, x > 0 patch: +x).
  std::vector<Vec3f> p;
  for (int side : {-1, 1}) {
    for (int y = 0; y < 10; ++y) {
      for (int z = 0; z < 10; ++z) {
        // A slight bulge keeps the seed (the farthest point) unambiguous.
        const float fy = 0.1f * float(y - 4.5f), fz = 0.1f * float(z - 4.5f);
        p.push_back({float(side) * (10.0f - 0.2f * (fy * fy + fz * fz)), fy, fz});
      }
    }
  }
  ThreadPool pool(2);
  const std::vector<Vec3f> n = pca_normals(p, pool, Progress::none(), {.k = 8});
  for (std::size_t i = 0; i < p.size(); ++i) {
    EXPECT_GT(n[i].x * p[i].x, 0.0f) << "point " << i;
  }
}

TEST(PcaNormals, ATorusCutIntoManyPiecesIsOrientedAsOne) {
  // 200,000 samples: twelve pieces of the orientation forest, each a block of space whose trees
  // are grown on their own; the pieces must be joined consistently, including those of the
  // inner half that faces the centroid.
  const SurfaceSamples s = sample_scene(torus_scene(1.0f, 0.35f), 200'000, 6);
  ThreadPool pool(2);
  const NormalErrors e = compare(pca_normals(s.points.positions, pool), s.true_normals);
  EXPECT_LT(e.mean_deg, 1.0);
  EXPECT_EQ(e.inward, 0u);
}

TEST(PcaNormals, EachSeparateShapeIsOneOrientationComponent) {
  // Sphere, torus and cube apart, 60,000 samples (four pieces, which cut the shapes): every
  // shape is one joined surface and no two shapes share one.
  const SurfaceSamples s = sample_scene(demo_scene(), 60'000, 7);
  ThreadPool pool(2);
  PointSet points = s.points;
  points.normals.clear();
  points.radii.clear();
  std::vector<std::uint32_t> components;
  prepare_splats(points, pool, Progress::none(), {.orientation_components = &components});
  ASSERT_EQ(components.size(), s.points.size());
  std::map<std::uint32_t, std::set<std::uint32_t>> shapes_of;  // component -> shapes
  std::map<std::uint32_t, std::set<std::uint32_t>> components_of;
  for (std::size_t i = 0; i < components.size(); ++i) {
    shapes_of[components[i]].insert(s.shape_ids[i]);
    components_of[s.shape_ids[i]].insert(components[i]);
  }
  EXPECT_EQ(components_of.size(), 3u);
  for (const auto& [shape, ids] : components_of) EXPECT_EQ(ids.size(), 1u) << "shape " << shape;
  for (const auto& [id, shapes] : shapes_of) EXPECT_EQ(shapes.size(), 1u) << "component " << id;
}

TEST(PcaNormals, SameBitsForAnyThreadCount) {
  const SurfaceSamples s = sample_scene(demo_scene(), 20'000, 5);
  ThreadPool one(1), three(3);
  const std::vector<Vec3f> a = pca_normals(s.points.positions, one);
  const std::vector<Vec3f> b = pca_normals(s.points.positions, three);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) ASSERT_TRUE(a[i] == b[i]) << "point " << i;
}

TEST(PcaNormals, RejectsTooFewPointsAndTooSmallK) {
  ThreadPool pool(1);
  const std::vector<Vec3f> two = {{0, 0, 0}, {1, 0, 0}};
  try {
    pca_normals(two, pool);
    FAIL() << "expected an Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("at least 3 points"), std::string::npos) << e.what();
  }
  const std::vector<Vec3f> three = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  EXPECT_THROW(pca_normals(three, pool, Progress::none(), {.k = 2}), OptionError);
  // Three points make a plane: k larger than the cloud is fine.
  const std::vector<Vec3f> n = pca_normals(three, pool);
  for (const Vec3f& v : n) EXPECT_NEAR(std::abs(v.z), 1.0f, 1e-6f);
}

// pca_plane against Eigen's iterative eigensolver (QR iterations, not a closed form) on the
// covariance of the same float points: random neighbourhoods of 16 points spread along three
// random orthogonal directions, 1 : w : w·f with w from 1 down to 1e-3 (thin strips, as along a
// scan line) and f from 1 down to 1e-3, near the origin and far from it. Eigen's own closed form
// misses by up to 2e-3 rad on the thinnest strips here.
TEST(PcaPlane, MatchesAnIterativeEigensolverOnRandomNeighbourhoods) {
  std::mt19937 rng(7);
  std::normal_distribution<double> gauss;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::size_t compared = 0;
  double worst = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    const Eigen::Matrix3d rotation =
        Eigen::Quaterniond(gauss(rng), gauss(rng), gauss(rng), gauss(rng)).normalized()
            .toRotationMatrix();
    const double w = std::pow(10.0, -3.0 * unit(rng));
    const double spread[3] = {1.0, w, w * std::pow(10.0, -3.0 * unit(rng))};
    const double far = trial % 2 == 0 ? 10.0 : 1000.0 * w;  // float ulps well below w
    const Eigen::Vector3d centre(far * gauss(rng), far * gauss(rng), far * gauss(rng));
    std::vector<Vec3f> points;
    for (int i = 0; i < 16; ++i) {
      const Eigen::Vector3d p =
          centre + rotation * Eigen::Vector3d(spread[0] * gauss(rng), spread[1] * gauss(rng),
                                              spread[2] * gauss(rng));
      points.push_back({float(p.x()), float(p.y()), float(p.z())});
    }
    std::vector<std::uint32_t> neighbours(15);
    std::iota(neighbours.begin(), neighbours.end(), 1u);
    const Vec3f normal = pca_plane(points, 0, neighbours).normal;
    ASSERT_NEAR(length(normal), 1.0f, 1e-6f) << "trial " << trial;
    // The reference: the covariance of the float points as stored, in double, two passes.
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const Vec3f& p : points) mean += Eigen::Vector3d(p.x, p.y, p.z);
    mean /= 16.0;
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
    for (const Vec3f& p : points) {
      const Eigen::Vector3d d = Eigen::Vector3d(p.x, p.y, p.z) - mean;
      covariance += d * d.transpose();
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance / 16.0);
    const Eigen::Vector3d values = solver.eigenvalues();
    // Where the two smallest eigenvalues are close the normal is not defined: skip those.
    if (!(values[1] > 2 * values[0])) continue;
    const Eigen::Vector3d truth = solver.eigenvectors().col(0);
    const Eigen::Vector3d n(normal.x, normal.y, normal.z);
    const double angle = std::asin(std::min(1.0, n.cross(truth).norm()));
    worst = std::max(worst, angle);
    EXPECT_LT(angle, 1e-6) << "trial " << trial << ": eigenvalues " << values.transpose();
    ++compared;
  }
  EXPECT_GT(compared, 3000u);
  RecordProperty("worst_angle_rad", std::to_string(worst));
}

TEST(PcaPlane, PointsOnALineGetAUnitNormalAcrossIt) {
  for (const Vec3f direction : {Vec3f{0, 0, 1}, Vec3f{1, 0, 0}, Vec3f{0, 1, 0},
                                normalized(Vec3f{1, 1, 1}), normalized(Vec3f{3, -1, 0.5f})}) {
    std::vector<Vec3f> points;
    for (int i = 0; i < 16; ++i) points.push_back(Vec3f{5, -2, 7} + direction * float(i - 3));
    std::vector<std::uint32_t> neighbours(15);
    std::iota(neighbours.begin(), neighbours.end(), 1u);
    const Vec3f normal = pca_plane(points, 0, neighbours).normal;
    EXPECT_NEAR(length(normal), 1.0f, 1e-6f);
    EXPECT_LT(std::abs(dot(normal, direction)), 1e-5f)
        << "line along (" << direction.x << ", " << direction.y << ", " << direction.z << ")";
  }
}

TEST(PcaPlane, CoincidentPointsGetAUnitNormal) {
  const std::vector<Vec3f> points(8, Vec3f{1, 2, 3});
  const std::vector<std::uint32_t> neighbours = {1, 2, 3, 4, 5, 6, 7};
  const PcaPlane plane = pca_plane(points, 0, neighbours);
  EXPECT_NEAR(length(plane.normal), 1.0f, 1e-6f);
  EXPECT_TRUE(plane.mean == (Vec3f{1, 2, 3}));
}
