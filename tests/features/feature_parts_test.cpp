// Features found part by part (feature_parts.hpp) against compute_features over the whole set:
// the CSG scenes of spec §4.2 cut into boxes, each box's splats with the halo that
// feature_halo_reach asks for, must give every splat the whole set's planes and surface id, bit
// for bit, and the same statistics.
#include "pointillist/features/feature_parts.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <numeric>
#include <random>

#include "pointillist/core/error.hpp"
#include "pointillist/prep/radii.hpp"
#include "pointillist/scene/csg.hpp"

using namespace pointillist;

namespace {

struct Splats {
  std::vector<Vec3f> centers, normals;
  std::vector<float> radii;
};

// A scene's samples in a shuffled order (so that every box's splats interleave with the others'
// in the whole set's order), with cloud radii.
Splats scene_splats(const std::string& id, std::uint64_t seed) {
  const CsgSamples samples = sample_csg(csg_scene(id), SamplingMode::Random, 17);
  ThreadPool pool(2);
  const std::vector<float> radii =
      cloud_radii(samples.points.positions, pool, Progress::none(), CloudRadiusOptions{});
  std::vector<std::size_t> order(radii.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::shuffle(order.begin(), order.end(), std::mt19937_64(seed));
  Splats s;
  for (const std::size_t i : order) {
    s.centers.push_back(samples.points.positions[i]);
    s.normals.push_back(samples.points.normals[i]);
    s.radii.push_back(radii[i]);
  }
  return s;
}

// The features of `s` found in cells × cells × cells boxes of its bounds, then joined.
FeatureData by_parts(const Splats& s, int cells, const FeatureOptions& options, ThreadPool& pool,
                     std::size_t* largest_part = nullptr) {
  const std::size_t n = s.centers.size();
  Aabb box;
  for (const Vec3f c : s.centers) box.extend(c);
  const Vec3f extent = box.extent();
  const auto cell_of = [&](Vec3f c) {
    int index = 0;
    for (int a = 2; a >= 0; --a) {
      const int k = std::clamp(int((c[a] - box.lo[a]) / extent[a] * cells), 0, cells - 1);
      index = index * cells + k;
    }
    return index;
  };
  float r_max = 0;
  for (const float r : s.radii) r_max = std::max(r_max, r * options.radius_scale);

  // Pass 1: the spread of every part, added up, decides the threshold.
  const int part_count = cells * cells * cells;
  struct Part {
    std::vector<Vec3f> centers, normals;
    std::vector<float> radii;
    std::vector<std::uint64_t> keys;
    std::vector<std::uint8_t> owned;
    FeaturePartInput input() const { return {centers, normals, radii, keys, owned}; }
  };
  std::vector<Part> parts(static_cast<std::size_t>(part_count));
  for (int p = 0; p < part_count; ++p) {
    Aabb own;
    float r_own = 0;
    for (std::size_t i = 0; i < n; ++i) {
      if (cell_of(s.centers[i]) != p) continue;
      own.extend(s.centers[i]);
      r_own = std::max(r_own, s.radii[i] * options.radius_scale);
    }
    if (own.lo.x > own.hi.x) continue;
    const float reach = feature_halo_reach(r_own, r_max);
    Part& part = parts[std::size_t(p)];
    for (std::size_t i = 0; i < n; ++i) {
      const bool mine = cell_of(s.centers[i]) == p;
      const float d2 = own.distance_squared(s.centers[i]);
      const float limit = reach + s.radii[i] * options.radius_scale;
      if (!mine && !(d2 < limit * limit)) continue;
      part.centers.push_back(s.centers[i]);
      part.normals.push_back(s.normals[i]);
      part.radii.push_back(s.radii[i]);
      part.keys.push_back(i);
      part.owned.push_back(mine ? 1 : 0);
    }
    if (largest_part) *largest_part = std::max(*largest_part, part.keys.size());
  }
  SpreadHistogram spread;
  for (const Part& part : parts) {
    if (part.keys.empty()) continue;
    spread.add(feature_part_spread(part.input(), options, pool).histogram);
  }
  FeatureStats spread_stats;
  const FeatureOptions decided = adapt_sharp_threshold(options, spread, spread_stats);

  // Pass 2: each part's own splats, then the join.
  std::vector<FeaturePart> found(parts.size());
  std::vector<const FeaturePart*> pointers;
  std::vector<std::size_t> part_of;  // the part of each pointer
  for (std::size_t p = 0; p < parts.size(); ++p) {
    if (parts[p].keys.empty()) continue;
    found[p] = compute_feature_part(parts[p].input(), decided, pool);
    pointers.push_back(&found[p]);
    part_of.push_back(p);
  }
  // Each part's links against every other part's own splats.
  std::vector<std::pair<PartSurface, PartSurface>> joined;
  for (std::size_t to = 0; to < part_of.size(); ++to) {
    const Part& owner = parts[part_of[to]];
    std::vector<std::uint64_t> keys;
    for (std::size_t i = 0; i < owner.keys.size(); ++i) {
      if (owner.owned[i]) keys.push_back(owner.keys[i]);
    }
    for (std::size_t from = 0; from < part_of.size(); ++from) {
      if (from == to) continue;
      resolve_feature_links(std::uint32_t(from), found[part_of[from]].links, std::uint32_t(to),
                            keys, found[part_of[to]].component, joined);
    }
  }
  const FeatureJoin join = join_feature_parts(pointers, n, joined);
  FeatureData out;
  out.options = decided;
  out.stats = joined_feature_stats(pointers, join, spread_stats);
  out.surface_id.assign(n, 0);
  out.clip_mode.assign(n, ClipMode::None);
  std::vector<std::vector<ClipPlane>> planes(n);
  std::size_t listed = 0;
  for (std::size_t p = 0, q = 0; p < parts.size(); ++p) {
    if (parts[p].keys.empty()) continue;
    const FeaturePart& f = found[p];
    std::size_t k = 0;
    for (std::size_t i = 0; i < parts[p].keys.size(); ++i) {
      if (!parts[p].owned[i]) continue;
      const std::uint64_t key = parts[p].keys[i];
      out.surface_id[key] = join.surface[q][f.component[k]];
      out.clip_mode[key] = f.clip_mode[k];
      planes[key].assign(f.clip_planes.begin() + f.clip_offset[k],
                         f.clip_planes.begin() + f.clip_offset[k + 1]);
      ++k, ++listed;
    }
    ++q;
  }
  EXPECT_EQ(listed, n) << "every splat belongs to one part";
  out.clip_offset.push_back(0);
  for (const auto& list : planes) {
    out.clip_planes.insert(out.clip_planes.end(), list.begin(), list.end());
    out.clip_offset.push_back(static_cast<std::uint32_t>(out.clip_planes.size()));
  }
  return out;
}

void expect_same(const FeatureData& whole, const FeatureData& parts, const std::string& what) {
  EXPECT_EQ(whole.options.sharp_threshold, parts.options.sharp_threshold) << what;
  EXPECT_EQ(whole.surface_id, parts.surface_id) << what;
  EXPECT_EQ(whole.clip_mode, parts.clip_mode) << what;
  EXPECT_EQ(whole.clip_offset, parts.clip_offset) << what;
  ASSERT_EQ(whole.clip_planes.size(), parts.clip_planes.size()) << what;
  std::size_t differing = 0;
  for (std::size_t k = 0; k < whole.clip_planes.size(); ++k) {
    const ClipPlane a = whole.clip_planes[k], b = parts.clip_planes[k];
    differing += std::bit_cast<std::uint32_t>(a.n.x) != std::bit_cast<std::uint32_t>(b.n.x) ||
                 std::bit_cast<std::uint32_t>(a.n.y) != std::bit_cast<std::uint32_t>(b.n.y) ||
                 std::bit_cast<std::uint32_t>(a.n.z) != std::bit_cast<std::uint32_t>(b.n.z) ||
                 std::bit_cast<std::uint32_t>(a.h) != std::bit_cast<std::uint32_t>(b.h);
  }
  EXPECT_EQ(differing, 0u) << what << ": planes not bit for bit those of the whole set";
  const FeatureStats& s = whole.stats;
  const FeatureStats& t = parts.stats;
  EXPECT_EQ(s.splats, t.splats) << what;
  EXPECT_EQ(s.edges, t.edges) << what;
  EXPECT_EQ(s.sharp_edges, t.sharp_edges) << what;
  EXPECT_EQ(s.crossing_edges, t.crossing_edges) << what;
  EXPECT_EQ(s.antiparallel_edges, t.antiparallel_edges) << what;
  EXPECT_EQ(s.candidates, t.candidates) << what;
  EXPECT_EQ(s.clipped, t.clipped) << what;
  EXPECT_EQ(s.pass_through, t.pass_through) << what;
  EXPECT_EQ(s.capped, t.capped) << what;
  EXPECT_EQ(s.nearest_rule, t.nearest_rule) << what;
  EXPECT_EQ(s.spread_deg, t.spread_deg) << what;
  EXPECT_EQ(s.threshold_raised, t.threshold_raised) << what;
  EXPECT_EQ(s.segments, t.segments) << what;
  EXPECT_EQ(s.large_segments, t.large_segments) << what;
  EXPECT_EQ(s.plane_histogram, t.plane_histogram) << what;
}

TEST(FeatureParts, BoxesWithTheirHalosGiveTheWholeSetsFeatures) {
  ThreadPool pool(2);
  // A union with intersection curves, crossed cylinders (curved creases, six surfaces), a noisy
  // cube (the threshold rises above its spread), a difference (reflex corners).
  for (const char* id : {"T5", "T10", "T14-5", "T7"}) {
    const Splats s = scene_splats(id, 5);
    const FeatureData whole = compute_features(s.centers, s.normals, s.radii, pool);
    ASSERT_GT(whole.stats.clipped, 0u) << id;
    for (const int cells : {2, 3}) {
      std::size_t largest = 0;
      const FeatureData parts = by_parts(s, cells, {}, pool, &largest);
      // The parts are real parts: none holds the whole set.
      EXPECT_LT(largest, s.centers.size()) << id;
      expect_same(whole, parts, std::string(id) + " in " + std::to_string(cells) + "^3 boxes");
    }
  }
}

TEST(FeatureParts, EveryRuleAndEdgeTestGivesTheWholeSetsFeatures) {
  ThreadPool pool(2);
  const Splats s = scene_splats("T5", 9);
  for (const ClipRule rule : {ClipRule::Dissertation, ClipRule::Independent,
                              ClipRule::NearestPartner}) {
    FeatureOptions o;
    o.clip_rule = rule;
    o.radius_scale = 1.3f;
    o.clip_margin = 0.1f;
    expect_same(compute_features(s.centers, s.normals, s.radii, pool, o), by_parts(s, 2, o, pool),
                "rule " + std::to_string(int(rule)));
  }
  FeatureOptions linsen;
  linsen.edge_test = EdgeTest::Linsen;
  expect_same(compute_features(s.centers, s.normals, s.radii, pool, linsen),
              by_parts(s, 3, linsen, pool), "Linsen");
}

TEST(FeatureParts, SpreadIsTheQuartileToTheBucketsWidth) {
  // Against the exact quartile of the same cosines (sorted): within the bucket's relative width.
  std::mt19937 random(3);
  std::uniform_real_distribution<float> angle(0.0f, 1.2f);
  std::vector<float> cosines;
  SpreadHistogram a, b;
  for (int k = 0; k < 20000; ++k) {
    const float c = std::cos(angle(random) * angle(random));
    cosines.push_back(c);
    (k % 3 == 0 ? a : b).count(c);
  }
  // Not counted: pairs facing apart; counted as 1: cosines a rounding above it.
  a.count(-0.5f);
  a.count(0.0f);
  SpreadHistogram sum;
  sum.add(a);
  sum.add(b);
  EXPECT_EQ(sum.total(), cosines.size());
  std::sort(cosines.begin(), cosines.end());
  const float exact = cosines[cosines.size() / 4];
  const float found = std::cos(sum.spread());
  EXPECT_NEAR(found, exact, exact * 1.0f / (1 << 15)) << "spread " << sum.spread();

  SpreadHistogram ones;
  ones.count(1.0000001f);
  ones.count(1.0f);
  EXPECT_EQ(ones.spread(), 0.0f);
  EXPECT_EQ(SpreadHistogram{}.spread(), 0.0f);
}

TEST(FeatureParts, LinksJoinTheSurfacesOfTheirSplatsAndIdsFollowFirstSplats) {
  // Part 0 owns keys 0, 1, 4 (surfaces {0, 4} and {1}); part 1 owns 2, 3, 5 (surfaces {3, 5}
  // and {2}). Part 0's surface 0 reaches halo splat 5; part 1's surface 1 reaches 9, which no
  // part owns (outside every part: left alone).
  FeaturePart p0, p1;
  p0.component_first = {0, 1};
  p0.component_size = {2, 1};
  p0.component = {0, 1, 0};  // keys 0, 1, 4
  p0.links = {{.component = 0, .other = 5}};
  p1.component_first = {3, 2};
  p1.component_size = {2, 1};
  p1.component = {1, 0, 0};  // keys 2, 3, 5
  p1.links = {{.component = 1, .other = 9}};
  const std::vector<std::uint64_t> keys0 = {0, 1, 4}, keys1 = {2, 3, 5};
  std::vector<std::pair<PartSurface, PartSurface>> joined;
  resolve_feature_links(0, p0.links, 1, keys1, p1.component, joined);
  resolve_feature_links(1, p1.links, 0, keys0, p0.component, joined);
  ASSERT_EQ(joined.size(), 1u);
  EXPECT_EQ(joined[0].second.part, 1u);
  EXPECT_EQ(joined[0].second.component, 0u);
  const FeaturePart* const parts[] = {&p0, &p1};
  const FeatureJoin join = join_feature_parts(parts, 6, joined);
  ASSERT_EQ(join.segments, 3u);
  // Ids by first splat: {0, 4, 3, 5} first at 0, {1} at 1, {2} at 2.
  EXPECT_EQ(join.surface[0], (std::vector<std::uint32_t>{0, 1}));
  EXPECT_EQ(join.surface[1], (std::vector<std::uint32_t>{0, 2}));
  EXPECT_EQ(join.large_segments, 3u);  // 0.5 % of 6 splats is one splat
  const std::pair<PartSurface, PartSurface> bad[] = {{{0, 0}, {1, 7}}};
  EXPECT_THROW(join_feature_parts(parts, 6, bad), Error);
}

}  // namespace
