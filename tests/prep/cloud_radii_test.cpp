// Cloud radii: the defining formula on a grid and brute force, and hole-free coverage of
// randomly sampled analytic surfaces.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "pointillist/core/error.hpp"
#include "pointillist/prep/normals.hpp"
#include "pointillist/prep/radii.hpp"
#include "pointillist/scene/analytic.hpp"

using namespace pointillist;

TEST(CloudRadii, RegularGridGivesMeanFiveNeighbourDistanceTimesCoverageAndScale) {
  // A 20 × 20 square grid with spacing h. An interior point's 5 nearest: 4 at h, then one of
  // the 4 diagonal ones at h√2, so the mean is (4 + √2) h / 5.
  const float h = 0.25f;
  std::vector<Vec3f> p;
  for (int y = 0; y < 20; ++y) {
    for (int x = 0; x < 20; ++x) p.push_back({x * h, y * h, 1.0f});
  }
  ThreadPool pool(2);
  const std::vector<float> r =
      cloud_radii(p, pool, Progress::none(), {.coverage = 1.5f, .scale = 2.0f});
  const float expected = (4.0f + std::sqrt(2.0f)) * h / 5.0f * 1.5f * 2.0f;
  for (int y = 1; y < 19; ++y) {
    for (int x = 1; x < 19; ++x) EXPECT_FLOAT_EQ(r[std::size_t(y * 20 + x)], expected);
  }
  // A corner point: 2 at h, 1 at h√2, 2 at 2h.
  EXPECT_FLOAT_EQ(r[0], (2.0f + std::sqrt(2.0f) + 4.0f) * h / 5.0f * 1.5f * 2.0f);
  // The default coverage is the documented constant.
  const std::vector<float> d = cloud_radii(p, pool);
  EXPECT_FLOAT_EQ(d[21], (4.0f + std::sqrt(2.0f)) * h / 5.0f * kDefaultCloudCoverage);
}

TEST(CloudRadii, MatchBruteForceOnRandomPoints) {
  const SurfaceSamples s = sample_scene(torus_scene(), 1500, 8);
  const std::vector<Vec3f>& p = s.points.positions;
  ThreadPool pool(2);
  const std::vector<float> r =
      cloud_radii(p, pool, Progress::none(), {.neighbours = 3, .coverage = 1.0f, .outlier_ratio = 0});
  for (std::size_t i = 0; i < p.size(); ++i) {
    std::vector<float> d;
    for (std::size_t j = 0; j < p.size(); ++j) {
      if (j != i) d.push_back(distance(p[i], p[j]));
    }
    std::partial_sort(d.begin(), d.begin() + 3, d.end());
    EXPECT_NEAR(r[i], (d[0] + d[1] + d[2]) / 3.0f, 1e-6f) << "point " << i;
  }
}

TEST(CloudRadii, RejectsZeroNeighbours) {
  ThreadPool pool(1);
  const std::vector<Vec3f> p = {{0, 0, 0}, {1, 0, 0}};
  EXPECT_THROW(cloud_radii(p, pool, Progress::none(), {.neighbours = 0}), OptionError);
}

namespace {

// Independent oracle for coverage: a uniform grid over the samples (cells as wide as the
// largest radius, so every disc that can cover a point lies in the 27 cells around it).
class SampleGrid {
 public:
  SampleGrid(const std::vector<Vec3f>& points, float cell) : cell_(cell) {
    for (const Vec3f& p : points) box_.extend(p);
    for (int a = 0; a < 3; ++a) {
      size_[a] = std::int64_t((box_.hi[a] - box_.lo[a]) / cell) + 1;
    }
    std::vector<std::int64_t> cell_of(points.size());
    begin_.assign(std::size_t(size_[0] * size_[1] * size_[2]) + 1, 0);
    for (std::size_t i = 0; i < points.size(); ++i) {
      cell_of[i] = index(coord(points[i], 0), coord(points[i], 1), coord(points[i], 2));
      ++begin_[std::size_t(cell_of[i]) + 1];
    }
    for (std::size_t c = 1; c < begin_.size(); ++c) begin_[c] += begin_[c - 1];
    items_.resize(points.size());
    std::vector<std::uint32_t> fill(begin_.begin(), begin_.end() - 1);
    for (std::size_t i = 0; i < points.size(); ++i) {
      items_[fill[std::size_t(cell_of[i])]++] = std::uint32_t(i);
    }
  }

  // Calls fn(i) for the samples in the 27 cells around q (q's own cell first, where a covering
  // disc is most likely) until it returns true; says whether one did.
  template <class Fn>
  bool any_near(Vec3f q, Fn&& fn) const {
    const std::int64_t c[3] = {coord(q, 0), coord(q, 1), coord(q, 2)};
    const auto visit = [&](std::int64_t x, std::int64_t y, std::int64_t z) {
      if (x < 0 || y < 0 || z < 0 || x >= size_[0] || y >= size_[1] || z >= size_[2]) return false;
      const auto cell = std::size_t(index(x, y, z));
      for (std::uint32_t e = begin_[cell]; e < begin_[cell + 1]; ++e) {
        if (fn(items_[e])) return true;
      }
      return false;
    };
    if (visit(c[0], c[1], c[2])) return true;
    for (std::int64_t dz = -1; dz <= 1; ++dz) {
      for (std::int64_t dy = -1; dy <= 1; ++dy) {
        for (std::int64_t dx = -1; dx <= 1; ++dx) {
          if ((dx != 0 || dy != 0 || dz != 0) && visit(c[0] + dx, c[1] + dy, c[2] + dz)) {
            return true;
          }
        }
      }
    }
    return false;
  }

 private:
  std::int64_t coord(Vec3f p, int axis) const {
    const auto c = std::int64_t(std::floor((p[axis] - box_.lo[axis]) / cell_));
    return std::clamp<std::int64_t>(c, -1, size_[axis]);  // probes just outside the box
  }
  std::int64_t index(std::int64_t x, std::int64_t y, std::int64_t z) const {
    return (z * size_[1] + y) * size_[0] + x;
  }

  float cell_;
  Aabb box_;
  std::int64_t size_[3] = {1, 1, 1};
  std::vector<std::uint32_t> begin_, items_;
};

// Fraction of `probes` random surface points inside no sample's disc (centre, PCA normal, radius
// at `coverage`), measured in the disc's plane: the holes a renderer of those discs would show
// seen head-on.
double uncovered_fraction(const AnalyticScene& scene, std::size_t samples, std::uint64_t seed,
                          std::size_t probes, float coverage = kDefaultCloudCoverage) {
  const SurfaceSamples s = sample_scene(scene, samples, seed);
  ThreadPool pool(2);
  const std::vector<Vec3f>& p = s.points.positions;
  const std::vector<Vec3f> n = pca_normals(p, pool);
  const std::vector<float> r = cloud_radii(p, pool, Progress::none(), {.coverage = coverage});
  const SampleGrid grid(p, *std::max_element(r.begin(), r.end()));
  const SurfaceSamples probe = sample_scene(scene, probes, seed + 1000);
  std::size_t uncovered = 0;
  for (const Vec3f q : probe.points.positions) {
    uncovered += !grid.any_near(q, [&](std::uint32_t i) {
      const Vec3f d = q - p[i];
      const Vec3f in_plane = d - n[i] * dot(d, n[i]);
      return length_squared(in_plane) <= r[i] * r[i];
    });
  }
  return double(uncovered) / double(probes);
}

}  // namespace

TEST(CloudRadii, DefaultCoverageLeavesNoHolesOnRandomlySampledSurfaces) {
  // 10 to 50 probes per sample: enough to see the 1e-4 of the surface left open at coverage 1.6,
  // some 25% below the smallest coverage found safe (2.1).
  EXPECT_EQ(uncovered_fraction(sphere_scene(), 2'000, 21, 100'000), 0.0);
  EXPECT_EQ(uncovered_fraction(sphere_scene(), 20'000, 22, 200'000), 0.0);
  EXPECT_EQ(uncovered_fraction(torus_scene(), 20'000, 23, 200'000), 0.0);
  EXPECT_EQ(uncovered_fraction(demo_scene(), 30'000, 24, 300'000), 0.0);
}

TEST(CloudRadii, CoverageOfOneLeavesHoles) {
  // The check above can fail: at coverage 1 about 1% of such a surface is uncovered.
  EXPECT_GT(uncovered_fraction(sphere_scene(), 5'000, 25, 100'000, 1.0f), 0.003);
}

TEST(CloudRadii, IsolatedPointsAreCappedAtTheirNeighboursRadiusTimesTheOutlierRatio) {
  // A 20 × 20 grid of spacing h and two stray points 40 h above its centre, h apart (a pair, so
  // that neither is the other's only neighbour). Uncapped, a stray point's mean 5-NN distance
  // is about (h + 4·40h)/5 ≈ 32 h. Its neighbours' median is a grid point's mean distance
  // ((4 + √2)/5 h) or at most a few h more; with the cap the stray radius stays
  // within kDefaultOutlierRatio (4) × that.
  const float h = 0.1f;
  std::vector<Vec3f> p;
  for (int y = 0; y < 20; ++y) {
    for (int x = 0; x < 20; ++x) p.push_back({x * h, y * h, 0.0f});
  }
  p.push_back({1.0f, 1.0f, 40 * h});
  p.push_back({1.0f + h, 1.0f, 40 * h});
  ThreadPool pool(2);
  const std::vector<float> capped = cloud_radii(p, pool, Progress::none(), {.coverage = 1.0f});
  const std::vector<float> uncapped =
      cloud_radii(p, pool, Progress::none(), {.coverage = 1.0f, .outlier_ratio = 0.0f});
  const float grid_mean = (4.0f + std::sqrt(2.0f)) * h / 5.0f;
  for (std::size_t s : {std::size_t{400}, std::size_t{401}}) {
    EXPECT_GT(uncapped[s], 25 * h) << "stray point " << s;
    EXPECT_LE(capped[s], kDefaultOutlierRatio * 1.5f * grid_mean) << "stray point " << s;
  }
  // Grid points keep the defining formula (their neighbours are as dense as they are).
  for (int y = 1; y < 19; ++y) {
    for (int x = 1; x < 19; ++x) {
      EXPECT_NEAR(capped[std::size_t(y * 20 + x)], grid_mean, 1e-6f) << x << "," << y;
    }
  }
}

TEST(CloudRadii, OutlierCapMatchesBruteForceMediansOnRandomPointsWithStrays) {
  // Random samples of a torus and a few clusters of strays above it: every radius is
  // min(mean, ratio × median of the 15 nearest neighbours' means), each found by brute force.
  SurfaceSamples s = sample_scene(torus_scene(), 1200, 21);
  std::vector<Vec3f> p = s.points.positions;
  for (int c = 0; c < 6; ++c) {  // pairs, far from each other
    const float x = 3.0f * float(c % 3) - 3.0f, y = c < 3 ? -2.0f : 2.0f;
    p.push_back({x, y, 1.5f});
    p.push_back({x + 0.05f, y, 1.5f});
  }
  const std::size_t n = p.size(), k = 5, m = kOutlierNeighbours;
  const float ratio = 1.3f;  // low, so that surface points are capped too
  std::vector<std::vector<std::size_t>> nearest(n);
  std::vector<float> mean(n);
  for (std::size_t i = 0; i < n; ++i) {
    std::vector<std::pair<float, std::size_t>> d;
    for (std::size_t j = 0; j < n; ++j) {
      if (j != i) d.push_back({distance(p[i], p[j]), j});
    }
    std::sort(d.begin(), d.end());
    float sum = 0.0f;
    for (std::size_t t = 0; t < k; ++t) sum += d[t].first;
    mean[i] = sum / float(k);
    for (std::size_t t = 0; t < m; ++t) nearest[i].push_back(d[t].second);
  }
  ThreadPool pool(2);
  const std::vector<float> r =
      cloud_radii(p, pool, Progress::none(), {.coverage = 1.0f, .outlier_ratio = ratio});
  std::size_t capped = 0;
  for (std::size_t i = 0; i < n; ++i) {
    std::vector<float> theirs;
    for (const std::size_t j : nearest[i]) theirs.push_back(mean[j]);
    std::sort(theirs.begin(), theirs.end());
    const float cap = ratio * theirs[m / 2];
    capped += cap < mean[i];
    EXPECT_NEAR(r[i], std::min(mean[i], cap), 1e-6f) << "point " << i;
  }
  EXPECT_GT(capped, 30u);  // the strays and some surface points: the cap is exercised
}

TEST(CloudRadii, UniformlySparseRegionsAreNotCapped) {
  // Two grids side by side, one 4× sparser than the other: interior points of the sparse grid
  // (away from the border) keep their full mean distance although it is 4× the dense grid's.
  std::vector<Vec3f> p;
  const float h = 0.1f, H = 0.4f;
  for (int y = 0; y < 40; ++y) {
    for (int x = 0; x < 40; ++x) p.push_back({x * h, y * h, 0.0f});
  }
  const std::size_t sparse_start = p.size();
  for (int y = 0; y < 10; ++y) {
    for (int x = 0; x < 10; ++x) p.push_back({10.0f + x * H, y * H, 0.0f});
  }
  ThreadPool pool(2);
  const std::vector<float> r = cloud_radii(p, pool, Progress::none(), {.coverage = 1.0f});
  const float sparse_mean = (4.0f + std::sqrt(2.0f)) * H / 5.0f;
  for (int y = 1; y < 9; ++y) {
    for (int x = 1; x < 9; ++x) {
      EXPECT_NEAR(r[sparse_start + std::size_t(y * 10 + x)], sparse_mean, 1e-6f) << x << "," << y;
    }
  }
}
