// kNN against brute force, Morton order as a spatially coherent permutation.
#include "pointillist/spatial/knn.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <set>
#include <tuple>

using namespace pointillist;

namespace {

std::vector<Vec3f> random_points(std::size_t n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<Vec3f> p(n);
  for (Vec3f& v : p) v = {u(rng), u(rng), u(rng)};
  return p;
}

// Points on a 3D integer grid: many exactly equal distances.
std::vector<Vec3f> grid_points(int side) {
  std::vector<Vec3f> p;
  for (int z = 0; z < side; ++z) {
    for (int y = 0; y < side; ++y) {
      for (int x = 0; x < side; ++x) p.push_back({float(x), float(y), float(z)});
    }
  }
  return p;
}

// The k smallest squared distances from point i to the other points, sorted (the oracle).
std::vector<float> brute_force_d2(const std::vector<Vec3f>& p, std::size_t i, std::size_t k) {
  std::vector<float> d;
  for (std::size_t j = 0; j < p.size(); ++j) {
    if (j != i) d.push_back(length_squared(p[j] - p[i]));
  }
  std::partial_sort(d.begin(), d.begin() + std::ptrdiff_t(k), d.end());
  d.resize(k);
  return d;
}

// Checks every row against brute force: the distances match the k smallest (so equal distances
// may swap indices), indices are distinct, not the point itself, and really at those distances.
void expect_matches_brute_force(const std::vector<Vec3f>& p, std::uint32_t k, unsigned threads,
                                KnnPaths* paths = nullptr) {
  ThreadPool pool(threads);
  std::vector<float> d2;
  const auto nb = k_nearest_neighbours(p, pool, {.k = k, .paths = paths}, &d2);
  ASSERT_EQ(nb.size(), p.size() * k);
  ASSERT_EQ(d2.size(), p.size() * k);
  for (std::size_t i = 0; i < p.size(); ++i) {
    const std::vector<float> oracle = brute_force_d2(p, i, k);
    std::set<std::uint32_t> seen;
    for (std::uint32_t j = 0; j < k; ++j) {
      const std::uint32_t m = nb[i * k + j];
      ASSERT_LT(m, p.size());
      EXPECT_NE(m, i) << "point " << i;
      EXPECT_TRUE(seen.insert(m).second) << "point " << i << " lists " << m << " twice";
      EXPECT_EQ(d2[i * k + j], length_squared(p[m] - p[i])) << "point " << i;
      EXPECT_FLOAT_EQ(d2[i * k + j], oracle[j]) << "point " << i << " neighbour " << j;
    }
  }
}

}  // namespace

TEST(KNearestNeighbours, MatchesBruteForceOnRandomPoints) {
  expect_matches_brute_force(random_points(2000, 7), 16, 2);
}

TEST(KNearestNeighbours, MatchesBruteForceOnManyPointsInSampledRows) {
  // 200,000 points, a grid of about 25,000 cells answered on two threads in many tasks; every
  // 401st row against brute force.
  const std::vector<Vec3f> p = random_points(200'000, 17);
  const std::uint32_t k = 12;
  ThreadPool pool(2);
  std::vector<float> d2;
  const auto nb = k_nearest_neighbours(p, pool, {.k = k}, &d2);
  for (std::size_t i = 0; i < p.size(); i += 401) {
    const std::vector<float> oracle = brute_force_d2(p, i, k);
    for (std::uint32_t j = 0; j < k; ++j) {
      const std::uint32_t m = nb[i * k + j];
      ASSERT_LT(m, p.size());
      EXPECT_NE(m, i) << "point " << i;
      EXPECT_EQ(d2[i * k + j], length_squared(p[m] - p[i])) << "point " << i;
      EXPECT_EQ(d2[i * k + j], oracle[j]) << "point " << i << " neighbour " << j;
    }
  }
}

TEST(KNearestNeighbours, MatchesBruteForceWithEqualDistancesOnAGrid) {
  expect_matches_brute_force(grid_points(12), 8, 2);
}

TEST(KNearestNeighbours, EqualDistancesAreOrderedByIndex) {
  const std::vector<Vec3f> p = grid_points(6);
  ThreadPool pool(2);
  std::vector<float> d2;
  const std::uint32_t k = 6;
  const auto nb = k_nearest_neighbours(p, pool, {.k = k}, &d2);
  for (std::size_t i = 0; i < p.size(); ++i) {
    for (std::uint32_t j = 1; j < k; ++j) {
      ASSERT_LE(d2[i * k + j - 1], d2[i * k + j]);
      if (d2[i * k + j - 1] == d2[i * k + j]) {
        EXPECT_LT(nb[i * k + j - 1], nb[i * k + j]);
      }
    }
  }
  // An interior grid point has exactly its 6 face neighbours at distance 1.
  const std::size_t centre = 2 + 6 * (2 + 6 * 2);
  const std::vector<std::uint32_t> expected = {centre - 36, centre - 6, centre - 1,
                                               centre + 1,  centre + 6, centre + 36};
  EXPECT_EQ(std::vector<std::uint32_t>(nb.begin() + centre * k, nb.begin() + centre * k + k),
            expected);
}

// On a grid, an interior point with k = 4 has 6 face neighbours tied at distance 1: the cut takes
// the 4 lowest positions (x, then y, then z), whatever else is in the set, so a subset holding
// a point's neighbourhood (a chunk and its halo) finds the same neighbours as the whole.
TEST(KNearestNeighbours, TiesAtTheCutGoToTheLowestPositionsInAnySubset) {
  const std::vector<Vec3f> all = grid_points(9);
  ThreadPool pool(2);
  const std::uint32_t k = 4;
  const auto whole = k_nearest_neighbours(all, pool, {.k = k});
  const std::size_t centre = 4 + 9 * (4 + 9 * 4);  // (4, 4, 4)
  std::vector<Vec3f> got;
  for (std::uint32_t j = 0; j < k; ++j) got.push_back(all[whole[centre * k + j]]);
  std::sort(got.begin(), got.end(), [](Vec3f a, Vec3f b) {
    return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z);
  });
  const std::vector<Vec3f> lowest = {{3, 4, 4}, {4, 3, 4}, {4, 4, 3}, {4, 4, 5}};
  EXPECT_EQ(got, lowest);
  // Subsets: the points within distance 2.5 of the centre, in shuffled orders.
  std::mt19937 rng(3);
  for (int trial = 0; trial < 5; ++trial) {
    std::vector<std::size_t> keep;
    for (std::size_t i = 0; i < all.size(); ++i) {
      if (length_squared(all[i] - all[centre]) <= 6.25f) keep.push_back(i);
    }
    std::shuffle(keep.begin(), keep.end(), rng);
    std::vector<Vec3f> part;
    std::size_t at = 0;
    for (std::size_t i = 0; i < keep.size(); ++i) {
      part.push_back(all[keep[i]]);
      if (keep[i] == centre) at = i;
    }
    const auto sub = k_nearest_neighbours(part, pool, {.k = k});
    std::set<std::size_t> a, b;
    for (std::uint32_t j = 0; j < k; ++j) {
      a.insert(whole[centre * k + j]);
      b.insert(keep[sub[at * k + j]]);
    }
    EXPECT_EQ(a, b) << "trial " << trial;
  }
}

TEST(KNearestNeighbours, SameResultForAnyThreadCountAndOrderFlag) {
  const std::vector<Vec3f> p = random_points(3000, 11);
  ThreadPool one(1), three(3);
  std::vector<float> d_one, d_three;
  const auto a = k_nearest_neighbours(p, one, {.k = 10}, &d_one);
  const auto b = k_nearest_neighbours(p, three, {.k = 10}, &d_three);
  EXPECT_EQ(a, b);
  EXPECT_EQ(d_one, d_three);
  // Telling it the (random) points are ordered must change only speed, not the answer.
  const auto c = k_nearest_neighbours(p, three, {.k = 10, .points_are_ordered = true});
  EXPECT_EQ(a, c);
}

TEST(KNearestNeighbours, FewerPointsThanKRepeatTheLastNeighbour) {
  ThreadPool pool(2);
  const std::vector<Vec3f> p = {{0, 0, 0}, {1, 0, 0}, {3, 0, 0}};
  std::vector<float> d2;
  const auto nb = k_nearest_neighbours(p, pool, {.k = 4}, &d2);
  EXPECT_EQ(nb, (std::vector<std::uint32_t>{1, 2, 2, 2, 0, 2, 2, 2, 1, 0, 0, 0}));
  EXPECT_EQ(d2, (std::vector<float>{1, 9, 9, 9, 1, 4, 4, 4, 4, 9, 9, 9}));

  const std::vector<Vec3f> single = {{5, 5, 5}};
  EXPECT_EQ(k_nearest_neighbours(single, pool, {.k = 2}), (std::vector<std::uint32_t>{0, 0}));
  EXPECT_TRUE(k_nearest_neighbours({}, pool, {.k = 3}).empty());
}

TEST(KNearestNeighbours, DuplicatePointsAreNeighboursAtDistanceZero) {
  ThreadPool pool(2);
  std::vector<Vec3f> p(5, Vec3f{1, 2, 3});
  p.push_back({1, 2, 4});
  std::vector<float> d2;
  const auto nb = k_nearest_neighbours(p, pool, {.k = 3}, &d2);
  // Point 2 has four copies at distance 0; the three lowest indices other than itself win.
  EXPECT_EQ(std::vector<std::uint32_t>(nb.begin() + 6, nb.begin() + 9),
            (std::vector<std::uint32_t>{0, 1, 3}));
  EXPECT_EQ(std::vector<float>(d2.begin() + 6, d2.begin() + 9), (std::vector<float>{0, 0, 0}));
  EXPECT_EQ(std::vector<float>(d2.begin() + 15, d2.begin() + 18), (std::vector<float>{1, 1, 1}));
}

// A dense surface with stray points far from it: the surface's queries are answered from the
// grid's cell blocks, the strays' (whose neighbours lie beyond their blocks) by the kd-tree; both
// must be the exact k nearest.
TEST(KNearestNeighbours, MatchesBruteForceOnASurfaceWithStrayPoints) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<Vec3f> p;
  for (int i = 0; i < 5000; ++i) {
    const float a = u(rng) * 6.2831853f, z = 2 * u(rng) - 1, r = std::sqrt(1 - z * z);
    p.push_back({r * std::cos(a), r * std::sin(a), z});
  }
  for (int i = 0; i < 60; ++i) p.push_back({8 * u(rng) - 4, 8 * u(rng) - 4, 8 * u(rng) - 4});
  std::shuffle(p.begin(), p.end(), rng);
  expect_matches_brute_force(p, 16, 2);
}

// Points along a line in a random direction, jittered: the grid's cells (about 8 points each)
// lie along it, so a query near its cell's end sees too few points in its 3x3x3 block.
std::vector<Vec3f> jittered_line(std::size_t n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  const Vec3f dir = normalized(Vec3f{0.8f, 0.5f, 0.3f});
  std::vector<Vec3f> p;
  for (std::size_t i = 0; i < n; ++i) {
    const float t = float(i) + 0.3f * u(rng);
    p.push_back(dir * t + Vec3f{u(rng), u(rng), u(rng)} * 0.05f);
  }
  std::shuffle(p.begin(), p.end(), rng);
  return p;
}

// The queries the 3x3x3 block cannot answer are answered from wider blocks, exactly.
TEST(KNearestNeighbours, WiderBlocksAnswerTheBlocksMissesLikeBruteForce) {
  KnnPaths paths;
  expect_matches_brute_force(jittered_line(3000, 21), 24, 2, &paths);
  EXPECT_GT(paths.wide, 0u);
  EXPECT_EQ(paths.grid + paths.wide + paths.tree, 3000u);
}

// k = 100 reaches past the 9^3 block too: those queries go to the kd-tree, also when there are
// more misses than the wider blocks are tried for (4,096).
TEST(KNearestNeighbours, MissesOfEveryBlockGoToTheKdTreeLikeBruteForce) {
  for (const std::size_t n : {std::size_t(2000), std::size_t(6000)}) {
    KnnPaths paths;
    expect_matches_brute_force(jittered_line(n, 23), 100, 2, &paths);
    EXPECT_GT(paths.tree, 0u) << n << " points";
    EXPECT_EQ(paths.grid + paths.wide + paths.tree, n) << n << " points";
  }
}

// Forty copies of one point among others: each copy's 16 neighbours are 16 other copies, those
// with the lowest indices (all tie at distance 0 and at the same position), however many tie.
TEST(KNearestNeighbours, ManyCopiesTiedAtTheCutGoToTheLowestIndices) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<Vec3f> p;
  for (int i = 0; i < 200; ++i) p.push_back({u(rng), u(rng), u(rng)});
  std::vector<std::uint32_t> copies;
  for (int i = 0; i < 40; ++i) {
    copies.push_back(std::uint32_t(p.size()));
    p.push_back({0.25f, 0.25f, 0.25f});
    for (int j = 0; j < 3; ++j) p.push_back({u(rng), u(rng), u(rng)});
  }
  ThreadPool pool(2);
  const std::uint32_t k = 16;
  const auto nb = k_nearest_neighbours(p, pool, {.k = k});
  for (const std::uint32_t c : copies) {
    std::vector<std::uint32_t> expected;
    for (const std::uint32_t o : copies) {
      if (o != c && expected.size() < k) expected.push_back(o);
    }
    EXPECT_EQ(std::vector<std::uint32_t>(nb.begin() + std::size_t(c) * k,
                                         nb.begin() + std::size_t(c) * k + k),
              expected)
        << "copy " << c;
  }
}

TEST(MortonOrder, IsAPermutation) {
  ThreadPool pool(2);
  for (std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{1000}, std::size_t{150'000}}) {
    const auto order = morton_order(random_points(n, 3), pool);
    ASSERT_EQ(order.size(), n);
    std::vector<std::uint32_t> sorted = order;
    std::sort(sorted.begin(), sorted.end());
    std::vector<std::uint32_t> identity(n);
    std::iota(identity.begin(), identity.end(), 0u);
    EXPECT_EQ(sorted, identity) << n << " points";
  }
}

TEST(MortonOrder, FollowsTheZCurveOnA2x2x2Grid) {
  // Morton code bit order is x (lowest), then y, then z.
  std::vector<Vec3f> p;
  for (int i = 7; i >= 0; --i) p.push_back({float(i & 1), float((i >> 1) & 1), float(i >> 2)});
  ThreadPool pool(1);
  EXPECT_EQ(morton_order(p, pool), (std::vector<std::uint32_t>{7, 6, 5, 4, 3, 2, 1, 0}));
}

TEST(MortonOrder, ConsecutivePointsAreClose) {
  // Random order: consecutive points are about 1 apart in the unit cube [-1, 1]^3. Along the
  // curve they must be about as close as a grid of that density (2 / n^(1/3) ≈ 0.04 here).
  const std::size_t n = 200'000;
  const std::vector<Vec3f> p = random_points(n, 5);
  ThreadPool one(1), two(2);
  const auto order = morton_order(p, two);
  EXPECT_EQ(order, morton_order(p, one));
  double random_sum = 0, ordered_sum = 0;
  for (std::size_t i = 1; i < n; ++i) {
    random_sum += distance(p[i], p[i - 1]);
    ordered_sum += distance(p[order[i]], p[order[i - 1]]);
  }
  EXPECT_GT(random_sum / double(n), 0.9);
  EXPECT_LT(ordered_sum / double(n), 0.06);
}

TEST(MortonOrder, LargeBucketsWithManyTiesSortByCodeThenIndex) {
  // 300,000 points on 9,096 distinct positions: 5,000 random ones, and a 16^3 grid of steps of
  // about 2 Morton cells (their codes differ in the lowest bits only) that most points copy, so
  // that the sort's top-level buckets hold many points and many ties. The order is that of
  // sorting (Morton code, index) pairs by comparison.
  std::vector<Vec3f> distinct = random_points(5'000, 11);
  for (int x = 0; x < 16; ++x) {
    for (int y = 0; y < 16; ++y) {
      for (int z = 0; z < 16; ++z) {
        distinct.push_back(Vec3f{float(x), float(y), float(z)} * 2e-6f + Vec3f{0.1f, 0.2f, 0.3f});
      }
    }
  }
  std::vector<Vec3f> p;
  std::uint64_t state = 12345;
  for (std::size_t i = 0; i < 300'000; ++i) {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    const std::size_t pick = (state >> 33) % distinct.size();
    p.push_back(distinct[i % 10 == 0 ? pick : 5'000 + pick % 4'096]);
  }
  ThreadPool pool(2);
  const MortonFrame frame = MortonFrame::of(p);
  std::vector<std::pair<std::uint64_t, std::uint32_t>> expected;
  for (std::uint32_t i = 0; i < p.size(); ++i) expected.push_back({frame.code(p[i]), i});
  std::sort(expected.begin(), expected.end());
  const auto order = morton_order(p, pool);
  ASSERT_EQ(order.size(), p.size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    ASSERT_EQ(order[i], expected[i].second) << "place " << i;
  }
}

TEST(MortonOrder, EqualPointsKeepIndexOrderAndNanDoesNotBreakIt) {
  ThreadPool pool(2);
  std::vector<Vec3f> p(4, Vec3f{1, 1, 1});
  p.push_back({0, 0, 0});
  p.push_back({std::nanf(""), 0, 0});
  const auto order = morton_order(p, pool);
  // NaN clamps to the low corner of its axis, tying with (0,0,0) at code 0; index breaks the tie.
  EXPECT_EQ(order, (std::vector<std::uint32_t>{4, 5, 0, 1, 2, 3}));
}
