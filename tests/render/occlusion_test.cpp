// Occlusion queries and the culling methods' rules: the depth pyramid against a brute-force scan,
// sphere queries against splats drawn by the fast rasterizer's coverage rule (never optimistic),
// CHC++'s cost model against the spec's worked numbers, and the traversal rules on constructed
// hierarchies with scripted query answers.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <vector>

#include "pointillist/render/occlusion.hpp"
#include "render_test_util.hpp"

using namespace pointillist;
using namespace pointillist::render_test;

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

std::vector<float> random_depths(int w, int h, std::mt19937& rng, float empty_share) {
  std::uniform_real_distribution<float> u(0.0f, 1.0f), depth(1.0f, 10.0f);
  std::vector<float> d(static_cast<std::size_t>(w) * h);
  // Blocks of similar depth with holes, so that tiles of every level vary.
  for (float& v : d) v = u(rng) < empty_share ? kInf : depth(rng);
  return d;
}

}  // namespace

TEST(DepthPyramid, AnswersEveryRectangleAsABruteForceScan) {
  std::mt19937 rng(7);
  for (const auto& [w, h] : {std::pair{64, 48}, std::pair{37, 23}, std::pair{1, 1},
                            std::pair{200, 3}, std::pair{5, 130}}) {
    std::vector<float> depth = random_depths(w, h, rng, 0.02f);
    DepthPyramid pyramid;
    pyramid.reset(depth, w, h);
    std::uniform_int_distribution<int> xs(-5, w + 5), ys(-5, h + 5);
    std::uniform_real_distribution<float> zs(0.5f, 11.0f);
    for (int trial = 0; trial < 3000; ++trial) {
      if (trial % 500 == 250) {
        // Draw something nearer into a rectangle and refresh only there.
        const int x0 = std::clamp(xs(rng), 0, w - 1), y0 = std::clamp(ys(rng), 0, h - 1);
        const int x1 = std::min(w, x0 + 1 + std::abs(xs(rng)) % 9);
        const int y1 = std::min(h, y0 + 1 + std::abs(ys(rng)) % 9);
        for (int y = y0; y < y1; ++y) {
          for (int x = x0; x < x1; ++x) depth[static_cast<std::size_t>(y) * w + x] = 0.75f;
        }
        pyramid.refresh(x0, y0, x1, y1);
      }
      int x0 = xs(rng), x1 = xs(rng), y0 = ys(rng), y1 = ys(rng);
      if (x0 > x1) std::swap(x0, x1);
      if (y0 > y1) std::swap(y0, y1);
      const float z = zs(rng);
      bool want = false;
      for (int y = std::max(y0, 0); y <= std::min(y1, h - 1); ++y) {
        for (int x = std::max(x0, 0); x <= std::min(x1, w - 1); ++x) {
          want = want || depth[static_cast<std::size_t>(y) * w + x] >= z;
        }
      }
      std::uint64_t tested = 0;
      ASSERT_EQ(pyramid.any_at_or_behind(x0, y0, x1, y1, z, tested), want)
          << w << "x" << h << " rect " << x0 << "," << y0 << " " << x1 << "," << y1 << " z " << z;
    }
  }
}

// The fast rasterizer's documented coverage (splat_raster.hpp): the pixels whose centre lies in
// the circle of diameter size_px around the projected centre, or, covering none, the pixel
// holding the centre; a splat can be drawn over a pixel whose depth is not smaller than its own.
bool splat_may_draw(const CameraFrame& cam, Vec3f centre, float radius, float scale,
                    const std::vector<float>& depth) {
  const Vec3f d = centre - cam.eye;
  const float z = dot(d, cam.forward);
  if (!(z > 0)) return false;
  const float x = 0.5f * cam.width + cam.focal_px * dot(d, cam.right) / z;
  const float y = 0.5f * cam.height - cam.focal_px * dot(d, cam.up) / z;
  const float r = scale * radius * cam.focal_px / z;
  bool covers = false, drawn = false;
  for (int j = 0; j < cam.height; ++j) {
    for (int i = 0; i < cam.width; ++i) {
      const float dx = i + 0.5f - x, dy = j + 0.5f - y;
      if (dx * dx + dy * dy <= r * r) {
        covers = true;
        drawn = drawn || depth[static_cast<std::size_t>(j) * cam.width + i] >= z;
      }
    }
  }
  if (!covers) {
    const int i = static_cast<int>(std::floor(x)), j = static_cast<int>(std::floor(y));
    if (i >= 0 && i < cam.width && j >= 0 && j < cam.height) {
      drawn = depth[static_cast<std::size_t>(j) * cam.width + i] >= z;
    }
  }
  return drawn;
}

TEST(OcclusionQuery, IsNeverOptimisticAgainstSplatsInsideTheSphere) {
  std::mt19937 rng(11);
  Camera c = axis_camera(48, 36, 50.0f);
  c.eye = {0.2f, -0.1f, 0.3f};
  c.target = {0.25f, -0.05f, -1.0f};
  const CameraFrame cam = make_camera_frame(c);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), unit(0.0f, 1.0f);
  std::size_t hidden = 0, spheres = 0, wrong = 0;
  for (int buffer = 0; buffer < 20; ++buffer) {
    const std::vector<float> depth = random_depths(cam.width, cam.height, rng, 0.01f);
    DepthPyramid pyramid;
    pyramid.reset(depth, cam.width, cam.height);
    for (int s = 0; s < 5000; ++s, ++spheres) {
      // Spheres from tiny to large, in front of, among and behind the stored depths.
      const float dist = 0.5f + 12.0f * unit(rng);
      const Vec3f centre = cam.eye + cam.forward * dist +
                           cam.right * (0.5f * dist * u(rng)) + cam.up * (0.4f * dist * u(rng));
      const float radius = std::pow(10.0f, -3.0f + 3.0f * unit(rng));
      const float scale = unit(rng) < 0.2f ? 1.0f + 2.0f * unit(rng) : 1.0f;
      std::uint64_t tested = 0;
      const bool answer = bound_may_be_visible(pyramid, cam, {centre, radius}, {scale}, tested);
      hidden += !answer;
      if (answer) continue;
      // Splats inside the sphere (centre offset + radius within it), including the nearest
      // possible one, must all be hidden.
      for (int k = 0; k < 5; ++k) {
        Vec3f dir{u(rng), u(rng), u(rng)};
        if (k == 0) dir = -cam.forward;
        const float len = std::max(length(dir), 1e-6f);
        const float off = (k == 0 ? 1.0f : unit(rng)) * radius;
        const Vec3f p = centre + dir * (off / len);
        const float r = radius - off;
        if (splat_may_draw(cam, p, r, scale, depth)) ++wrong;
      }
    }
  }
  EXPECT_EQ(wrong, 0u);
  // The test has teeth: a good share of the spheres is found hidden.
  EXPECT_GT(hidden, spheres / 10);
}

TEST(OcclusionQuery, BoundsReachingTheEyePlaneAreVisibleWithoutATest) {
  const CameraFrame cam = make_camera_frame(axis_camera(32, 24));
  const std::vector<float> depth(32 * 24, 0.01f);  // everything very near
  DepthPyramid pyramid;
  pyramid.reset(depth, 32, 24);
  std::uint64_t tested = 0;
  EXPECT_TRUE(bound_may_be_visible(pyramid, cam, {{0, 0, -1}, 1.5f}, {}, tested));
  EXPECT_TRUE(bound_may_be_visible(pyramid, cam, {{0, 0, 0.5f}, 1.0f}, {}, tested));
  EXPECT_EQ(tested, 0u);
  EXPECT_FALSE(bound_may_be_visible(pyramid, cam, {{0, 0, -3}, 1.0f}, {}, tested));
}

TEST(ChcCostModel, KeepProbabilityAndGroupsMatchTheSpecsWorkedNumbers) {
  EXPECT_NEAR(keep_probability(1), 0.7325, 5e-5);
  EXPECT_NEAR(keep_probability(2), 0.8953, 5e-5);
  EXPECT_NEAR(keep_probability(3), 0.9551, 5e-5);
  EXPECT_NEAR(keep_probability(5), 0.9853, 5e-5);
  EXPECT_NEAR(keep_probability(10), 0.99, 5e-5);
  const auto groups = [](std::uint64_t i) {
    return multiquery_groups(std::vector<double>(50, keep_probability(i)));
  };
  std::vector<std::size_t> want1(16, 3);
  want1.push_back(2);
  EXPECT_EQ(groups(1), want1);
  EXPECT_EQ(groups(3), std::vector<std::size_t>(10, 5));
  EXPECT_EQ(groups(10), (std::vector<std::size_t>{11, 11, 11, 11, 6}));
  EXPECT_EQ(groups(40), (std::vector<std::size_t>{11, 11, 11, 11, 6}));
}

namespace {

// Scripted queries: a bound's node is its centre's x; a query is visible when any of its nodes
// is in `visible`. Answers become available `latency` flushes after their issue.
class ScriptedQueries final : public OcclusionQueries {
 public:
  std::set<std::uint32_t> visible;
  unsigned latency = 0;
  struct Issued {
    std::vector<std::uint32_t> nodes;
    std::uint64_t flushes_before;  // flushes done when it was issued
  };
  std::vector<Issued> issued;
  std::vector<std::uint32_t> drawn;  // nodes in the order they were flushed
  std::uint64_t flushes = 0;
  std::uint64_t frame_start = 0;  // flushes when the frame began

  QueryId issue(std::span<const QueryBound> bounds) override {
    if (!queue_.empty()) flush();
    Issued q{{}, flushes};
    bool vis = false;
    for (const QueryBound& b : bounds) {
      const auto n = static_cast<std::uint32_t>(b.center.x);
      q.nodes.push_back(n);
      vis = vis || visible.count(n) > 0;
    }
    issued.push_back(q);
    answers_.push_back({flushes + latency, vis});
    return static_cast<QueryId>(answers_.size() - 1);
  }
  bool poll(QueryId id) const override { return flushes >= answers_[id].first; }
  std::uint32_t result(QueryId id) override {
    while (!poll(id)) flush();
    return answers_[id].second;
  }
  void enqueue_render(std::uint32_t node) override { queue_.push_back(node); }
  void flush() override {
    drawn.insert(drawn.end(), queue_.begin(), queue_.end());
    queue_.clear();
    ++flushes;
  }
  void new_frame() {
    issued.clear();
    drawn.clear();
    frame_start = flushes;
  }

 private:
  std::vector<std::uint32_t> queue_;
  std::vector<std::pair<std::uint64_t, bool>> answers_;
};

// A root (node 0) over `leaves` leaves (nodes 1..leaves), leaf k at distance k.
struct Flat {
  CullHierarchy h;
  CullCallbacks cb;
  CullState state;
  explicit Flat(std::uint32_t leaves) {
    h.nodes.resize(leaves + 1);
    h.nodes[0].first_child = 0;
    h.nodes[0].child_count = leaves;
    h.nodes[0].culling_leaves = leaves;
    for (std::uint32_t k = 1; k <= leaves; ++k) {
      h.nodes[k].bound = {{float(k), 0, 0}, 0.1f};
      h.nodes[k].parent = 0;
      h.children.push_back(k);
    }
    h.nodes[0].bound = {{0, 0, 0}, 1000.0f};
    cb.visit = [](std::uint32_t n) {
      CullCallbacks::Visit v;
      v.kind = n == 0 ? CullCallbacks::Kind::Interior : CullCallbacks::Kind::Leaf;
      v.distance = float(n);
      v.near = n == 0;  // the root holds the eye: opened without a query
      return v;
    };
  }
  OcclusionStats frame(const OcclusionSettings& s, ScriptedQueries& q) {
    q.new_frame();
    OcclusionStats stats;
    cull_frame(h, cb, s, q, state, stats);
    return stats;
  }
};

std::vector<std::uint32_t> sorted(std::vector<std::uint32_t> v) {
  std::sort(v.begin(), v.end());
  return v;
}

OcclusionSettings chcpp() {
  OcclusionSettings s;
  s.method = OcclusionMethod::ChcPlusPlus;
  s.randomized = false;
  return s;
}

}  // namespace

TEST(ChcRules, VisibleLeavesAreDrawnAndKeptVisibleWithoutWaitingNextFrame) {
  Flat f(7);
  ScriptedQueries q;
  q.visible = {2, 5};
  OcclusionSettings s = chcpp();
  f.frame(s, q);
  EXPECT_EQ(sorted(q.drawn), (std::vector<std::uint32_t>{2, 5}));
  // Frame 2: 2 and 5 were visible, so they are drawn before any query of this frame is issued
  // (persistence), and are not queried again before n_av frames (no v-queries yet).
  const OcclusionStats st = f.frame(s, q);
  ASSERT_FALSE(q.issued.empty());
  EXPECT_EQ(q.issued.front().flushes_before, q.frame_start + 1);  // the first issue flushed them
  EXPECT_EQ(sorted(q.drawn), (std::vector<std::uint32_t>{2, 5}));
  EXPECT_EQ(st.v_queries, 0u);
  EXPECT_EQ(st.queries_skipped, 2u);
  for (const auto& issued : q.issued) {
    for (std::uint32_t n : issued.nodes) EXPECT_TRUE(n != 2 && n != 5) << n;
  }
}

TEST(ChcRules, PreviouslyHiddenNodesAreQueriedInBatchesOfB) {
  // Leaves 1 and 4 are visible. A visible leaf is queued for drawing, and the next issue flushes
  // the queue first (R3), so the flush count at each issue shows how the queries were grouped.
  const auto flushes_at_issue = [](OcclusionMethod m) {
    Flat f(7);
    ScriptedQueries q;
    q.visible = {1, 4};
    OcclusionSettings s = chcpp();
    s.method = m;
    s.batch = 3;
    s.multiqueries = false;
    f.frame(s, q);
    std::vector<std::uint64_t> at;
    std::vector<std::uint32_t> order;
    for (const auto& i : q.issued) {
      at.push_back(i.flushes_before - q.frame_start);
      order.push_back(i.nodes[0]);
    }
    EXPECT_EQ(order, (std::vector<std::uint32_t>{1, 2, 3, 4, 5, 6, 7})) << name(m);
    EXPECT_EQ(sorted(q.drawn), (std::vector<std::uint32_t>{1, 4})) << name(m);
    return at;
  };
  // CHC++ (R1, b = 3): nodes 1–3 together, then 4–6 after drawing 1, then 7 after drawing 4.
  EXPECT_EQ(flushes_at_issue(OcclusionMethod::ChcPlusPlus),
            (std::vector<std::uint64_t>{0, 0, 0, 1, 1, 1, 2}));
  // CHC: each node as it is reached, so node 1's drawing comes before node 2's query.
  EXPECT_EQ(flushes_at_issue(OcclusionMethod::Chc),
            (std::vector<std::uint64_t>{0, 1, 1, 1, 2, 2, 2}));
}

TEST(ChcRules, AFailedMultiqueryReissuesEachOfItsNodes) {
  Flat f(50);
  ScriptedQueries q;
  OcclusionSettings s = chcpp();
  s.split_failed = false;  // the paper's rule
  for (int frame = 0; frame < 11; ++frame) f.frame(s, q);  // all hidden: i grows to 11
  q.visible = {5};
  const OcclusionStats st = f.frame(s, q);
  // pkeep(12) ≈ 0.99: groups of 11, 11, 11, 11, 6 by node order; node 5's group fails and its
  // 11 nodes are queried one by one.
  EXPECT_EQ(st.queries_multi, 5u);
  EXPECT_EQ(st.multiquery_nodes, 50u);
  EXPECT_EQ(st.multiquery_failed, 1u);
  EXPECT_EQ(st.queries_single, 11u);
  std::vector<std::uint32_t> singles;
  for (const auto& i : q.issued) {
    if (i.nodes.size() == 1) singles.push_back(i.nodes[0]);
  }
  EXPECT_EQ(sorted(singles), (std::vector<std::uint32_t>{1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11}));
  EXPECT_EQ(q.drawn, (std::vector<std::uint32_t>{5}));
}

TEST(ChcRules, AFailedMultiqueryOfLikelyHiddenNodesIsQueriedAgainInHalves) {
  Flat f(50);
  ScriptedQueries q;
  OcclusionSettings s = chcpp();
  for (int frame = 0; frame < 11; ++frame) f.frame(s, q);  // all hidden: i grows to 11
  q.visible = {5};
  const OcclusionStats st = f.frame(s, q);
  // The first query holding node 5 is the failed group; every later query is a half of a
  // failed one: the half holding 5 (which fails again) and its sibling (hidden), down to {5}.
  std::size_t first = 0;
  while (first < q.issued.size() &&
         std::count(q.issued[first].nodes.begin(), q.issued[first].nodes.end(), 5u) == 0) {
    ++first;
  }
  ASSERT_LT(first, q.issued.size());
  std::vector<std::uint32_t> failed = q.issued[first].nodes;
  ASSERT_GT(failed.size(), 2u);
  // At pkeep ≈ 0.99 a failed group of four or more is halved; a group of three f fails is
  // cheaper node by node (3·f queries against 2·f and then 2·(2f/3) for its failing pair).
  std::vector<std::vector<std::uint32_t>> expected;
  std::uint64_t failed_groups = 0;
  while (failed.size() > 1) {
    ++failed_groups;
    if (failed.size() <= 3) {
      for (std::uint32_t n : failed) expected.push_back({n});
      break;
    }
    const std::size_t half = (failed.size() + 1) / 2;
    std::vector<std::uint32_t> a(failed.begin(), failed.begin() + half);
    std::vector<std::uint32_t> b(failed.begin() + half, failed.end());
    expected.push_back(a);
    expected.push_back(b);
    failed = std::count(a.begin(), a.end(), 5u) ? a : b;
  }
  std::vector<std::vector<std::uint32_t>> later;
  std::set<std::uint32_t> covered;
  for (std::size_t k = 0; k < q.issued.size(); ++k) {
    for (std::uint32_t n : q.issued[k].nodes) covered.insert(n);
    if (k > first && q.issued[k].flushes_before >= q.issued[first].flushes_before) {
      const auto& nodes = q.issued[k].nodes;
      // Queries of the other first-round groups are not halves; skip them.
      if (std::count(q.issued[first].nodes.begin(), q.issued[first].nodes.end(), nodes[0])) {
        later.push_back(nodes);
      }
    }
  }
  EXPECT_EQ(later, expected);
  EXPECT_EQ(st.multiquery_failed, failed_groups);
  EXPECT_EQ(covered.size(), 50u);  // every node was in some query
  EXPECT_EQ(q.drawn, (std::vector<std::uint32_t>{5}));
  // Fewer queries than re-querying each node of the failed group.
  EXPECT_LT(expected.size(), q.issued[first].nodes.size());
}

TEST(ChcCostModel, TheHalvingRulesCostIsTheExpectedNumberOfQueriesOfTheBestPlan) {
  // Oracle: for every plan (each group of three or more in the halving tree either re-queries
  // its nodes one by one or queries its halves when it fails), enumerate every outcome (each
  // node stays hidden with its pkeep, independently), count the queries the plan makes, weight
  // by the outcome's probability; the cost is the smallest expectation over the plans.
  const auto best_plan = [](const std::vector<double>& keep) {
    const std::size_t m = keep.size();
    // The groups of three or more in the halving tree, in a fixed order.
    std::vector<std::pair<std::size_t, std::size_t>> splittable;
    std::vector<std::pair<std::size_t, std::size_t>> todo{{0, m}};
    while (!todo.empty()) {
      const auto [lo, hi] = todo.back();
      todo.pop_back();
      if (hi - lo < 3) continue;
      splittable.push_back({lo, hi});
      const std::size_t mid = lo + (hi - lo + 1) / 2;
      todo.push_back({lo, mid});
      todo.push_back({mid, hi});
    }
    double best = 1e300;
    for (std::uint32_t plan = 0; plan < (1u << splittable.size()); ++plan) {
      const auto halves = [&](std::size_t lo, std::size_t hi) {
        for (std::size_t k = 0; k < splittable.size(); ++k) {
          if (splittable[k] == std::pair{lo, hi}) return (plan >> k & 1) != 0;
        }
        return false;
      };
      double expected = 0;
      for (std::uint32_t mask = 0; mask < (1u << m); ++mask) {  // bit set: turned visible
        double p = 1;
        for (std::size_t k = 0; k < m; ++k) p *= (mask >> k & 1) ? 1 - keep[k] : keep[k];
        int queries = 0;
        std::vector<std::pair<std::size_t, std::size_t>> q{{0, m}};
        while (!q.empty()) {
          const auto [lo, hi] = q.back();
          q.pop_back();
          ++queries;
          bool visible = false;
          for (std::size_t k = lo; k < hi; ++k) visible = visible || (mask >> k & 1);
          if (!visible || hi - lo == 1) continue;
          if (halves(lo, hi)) {
            const std::size_t mid = lo + (hi - lo + 1) / 2;
            q.push_back({lo, mid});
            q.push_back({mid, hi});
          } else {
            for (std::size_t k = lo; k < hi; ++k) q.push_back({k, k + 1});
          }
        }
        expected += p * queries;
      }
      best = std::min(best, expected);
    }
    return best;
  };
  std::uint64_t x = 7;
  for (std::size_t m = 1; m <= 9; ++m) {
    for (int trial = 0; trial < 3; ++trial) {
      std::vector<double> keep(m);
      for (double& k : keep) {
        x = x * 6364136223846793005ull + 1442695040888963407ull;
        k = (trial == 0 ? 0.3 : 0.9) + (trial == 0 ? 0.69 : 0.099) *
                                           static_cast<double>(x >> 11) / 9007199254740992.0;
      }
      std::sort(keep.rbegin(), keep.rend());
      EXPECT_NEAR(split_query_cost(keep), best_plan(keep), 1e-9) << m << " " << trial;
    }
  }
  // Re-querying each node is one of the plans, so a group never costs more than the paper's
  // C(M); likely-hidden groups are split, likely-visible ones are not; each group is the
  // prefix of largest |M| / C(M).
  for (const std::uint64_t i : {1u, 3u, 10u}) {
    const std::vector<double> keep(50, keep_probability(i));
    const std::span<const double> all(keep);
    for (std::size_t size = 1; size <= 50; ++size) {
      EXPECT_LE(split_query_cost(all.first(size)),
                1.0 + (1.0 - std::pow(keep[0], double(size))) * double(size) + 1e-12);
    }
    const auto groups = multiquery_groups(keep, true);
    for (std::size_t size = 1; size <= 50; ++size) {
      EXPECT_GE(groups[0] / split_query_cost(all.first(groups[0])),
                size / split_query_cost(all.first(size)) - 1e-12);
    }
  }
  EXPECT_TRUE(split_failed_group(std::vector<double>(8, keep_probability(10))));
  EXPECT_FALSE(split_failed_group(std::vector<double>(8, 0.3)));
}

TEST(ChcRules, AVisibleLeafsRequeryIntervalDoublesWhileItStaysVisible) {
  Flat f(1);
  ScriptedQueries q;
  q.visible = {1};
  OcclusionSettings s = chcpp();
  s.requery_frames = 5;
  s.requery_doublings = 2;
  std::vector<std::uint64_t> queried;
  for (std::uint64_t frame = 1; frame <= 70; ++frame) {
    if (frame == 50) q.visible.clear();  // hidden from frame 50: found at its next query
    f.frame(s, q);
    if (!q.issued.empty()) queried.push_back(frame);
  }
  // Found visible at 1; re-queried n_av later (6), then at intervals 5, 10, 20, 20 (the cap,
  // n_av · 2²); the query at 61 finds it hidden, and from then on it is queried every frame.
  ASSERT_GE(queried.size(), 7u);
  EXPECT_EQ(std::vector<std::uint64_t>(queried.begin(), queried.begin() + 7),
            (std::vector<std::uint64_t>{1, 6, 11, 21, 41, 61, 62}));
}

TEST(ChcRules, VisibleLeavesAreRequeriedEveryNavFramesOrAfterARandomFirstOffset) {
  for (bool randomized : {false, true}) {
    std::set<std::uint64_t> first_offsets;
    for (std::uint64_t seed = 1; seed <= 40; ++seed) {
      Flat f(1);
      ScriptedQueries q;
      q.visible = {1};
      OcclusionSettings s = chcpp();
      s.requery_frames = 5;
      s.requery_doublings = 0;  // the paper's fixed interval
      s.randomized = randomized;
      s.seed = seed;
      std::vector<std::uint64_t> queried;
      for (std::uint64_t frame = 1; frame <= 22; ++frame) {
        f.frame(s, q);
        if (!q.issued.empty()) queried.push_back(frame);
        EXPECT_EQ(q.drawn, (std::vector<std::uint32_t>{1})) << frame;
      }
      ASSERT_GE(queried.size(), 3u);
      EXPECT_EQ(queried[0], 1u);
      const std::uint64_t offset = queried[1] - queried[0];
      first_offsets.insert(offset);
      EXPECT_LE(offset, 5u);
      if (!randomized) {
        EXPECT_EQ(offset, 5u);
      }
      for (std::size_t k = 2; k < queried.size(); ++k) EXPECT_EQ(queried[k] - queried[k - 1], 5u);
    }
    // R5 spreads the first re-query over [0, n_av]; without it every node waits n_av.
    if (randomized) {
      EXPECT_GE(first_offsets.size(), 4u);
    } else {
      EXPECT_EQ(first_offsets.size(), 1u);
    }
  }
}

TEST(ChcRules, StopAndWaitQueriesEveryNodeAndWaitsForEachAnswer) {
  Flat f(6);
  ScriptedQueries q;
  q.latency = 2;
  q.visible = {3, 4};
  OcclusionSettings s;
  s.method = OcclusionMethod::StopAndWait;
  const OcclusionStats st = f.frame(s, q);
  EXPECT_EQ(st.queries_single, 6u);
  EXPECT_EQ(sorted(q.drawn), (std::vector<std::uint32_t>{3, 4}));
  // Each query is issued only after the previous one was answered (two flushes later).
  for (std::size_t k = 1; k < q.issued.size(); ++k) {
    EXPECT_GE(q.issued[k].flushes_before, q.issued[k - 1].flushes_before + 2);
  }
}

TEST(ChcRules, WithLatencyEveryVisibleLeafIsStillDrawnInTheFrame) {
  for (unsigned latency : {1u, 3u}) {
    for (OcclusionMethod m : {OcclusionMethod::Chc, OcclusionMethod::ChcPlusPlus}) {
      Flat f(30);
      ScriptedQueries q;
      q.latency = latency;
      q.visible = {1, 7, 8, 29};
      OcclusionSettings s = chcpp();
      s.method = m;
      s.batch = 4;
      for (int frame = 0; frame < 4; ++frame) {
        f.frame(s, q);
        EXPECT_EQ(sorted(q.drawn), (std::vector<std::uint32_t>{1, 7, 8, 29}))
            << name(m) << " latency " << latency << " frame " << frame;
      }
    }
  }
}
