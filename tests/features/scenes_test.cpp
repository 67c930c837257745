// compute_features on the CSG scenes of spec §4.2 against their exact faces: which splats need
// clipping (a drawn disc that leaves its face), what part of each disc the planes keep, how the
// splats segment into surfaces (acceptance bars A1, A2, A5, A6, A7, A9 of spec §4.6, on the
// preprocessing).
#include "pointillist/features/features.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <map>
#include <random>

#include "pointillist/prep/radii.hpp"
#include "pointillist/scene/csg.hpp"

using namespace pointillist;

namespace {

struct Prepared {
  CsgScene scene;
  CsgSamples samples;
  std::vector<float> radii;
  FeatureData features;
};

Prepared prepare(const std::string& id, SamplingMode mode, FeatureOptions options = {},
                 unsigned threads = 2) {
  Prepared p;
  p.scene = csg_scene(id);
  p.samples = sample_csg(p.scene, mode, 17);
  ThreadPool pool(threads);
  CloudRadiusOptions radius;
  // J mode: the dissertation's radius (mean 5-NN distance); R mode: Pointillist's default.
  radius.coverage = mode == SamplingMode::Jittered ? 1.0f : kDefaultCloudCoverage;
  p.radii = cloud_radii(p.samples.points.positions, pool, Progress::none(), radius);
  p.features = compute_features(p.samples.points.positions, p.samples.points.normals, p.radii, pool,
                                options);
  return p;
}

struct ClipCheck {
  std::size_t needs = 0, needs_and_clipped = 0;
  std::size_t points = 0, wrong = 0;  // disc points tested, and those the planes get wrong
  double recall() const { return needs ? double(needs_and_clipped) / needs : 1.0; }
  double wrong_share() const { return points ? double(wrong) / points : 0.0; }
};

// Over the splats of planar faces: whether the drawn disc (radius_scale × radius) leaves its
// face (64 rim points just inside the rim, spec §4.5 "ground-truth clip need"), and on a grid of
// disc points away from the face's border, whether the clip test keeps exactly the face.
// Faces on one plane that touch are one surface (the step's front faces): a point is on the
// splat's surface when one of the faces on its plane contains it.
ClipCheck check_clipping(const Prepared& p) {
  ClipCheck c;
  const float scale = p.features.options.radius_scale;
  std::vector<std::vector<std::uint32_t>> same_plane(p.scene.label_count());
  std::vector<std::pair<Vec3f, float>> plane_of(p.scene.label_count(), {Vec3f{}, NAN});
  for (std::size_t i = 0; i < p.samples.labels.size(); ++i) {
    const Vec3f n = p.samples.points.normals[i];
    plane_of[p.samples.labels[i]] = {n, dot(n, p.samples.points.positions[i])};
  }
  for (std::uint32_t a = 0; a < same_plane.size(); ++a) {
    for (std::uint32_t b = 0; b < same_plane.size(); ++b) {
      if (plane_of[a].first == plane_of[b].first &&
          std::fabs(plane_of[a].second - plane_of[b].second) < 1e-5f) {
        same_plane[a].push_back(b);
      }
    }
  }
  const auto on_surface = [&](std::uint32_t label, Vec3f x) {
    for (std::uint32_t l : same_plane[label]) {
      if (csg_face_contains(p.scene, l, x)) return true;
    }
    return false;
  };
  for (std::size_t i = 0; i < p.samples.labels.size(); ++i) {
    const std::uint32_t label = p.samples.labels[i];
    if (!csg_face_is_planar(p.scene, label)) continue;
    const Vec3f center = p.samples.points.positions[i], n = p.samples.points.normals[i];
    const float r = p.radii[i] * scale;
    const TangentFrame f = tangent_frame(n);
    bool needs = false;
    for (int k = 0; k < 64 && !needs; ++k) {
      const float a = k * 2 * kPi / 64;
      const Vec3f rim = center + (f.u * std::cos(a) + f.v * std::sin(a)) * (r * (1 - 1e-4f));
      needs = !on_surface(label, rim);
    }
    const bool clipped = p.features.clip_mode[i] != ClipMode::None;
    c.needs += needs;
    c.needs_and_clipped += needs && clipped;
    if (!needs && !clipped) continue;
    const auto planes = p.features.planes(i);
    constexpr int kSteps = 15;
    for (int a = 0; a < kSteps; ++a) {
      for (int b = 0; b < kSteps; ++b) {
        const float du = (2.0f * a / (kSteps - 1) - 1) * r, dv = (2.0f * b / (kSteps - 1) - 1) * r;
        if (du * du + dv * dv > r * r) continue;
        const Vec3f x = center + f.u * du + f.v * dv;
        const bool in = on_surface(label, x);
        // Skip points within 1e-3·r of the face's border.
        const float e = 1e-3f * r;
        if (on_surface(label, x + f.u * e) != in || on_surface(label, x - f.u * e) != in ||
            on_surface(label, x + f.v * e) != in || on_surface(label, x - f.v * e) != in) {
          continue;
        }
        ++c.points;
        c.wrong += clip_discards(planes, p.features.clip_mode[i], x) == in;
      }
    }
  }
  return c;
}

// Segments with at least 0.5 % of the splats, and the share of splats whose segment's majority
// plane (normal and offset of a planar face; faces on one plane that touch form one surface) is
// their own.
struct Segmentation {
  std::size_t large = 0;
  double purity = 0;
};
Segmentation check_segments(const Prepared& p) {
  using Key = std::tuple<int, int, int, int>;
  const auto key = [&](std::size_t i) {
    const Vec3f n = p.samples.points.normals[i];
    const float h = dot(n, p.samples.points.positions[i]);
    return Key{int(std::lround(n.x * 100)), int(std::lround(n.y * 100)), int(std::lround(n.z * 100)),
               int(std::lround(h * 100))};
  };
  std::map<std::uint32_t, std::map<Key, std::size_t>> votes;
  for (std::size_t i = 0; i < p.samples.labels.size(); ++i) ++votes[p.features.surface_id[i]][key(i)];
  Segmentation s;
  std::size_t pure = 0, total = p.samples.labels.size();
  for (const auto& [id, keys] : votes) {
    std::size_t size = 0, best = 0;
    for (const auto& [k, count] : keys) size += count, best = std::max(best, count);
    s.large += size * 200 >= total;
    pure += best;
  }
  s.purity = double(pure) / total;
  return s;
}

// Splats whose segment's majority ground-truth label is not their own (1 − purity, as a count).
std::size_t off_label(const FeatureData& f, const std::vector<std::uint32_t>& labels) {
  std::map<std::uint32_t, std::map<std::uint32_t, std::size_t>> votes;
  for (std::size_t i = 0; i < f.size(); ++i) ++votes[f.surface_id[i]][labels[i]];
  std::size_t off = 0;
  for (const auto& [id, counts] : votes) {
    std::size_t best = 0, size = 0;
    for (const auto& [l, n] : counts) best = std::max(best, n), size += n;
    off += size - best;
  }
  return off;
}

void report(const std::string& what, const Prepared& p, const ClipCheck& c) {
  const FeatureStats& s = p.features.stats;
  std::cout << what << ": splats " << s.splats << ", m " << s.mean_degree() << ", sharp "
            << s.sharp_edges << ", crossing " << s.crossing_edges << ", candidates "
            << s.candidates << ", clipped " << s.clipped << ", recall " << c.recall()
            << ", wrong " << c.wrong_share() << ", segments " << s.large_segments << "\n";
}

TEST(FeatureScenes, PlanarCreasesAreFoundAndClippedExactly) {
  for (const char* id : {"T1", "T2", "T8"}) {
    for (SamplingMode mode : {SamplingMode::Jittered, SamplingMode::Random}) {
      const Prepared p = prepare(id, mode);
      const ClipCheck c = check_clipping(p);
      report(std::string(id) + (mode == SamplingMode::Jittered ? " J" : " R"), p, c);
      EXPECT_GT(c.needs, 200u) << id;
      EXPECT_GE(c.recall(), 0.995) << id;  // A1
      // A2: the planes are the faces' planes. Not on the jittered cube of mixed density: its
      // sparse faces' discs take their radius from the dense face's samples and stop short of
      // the edge, and the dense face's discs keep what they leave open (keep_uncovered).
      if (std::string(id) == "T2" && mode == SamplingMode::Jittered) continue;
      EXPECT_LE(c.wrong_share(), 0.002) << id;
    }
  }
}

TEST(FeatureScenes, SegmentsAreTheFaces) {
  // T1: 6 faces; T8: 11 faces of which three pairs are coplanar and touch, so 8 surfaces.
  for (const auto& [id, faces] :
       {std::pair<const char*, std::size_t>{"T1", 6}, {"T2", 6}, {"T8", 8}}) {
    for (SamplingMode mode : {SamplingMode::Jittered, SamplingMode::Random}) {
      const Segmentation s = check_segments(prepare(id, mode));
      EXPECT_EQ(s.large, faces) << id;
      EXPECT_GE(s.purity, 0.995) << id;
    }
  }
}

TEST(FeatureScenes, InterpenetratingSpheresAreSeparatedButNotClipped) {
  for (SamplingMode mode : {SamplingMode::Jittered, SamplingMode::Random}) {
    const Prepared p = prepare("T9", mode);
    const FeatureStats& s = p.features.stats;
    EXPECT_GT(s.crossing_edges, 100u);  // the spheres' discs cross along the curve
    std::cout << "T9 " << (mode == SamplingMode::Jittered ? "J" : "R") << ": clipped " << s.clipped
              << " of " << s.splats << ", crossing edges " << s.crossing_edges << "\n";
    EXPECT_LE(s.clipped, s.splats / 100) << "false clips (A1: at most 1 %)";
    EXPECT_EQ(s.large_segments, 2u);
    // Each large segment is one sphere.
    EXPECT_LE(off_label(p.features, p.samples.labels), s.splats / 200);
  }
}

TEST(FeatureScenes, CrossedCylindersAreSixSurfacesWithLargeDiscs) {
  // T10's cylinders (radii 0.5 and 0.35) have parallel normals 0.15 apart where one passes
  // inside the other; random sampling's discs make those splats neighbours, and their edges
  // must not join the two lateral surfaces (spec §4.6 A9: segment count exact, purity).
  for (SamplingMode mode : {SamplingMode::Jittered, SamplingMode::Random}) {
    for (unsigned seed : {17u, 1u, 9u}) {
      Prepared p;
      p.scene = csg_scene("T10");
      p.samples = sample_csg(p.scene, mode, seed);
      ThreadPool pool(2);
      CloudRadiusOptions radius;
      radius.coverage = mode == SamplingMode::Jittered ? 1.0f : kDefaultCloudCoverage;
      p.radii = cloud_radii(p.samples.points.positions, pool, Progress::none(), radius);
      p.features = compute_features(p.samples.points.positions, p.samples.points.normals, p.radii,
                                    pool);
      EXPECT_EQ(p.features.stats.large_segments, 6u) << seed;
      // Purity >= 99.5 %.
      EXPECT_LE(off_label(p.features, p.samples.labels), p.features.size() / 200) << seed;
    }
  }
}

TEST(FeatureScenes, ThinSlabFacesNeverClipEachOther) {
  const Prepared p = prepare("T11", SamplingMode::Jittered);
  EXPECT_GT(p.features.stats.antiparallel_edges, 1000u);  // front and back splats are neighbours
  for (std::size_t i = 0; i < p.features.size(); ++i) {
    const Vec3f n = p.samples.points.normals[i];
    for (const ClipPlane& plane : p.features.planes(i)) {
      ASSERT_TRUE(std::isfinite(plane.h) && is_finite(plane.n)) << "splat " << i;
      // No plane of the opposite face: a plane parallel to the splat.
      EXPECT_LT(std::fabs(dot(normalized(plane.n), n)), 0.5f) << "splat " << i;
    }
  }
  const ClipCheck c = check_clipping(p);
  EXPECT_GE(c.recall(), 0.995);
  EXPECT_LE(c.wrong_share(), 0.002);
}

TEST(FeatureScenes, SmoothSurfacesHaveNoSharpEdges) {
  // A7: the sphere sampled near-uniformly, at the default threshold.
  const Prepared j = prepare("T13", SamplingMode::Jittered);
  EXPECT_EQ(j.features.stats.sharp_edges, 0u);
  EXPECT_EQ(j.features.stats.clipped, 0u);
  EXPECT_EQ(j.features.stats.segments, 1u);
  // R mode has discs 2.5 times larger: report, and hold it to what the spec asks (none).
  const Prepared r = prepare("T13", SamplingMode::Random);
  std::cout << "T13 R: sharp edges " << r.features.stats.sharp_edges << ", m "
            << r.features.stats.mean_degree() << "\n";
  EXPECT_EQ(r.features.stats.clipped, 0u);
}

TEST(FeatureScenes, SideTestFindsAtLeastTheClipsLinsenFinds) {
  // A1's comparison: Linsen's gap test (B3's) misses clips that the side test (B4's) makes.
  FeatureOptions linsen;
  linsen.edge_test = EdgeTest::Linsen;
  for (SamplingMode mode : {SamplingMode::Jittered, SamplingMode::Random}) {
    const ClipCheck side = check_clipping(prepare("T1", mode));
    const ClipCheck gap = check_clipping(prepare("T1", mode, linsen));
    std::cout << "T1 " << (mode == SamplingMode::Jittered ? "J" : "R") << " recall: side "
              << side.recall() << ", Linsen " << gap.recall() << "\n";
    EXPECT_GE(side.recall(), gap.recall());
  }
}

TEST(FeatureScenes, WedgeSweepFindsTheHingeDownToTheThreshold) {
  // A11 (spec T12): two strips at interior dihedral θ have normals −cos θ apart. Below the
  // default threshold w_s = 0.9 (θ < 154°) the hinge's discs are sharp edges that cross and
  // clip, and the strips are two surfaces; at 165° (w = 0.966) nothing is sharp and the wedge
  // is one surface. The table of spec §4.6 A11, in the dissertation's terms.
  std::cout << "theta  E_s/E  E_ir/E_s  P_c/P  P_r/P_c  segments\n";
  for (const int degrees : {20, 30, 45, 60, 90, 120, 150, 165}) {
    for (SamplingMode mode : {SamplingMode::Jittered, SamplingMode::Random}) {
      const Prepared p = prepare("T12-" + std::to_string(degrees), mode);
      const FeatureStats& s = p.features.stats;
      const auto ratio = [](std::uint64_t a, std::uint64_t b) { return b ? double(a) / b : 0.0; };
      std::cout << degrees << (mode == SamplingMode::Jittered ? " J " : " R ")
                << ratio(s.sharp_edges, s.edges) << " " << ratio(s.crossing_edges, s.sharp_edges)
                << " " << ratio(s.candidates, s.splats) << " " << ratio(s.clipped, s.candidates)
                << " " << s.large_segments << "\n";
      if (degrees == 165) {
        EXPECT_EQ(s.sharp_edges, 0u) << (mode == SamplingMode::Jittered ? "J" : "R");
        EXPECT_EQ(s.large_segments, 1u);
        continue;
      }
      EXPECT_GT(s.sharp_edges, 50u) << degrees;
      EXPECT_EQ(s.large_segments, 2u) << degrees;
      // Every sharp edge joins the two strips: a splat with one lies within two disc diameters
      // of the hinge, and the clipped splats are those whose disc reaches past the hinge.
      std::size_t far_candidates = 0, hinge_discs = 0, clipped_hinge_discs = 0;
      for (std::size_t i = 0; i < s.splats; ++i) {
        const Vec3f x = p.samples.points.positions[i];
        const float from_hinge = std::hypot(x.x, x.y), r = p.radii[i] * p.features.options.radius_scale;
        const bool candidate = p.features.clip_mode[i] != ClipMode::None;
        far_candidates += candidate && from_hinge > 4 * r;
        if (from_hinge < 0.5f * r && std::fabs(x.z) < 1 - 2 * r) {
          ++hinge_discs;
          clipped_hinge_discs += candidate;
        }
      }
      EXPECT_EQ(far_candidates, 0u) << degrees;
      EXPECT_GE(clipped_hinge_discs, hinge_discs * 99 / 100) << degrees;
    }
  }
}

TEST(FeatureScenes, NoisyCubeKeepsItsFaces) {
  // T14-2: normals tilted by 2° (σ) and positions by 0.1 h stay six surfaces (A8's premise):
  // two normals of one face are a few degrees apart, far inside the threshold.
  for (SamplingMode mode : {SamplingMode::Jittered, SamplingMode::Random}) {
    const Prepared p = prepare("T14-2", mode);
    EXPECT_EQ(p.features.stats.large_segments, 6u);
    EXPECT_LE(off_label(p.features, p.samples.labels), p.features.size() / 200);  // purity
  }
}

TEST(FeatureScenes, NoiseThatLooksLikeCreasesEverywhereIsReported) {
  // The test scenes' creases, even under 5° of normal noise with random sampling's large
  // discs, give no warning; a plane whose normals are tilted at random by up to 50° (the
  // normals of a rough scan at the scale of its discs) does.
  for (const char* id : {"T1", "T4", "T10", "T14-5"}) {
    const Prepared p = prepare(id, SamplingMode::Random);
    EXPECT_EQ(noisy_features_warning(p.features.stats, p.features.options), "") << id;
  }
  Prepared rough = prepare("T11", SamplingMode::Random);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> tilt(-0.6f, 0.6f);
  std::vector<Vec3f> normals = rough.samples.points.normals;
  for (Vec3f& n : normals) n = normalized(n + Vec3f{tilt(rng), tilt(rng), tilt(rng)});
  ThreadPool pool(2);
  const FeatureData f = compute_features(rough.samples.points.positions, normals, rough.radii, pool);
  const std::string warning = noisy_features_warning(f.stats, f.options);
  EXPECT_NE(warning.find("--sharp-threshold"), std::string::npos) << f.stats.capped << " of "
                                                                  << f.stats.clipped;
}

TEST(FeatureScenes, TheThresholdRisesOnlyAboveARoughSurfacesSpread) {
  // On every test scene, and on a coarse cube whose creases are a third of its neighbour
  // pairs, the threshold stays 0.9; on a plane whose normals are tilted at random by up to 50°
  // (third quartile of the pairs' angles about 40°) it rises, to at most 45°, unless the
  // threshold was given.
  for (const std::string& id : csg_scene_ids()) {
    for (SamplingMode mode : {SamplingMode::Jittered, SamplingMode::Random}) {
      const Prepared p = prepare(id, mode);
      EXPECT_EQ(p.features.options.sharp_threshold, 0.9f) << id << " " << p.features.stats.spread_deg;
    }
  }
  Prepared coarse;
  coarse.scene = csg_scene("T1");
  coarse.scene.spacing = 0.25f;
  coarse.samples = sample_csg(coarse.scene, SamplingMode::Random, 4);
  ThreadPool pool(2);
  coarse.radii = cloud_radii(coarse.samples.points.positions, pool, Progress::none(), {});
  const FeatureData c = compute_features(coarse.samples.points.positions,
                                         coarse.samples.points.normals, coarse.radii, pool);
  EXPECT_EQ(c.options.sharp_threshold, 0.9f);
  EXPECT_GT(c.stats.sharp_edges * 4, c.stats.edges);  // creases are many of the pairs
  EXPECT_EQ(c.stats.large_segments, 6u);
  Prepared rough = prepare("T11", SamplingMode::Random);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> tilt(-0.6f, 0.6f);
  std::vector<Vec3f> normals = rough.samples.points.normals;
  for (Vec3f& n : normals) n = normalized(n + Vec3f{tilt(rng), tilt(rng), tilt(rng)});
  const FeatureData raised = compute_features(rough.samples.points.positions, normals, rough.radii, pool);
  EXPECT_LT(raised.options.sharp_threshold, 0.9f) << raised.stats.spread_deg;
  EXPECT_NEAR(raised.options.sharp_threshold,
              std::max(std::cos(kSpreadFactor * raised.stats.spread_deg * kPi / 180), std::cos(0.25f * kPi)), 1e-5f);
  FeatureOptions given;
  given.adapt_threshold = false;
  EXPECT_EQ(compute_features(rough.samples.points.positions, normals, rough.radii, pool, given)
                .options.sharp_threshold,
            0.9f);
}

TEST(FeatureScenes, DoNotDependOnTheThreadCount) {
  const Prepared a = prepare("T8", SamplingMode::Random, {}, 1);
  const Prepared b = prepare("T8", SamplingMode::Random, {}, 2);
  EXPECT_EQ(a.features.surface_id, b.features.surface_id);
  EXPECT_EQ(a.features.clip_offset, b.features.clip_offset);
  EXPECT_EQ(a.features.clip_mode, b.features.clip_mode);
  ASSERT_EQ(a.features.clip_planes.size(), b.features.clip_planes.size());
  for (std::size_t k = 0; k < a.features.clip_planes.size(); ++k) {
    EXPECT_EQ(a.features.clip_planes[k].n, b.features.clip_planes[k].n);
    EXPECT_EQ(a.features.clip_planes[k].h, b.features.clip_planes[k].h);
  }
}

}  // namespace
