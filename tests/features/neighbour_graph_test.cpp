// The bounding-sphere graph against the brute-force oracle (every pair compared).
#include "pointillist/features/neighbour_graph.hpp"

#include <gtest/gtest.h>

#include <random>

#include "pointillist/scene/analytic.hpp"

using namespace pointillist;

namespace {

void expect_same_graph(const NeighbourGraph& got, const NeighbourGraph& want) {
  ASSERT_EQ(got.vertex_count(), want.vertex_count());
  for (std::size_t i = 0; i < want.vertex_count(); ++i) {
    const auto g = got.row(i), w = want.row(i);
    ASSERT_EQ(std::vector<std::uint32_t>(g.begin(), g.end()),
              std::vector<std::uint32_t>(w.begin(), w.end()))
        << "row " << i;
  }
}

struct Splats {
  std::vector<Vec3f> centers;
  std::vector<float> radii;
};

// Samples of the cube's surface with radii around `r`, a few of them 20 times larger (the
// oversized splats merged after), some exactly equal and a few zero.
Splats cube_splats(std::size_t n, float r, std::uint64_t seed) {
  const SurfaceSamples s = sample_scene(cube_scene(1.0f), n, seed);
  Splats out;
  out.centers = s.points.positions;
  std::mt19937 rng(static_cast<std::uint32_t>(seed));
  std::uniform_real_distribution<float> jitter(0.5f, 1.5f);
  for (std::size_t i = 0; i < n; ++i) {
    float radius = r * jitter(rng);
    if (i % 97 == 0) radius = 20 * r;
    if (i % 13 == 0) radius = r;
    if (i % 101 == 0) radius = 0;
    out.radii.push_back(radius);
  }
  return out;
}

TEST(NeighbourGraph, MatchesBruteForceOnASurfaceWithMixedRadii) {
  const Splats s = cube_splats(3000, 0.05f, 7);
  ThreadPool pool(2);
  const NeighbourGraph grid = build_neighbour_graph(s.centers, s.radii, pool);
  const NeighbourGraph brute = build_neighbour_graph_brute_force(s.centers, s.radii);
  EXPECT_GT(brute.edge_count(), 3000u * 4);  // a real graph, not a handful of edges
  expect_same_graph(grid, brute);
}

TEST(NeighbourGraph, MatchesBruteForceOnAVolumeCloudWithDuplicates) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  Splats s;
  for (int i = 0; i < 2000; ++i) {
    s.centers.push_back({u(rng) * 3, u(rng), u(rng) * 0.01f});  // flat and elongated box
    s.radii.push_back(0.04f + 0.04f * (u(rng) + 1));
  }
  for (int i = 0; i < 50; ++i) {  // copies of a point with the same radius
    s.centers.push_back(s.centers[i]);
    s.radii.push_back(s.radii[i]);
  }
  ThreadPool pool(2);
  expect_same_graph(build_neighbour_graph(s.centers, s.radii, pool),
                    build_neighbour_graph_brute_force(s.centers, s.radii));
}

TEST(NeighbourGraph, MatchesBruteForceOnDenseClustersWithLongRows) {
  // Clusters of 150 splats that all overlap (rows past the short-row sort, runs of every length
  // modulo four), on a sparse background of single splats.
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  Splats s;
  for (int cluster = 0; cluster < 4; ++cluster) {
    const Vec3f at{u(rng) * 5, u(rng) * 5, u(rng) * 5};
    for (int i = 0; i < 150 + cluster; ++i) {
      s.centers.push_back(at + Vec3f{u(rng), u(rng), u(rng)} * 0.05f);
      s.radii.push_back(0.06f + 0.01f * u(rng));
    }
  }
  for (int i = 0; i < 3000; ++i) {
    s.centers.push_back(Vec3f{u(rng), u(rng), u(rng)} * 5.0f);
    s.radii.push_back(0.05f);
  }
  ThreadPool pool(2);
  const NeighbourGraph grid = build_neighbour_graph(s.centers, s.radii, pool);
  EXPECT_GE(grid.row(0).size(), 149u);
  expect_same_graph(grid, build_neighbour_graph_brute_force(s.centers, s.radii));
}

TEST(NeighbourGraph, IsStrictAndSymmetric) {
  // d = r_a + r_b exactly is not an edge (eq. 3.1 is strict); slightly less is.
  const std::vector<Vec3f> c = {{0, 0, 0}, {1, 0, 0}, {0, 0.999f, 0}};
  const std::vector<float> r = {0.5f, 0.5f, 0.5f};
  ThreadPool pool(1);
  const NeighbourGraph g = build_neighbour_graph(c, r, pool);
  EXPECT_EQ(g.edge_count(), 1u);
  ASSERT_EQ(g.row(0).size(), 1u);
  EXPECT_EQ(g.row(0)[0], 2u);
  ASSERT_EQ(g.row(2).size(), 1u);
  EXPECT_EQ(g.row(2)[0], 0u);
  EXPECT_TRUE(g.row(1).empty());
}

TEST(NeighbourGraph, DoesNotDependOnTheThreadCount) {
  const Splats s = cube_splats(20000, 0.03f, 11);
  ThreadPool one(1), two(2), four(4);
  const NeighbourGraph a = build_neighbour_graph(s.centers, s.radii, one);
  expect_same_graph(build_neighbour_graph(s.centers, s.radii, two), a);
  expect_same_graph(build_neighbour_graph(s.centers, s.radii, four), a);
}

TEST(NeighbourGraph, HandlesEmptyAndSinglePointSets) {
  ThreadPool pool(1);
  EXPECT_EQ(build_neighbour_graph({}, {}, pool).vertex_count(), 0u);
  const std::vector<Vec3f> c = {{1, 2, 3}};
  const std::vector<float> r = {0};
  const NeighbourGraph g = build_neighbour_graph(c, r, pool);
  EXPECT_EQ(g.vertex_count(), 1u);
  EXPECT_EQ(g.edge_count(), 0u);
}

}  // namespace
