// Statistical outlier removal: strays placed by the test are found, surfaces of one density or
// of several are kept, attributes stay with their points; and PCA normals of a cloud whose
// farthest point has an ambiguous normal still come out facing outward.
#include "pointillist/prep/outliers.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "pointillist/core/error.hpp"
#include "pointillist/prep/prepare.hpp"

using namespace pointillist;

namespace {

// `count` random samples of the square [0, size]² in the plane z = 0.
void add_plane(PointSet& p, std::size_t count, float size, float x0, std::mt19937& rng) {
  std::uniform_real_distribution<float> u(0.0f, size);
  for (std::size_t i = 0; i < count; ++i) p.positions.push_back({x0 + u(rng), u(rng), 0.0f});
}

}  // namespace

TEST(Outliers, StraysAboveAPlaneAreFoundAndThePlaneIsKept) {
  std::mt19937 rng(71);
  PointSet p;
  add_plane(p, 20000, 1.0f, 0.0f, rng);  // spacing about 0.007
  const std::size_t plane = p.size();
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  // 8 lone strays 0.05 to 0.2 above the plane, at least 0.3 apart (strays are rare: their
  // neighbours are surface points), and a cluster of 5 within 0.01 of each other.
  for (int i = 0; i < 8; ++i) {
    p.positions.push_back({0.15f + 0.35f * float(i % 3), 0.15f + 0.35f * float(i / 3),
                           0.05f + 0.15f * u(rng)});
  }
  for (int i = 0; i < 5; ++i) {
    p.positions.push_back({0.3f + 0.01f * u(rng), 0.85f + 0.01f * u(rng), 0.1f + 0.01f * u(rng)});
  }
  ThreadPool pool(2);
  const std::vector<std::uint8_t> out = find_outliers(p.positions, pool);
  std::size_t strays_found = 0, plane_dropped = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (i < plane) {
      plane_dropped += out[i];
    } else {
      strays_found += out[i];
    }
  }
  EXPECT_EQ(strays_found, 13u);
  EXPECT_LE(plane_dropped, plane / 200) << "at most 0.5% of a uniform plane";
}

TEST(Outliers, RegionsOfDifferentDensityAreBothKept) {
  // A scan is denser near the scanner: two planes side by side, one with 9 times the samples
  // (3 times closer spacing). Neither may be dropped wholesale.
  std::mt19937 rng(72);
  PointSet p;
  add_plane(p, 18000, 1.0f, 0.0f, rng);
  const std::size_t dense = p.size();
  add_plane(p, 2000, 1.0f, 1.5f, rng);
  ThreadPool pool(2);
  const std::vector<std::uint8_t> out = find_outliers(p.positions, pool);
  std::size_t dense_dropped = 0, sparse_dropped = 0;
  for (std::size_t i = 0; i < p.size(); ++i) (i < dense ? dense_dropped : sparse_dropped) += out[i];
  EXPECT_LE(dense_dropped, dense / 200);
  EXPECT_LE(sparse_dropped, (p.size() - dense) / 50) << "at most 2% of the sparse region";
}

TEST(Outliers, RemovalKeepsEachPointsAttributesAndRefusesMeshes) {
  std::mt19937 rng(73);
  PointSet p;
  add_plane(p, 5000, 1.0f, 0.0f, rng);
  p.positions.push_back({0.5f, 0.5f, 2.0f});
  // Attributes that encode the position, so a misaligned compaction shows.
  for (const Vec3f& x : p.positions) {
    p.colors.push_back({std::uint8_t(x.x * 255), std::uint8_t(x.y * 255), std::uint8_t(x.z * 100)});
    p.radii.push_back(x.x + 2 * x.y);
    p.normals.push_back(normalized(Vec3f{x.x, x.y, 1.0f}));
  }
  ThreadPool pool(2);
  const std::size_t before = p.size();
  const std::size_t removed = remove_outliers(p, pool);
  EXPECT_GE(removed, 1u);
  EXPECT_EQ(p.size(), before - removed);
  ASSERT_EQ(p.colors.size(), p.size());
  ASSERT_EQ(p.radii.size(), p.size());
  ASSERT_EQ(p.normals.size(), p.size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Vec3f& x = p.positions[i];
    EXPECT_LT(x.z, 1.0f) << "the stray is gone";
    EXPECT_EQ(p.colors[i].r, std::uint8_t(x.x * 255)) << i;
    EXPECT_EQ(p.radii[i], x.x + 2 * x.y) << i;
  }
  PointSet mesh;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  mesh.triangles = {{0, 1, 2}};
  EXPECT_THROW(remove_outliers(mesh, pool), OptionError);
  EXPECT_THROW(find_outliers(p.positions, pool, Progress::none(), {.ratio = 1.0f}), OptionError);
  EXPECT_THROW(find_outliers(p.positions, pool, Progress::none(), {.neighbours = 0}),
               OptionError);
  PointSet prepared = p;
  EXPECT_THROW(prepare_splats(mesh, pool, Progress::none(), {.drop_outliers = true}),
               OptionError);
}

TEST(NormalOrientation, AFarthestPointWithAnAmbiguousNormalDoesNotTurnASphereInsideOut) {
  // A sphere with a flat fin sticking out radially: the fin's tip is the farthest point from the
  // centroid, and its normal is perpendicular to the way out, so it cannot say which side is out.
  // The sphere's many points decide; its normals must face outward whatever the fin's tilt.
  for (int trial = 0; trial < 6; ++trial) {
    std::mt19937 rng(80 + trial);
    std::normal_distribution<float> g(0.0f, 1.0f);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    PointSet p;
    for (int i = 0; i < 6000; ++i) p.positions.push_back(normalized(Vec3f{g(rng), g(rng), g(rng)}));
    const std::size_t sphere = p.size();
    const float tilt = 0.2f * (u(rng) - 0.5f);  // the fin's plane leans a little either way
    for (int i = 0; i < 1500; ++i) {
      const float along = 1.0f + 1.5f * u(rng), across = 0.3f * (u(rng) - 0.5f);
      p.positions.push_back({along, across, tilt * along});
    }
    ThreadPool pool(2);
    prepare_splats(p, pool, Progress::none(), {.normals = NormalSource::Pca});
    std::size_t inward = 0;
    for (std::size_t i = 0; i < sphere; ++i) inward += dot(p.normals[i], p.positions[i]) < 0.0f;
    EXPECT_LT(inward, sphere / 100) << "trial " << trial << ": " << inward << " of " << sphere
                                    << " sphere normals face inward";
  }
}
