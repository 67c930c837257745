// reconstruct_pixel against hand-computed surfaces: fragments built here with depths, weights,
// colors and normals chosen so that the separating bounds and the weighted means can be worked
// out on paper (the expected numbers are written out next to each check).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>
#include <vector>

#include "pointillist/core/error.hpp"
#include "pointillist/render/quality.hpp"

using namespace pointillist;

namespace {

constexpr float kTol = 1e-5f;  // float sums of a handful of terms of size ~2

// A fragment of a disc of radius r whose depth interval is depth ± half_depth.
Fragment frag(float depth, float half_depth, float weight, Vec3f color, Vec3f normal,
              std::uint32_t node, float r = 0.1f) {
  return Fragment{.depth = depth, .depth_min = depth - half_depth, .depth_max = depth + half_depth,
                  .radius = r, .weight = weight, .normal = normal, .base_color = color,
                  .node = node};
}

QualitySettings rule(Reconstruction r) {
  QualitySettings q;
  q.reconstruction = r;
  return q;
}

const char* name(Reconstruction r) { return r == Reconstruction::ZRange ? "ZRange" : "ZThreshold"; }

void expect_vec(Vec3f got, Vec3f want, float tol, const std::string& what) {
  EXPECT_NEAR(got.x, want.x, tol) << what;
  EXPECT_NEAR(got.y, want.y, tol) << what;
  EXPECT_NEAR(got.z, want.z, tol) << what;
}

// Two parallel surfaces facing the eye, R = 0.1, 10 radii apart (depth 2 and 3), the back one
// listed first and heavier, so neither list order nor weight can pick the front.
//   front: node 3, depth 2.0,    w 0.75, red,  n (0,0,1), interval ±0.02
//          node 4, depth 2.0625, w 0.25, blue, n (0,0,1), interval ±0.02
//   back:  node 1, depth 3.0,    w 2,    green, n (0,1,0)
//          node 2, depth 3.05,   w 2,    green, n (0,1,0)
// Z-threshold (ε = 1): B = 2.0 + 0.1 = 2.1; keys 2.0, 2.0625 <= B < 3.0.
// Z-range (margin 0.5): intervals [1.93, 2.07] and [1.9925, 2.1325]; B = 2.07, keys of the
// back fragments 2.93, 2.98 > B.
// Front surface: w = 1, depth 0.75·2 + 0.25·2.0625 = 2.015625, color (0.75, 0, 0.25).
// Back surface: w = 4, depth (3.0 + 3.05)/2 = 3.025, color (0, 1, 0), normal (0, 1, 0).
std::vector<Fragment> two_surfaces() {
  return {frag(3.0f, 0.02f, 2.0f, {0, 1, 0}, {0, 1, 0}, 1),
          frag(2.0f, 0.02f, 0.75f, {1, 0, 0}, {0, 0, 1}, 3),
          frag(3.05f, 0.02f, 2.0f, {0, 1, 0}, {0, 1, 0}, 2),
          frag(2.0625f, 0.02f, 0.25f, {0, 0, 1}, {0, 0, 1}, 4)};
}

void expect_front_of_two(const ReconstructedSurface& s, const std::string& what) {
  EXPECT_EQ(s.fragment_count, 2u) << what;
  EXPECT_NEAR(s.weight, 1.0f, kTol) << what;
  EXPECT_NEAR(s.depth, 2.015625f, kTol) << what;
  expect_vec(s.base_color, {0.75f, 0.0f, 0.25f}, kTol, what + " color");
  expect_vec(s.normal, {0, 0, 1}, kTol, what + " normal");
  EXPECT_EQ(s.front_node, 3u) << what;
}

void expect_back_of_two(const ReconstructedSurface& s, const std::string& what) {
  EXPECT_EQ(s.fragment_count, 2u) << what;
  EXPECT_NEAR(s.weight, 4.0f, kTol) << what;
  EXPECT_NEAR(s.depth, 3.025f, kTol) << what;
  expect_vec(s.base_color, {0, 1, 0}, kTol, what + " color");
  expect_vec(s.normal, {0, 1, 0}, kTol, what + " normal");
  EXPECT_EQ(s.front_node, 1u) << what;
}

constexpr Reconstruction kRules[] = {Reconstruction::ZThreshold, Reconstruction::ZRange};

}  // namespace

TEST(Reconstruction, SeparatesTwoParallelSurfacesFartherApartThanTheSplatSize) {
  for (Reconstruction r : kRules) {
    const auto out = reconstruct_pixel(two_surfaces(), rule(r));
    ASSERT_EQ(out.size(), 1u) << name(r);
    expect_front_of_two(out[0], name(r));
  }
}

TEST(Reconstruction, BlendsFragmentsOfOneSurfaceByNormalisedWeightedMean) {
  // One surface with depths spread by 0.08 < ε·R = 0.1, intervals ±0.03 (a tilted surface).
  //   w 0.5 depth 2.00 red   n (0, 0, 1)
  //   w 0.25 depth 2.04 green n (0.6, 0, 0.8)
  //   w 0.25 depth 2.08 blue  n (0, 0.6, 0.8)
  // Z-threshold: B = 2.1 >= 2.08. Z-range: B = 2.03 + 0.05 = 2.08 >= largest key 2.05 − 0.05.
  // Mean: w = 1, depth 1.0 + 0.51 + 0.52 = 2.03, color (0.5, 0.25, 0.25); Σ w·n = (0.15, 0.15,
  // 0.9), |Σ w·n| = √0.855, normal (0.15, 0.15, 0.9)/√0.855.
  const std::vector<Fragment> f = {frag(2.00f, 0.03f, 0.5f, {1, 0, 0}, {0, 0, 1}, 10),
                                   frag(2.04f, 0.03f, 0.25f, {0, 1, 0}, {0.6f, 0, 0.8f}, 11),
                                   frag(2.08f, 0.03f, 0.25f, {0, 0, 1}, {0, 0.6f, 0.8f}, 12)};
  const float len = std::sqrt(0.855f);
  for (Reconstruction r : kRules) {
    const auto out = reconstruct_pixel(f, rule(r), 4);
    ASSERT_EQ(out.size(), 1u) << name(r);
    EXPECT_EQ(out[0].fragment_count, 3u) << name(r);
    EXPECT_NEAR(out[0].weight, 1.0f, kTol) << name(r);
    EXPECT_NEAR(out[0].depth, 2.03f, kTol) << name(r);
    expect_vec(out[0].base_color, {0.5f, 0.25f, 0.25f}, kTol, name(r));
    expect_vec(out[0].normal, {0.15f / len, 0.15f / len, 0.9f / len}, kTol, name(r));
    EXPECT_EQ(out[0].front_node, 10u) << name(r);
  }
}

TEST(Reconstruction, BlendLimitIsEpsilonRadiiOrTheWidenedDepthInterval) {
  // Z-threshold with ε = 2, R = 0.25: B = 1 + 0.5 = 1.5. A fragment at 1.49 blends, one at
  // 1.51 starts the next surface. Z-range with margin 0.25, R = 0.25, disc facing the eye: the
  // front interval is [1 − 0.0625, 1 + 0.0625]; a fragment whose interval starts at 1.12 (key
  // 1.0575 <= 1.0625) blends, one starting at 1.13 (key 1.0675) does not.
  QualitySettings zt = rule(Reconstruction::ZThreshold);
  zt.z_threshold = 2.0f;
  const Fragment front = frag(1.0f, 0.0f, 1.0f, {1, 0, 0}, {0, 0, 1}, 0, 0.25f);
  {
    const std::vector<Fragment> f = {front, frag(1.49f, 0.0f, 1.0f, {0, 0, 1}, {0, 0, 1}, 1, 0.25f)};
    const auto out = reconstruct_pixel(f, zt, 2);
    ASSERT_EQ(out.size(), 1u);
    EXPECT_NEAR(out[0].depth, 1.245f, kTol);
  }
  {
    const std::vector<Fragment> f = {front, frag(1.51f, 0.0f, 1.0f, {0, 0, 1}, {0, 0, 1}, 1, 0.25f)};
    const auto out = reconstruct_pixel(f, zt, 2);
    ASSERT_EQ(out.size(), 2u);
    EXPECT_NEAR(out[0].depth, 1.0f, kTol);
    EXPECT_NEAR(out[1].depth, 1.51f, kTol);
  }
  QualitySettings zr = rule(Reconstruction::ZRange);
  zr.z_range_margin = 0.25f;
  {
    const std::vector<Fragment> f = {front, frag(1.12f, 0.0f, 1.0f, {0, 0, 1}, {0, 0, 1}, 1, 0.25f)};
    EXPECT_EQ(reconstruct_pixel(f, zr, 2).size(), 1u);
  }
  {
    const std::vector<Fragment> f = {front, frag(1.13f, 0.0f, 1.0f, {0, 0, 1}, {0, 0, 1}, 1, 0.25f)};
    EXPECT_EQ(reconstruct_pixel(f, zr, 2).size(), 2u);
  }
}

TEST(Reconstruction, NormalFallsBackToTheFrontFragmentWhenWeightedNormalsCancel) {
  // Equal weights, opposite normals: Σ w·n = 0, so the documented fallback is the normal of the
  // fragment with the smallest key (depth 1.0, node 7), even when it is listed second.
  const std::vector<Fragment> f = {frag(1.01f, 0.0f, 0.5f, {1, 1, 1}, {0, 0, -1}, 8),
                                   frag(1.0f, 0.0f, 0.5f, {1, 1, 1}, {0, 0, 1}, 7)};
  for (Reconstruction r : kRules) {
    const auto out = reconstruct_pixel(f, rule(r));
    ASSERT_EQ(out.size(), 1u) << name(r);
    expect_vec(out[0].normal, {0, 0, 1}, 0.0f, name(r));
    EXPECT_EQ(out[0].front_node, 7u) << name(r);
  }
}

TEST(Reconstruction, ResultDoesNotDependOnFragmentOrder) {
  // Every permutation of five fragments (three of the front surface, two of the back one) gives
  // the same two surfaces as computed by hand:
  //   front: depths 2.0, 2.05, 2.09 (ε·R = 0.1), weights 0.5, 0.25, 0.25, colors red, green,
  //          blue -> depth 1.0 + 0.5125 + 0.5225 = 2.035, color (0.5, 0.25, 0.25)
  //   back:  depths 2.5, 2.55, weights 1, 3 -> depth (2.5 + 7.65)/4 = 2.5375, color grey 0.5
  //          from colors 0.5 and 0.5.
  // The Z-range intervals are ±0.01: front B = 2.01 + 0.05 = 2.06 >= key of 2.09 (2.03); back
  // keys 2.44, 2.49 > 2.06. Sums in a different order may round differently: tolerance 1e-5.
  const std::vector<Fragment> base = {
      frag(2.0f, 0.01f, 0.5f, {1, 0, 0}, {0, 0, 1}, 0),
      frag(2.05f, 0.01f, 0.25f, {0, 1, 0}, {0, 0, 1}, 1),
      frag(2.09f, 0.01f, 0.25f, {0, 0, 1}, {0, 0, 1}, 2),
      frag(2.5f, 0.01f, 1.0f, {0.5f, 0.5f, 0.5f}, {1, 0, 0}, 3),
      frag(2.55f, 0.01f, 3.0f, {0.5f, 0.5f, 0.5f}, {1, 0, 0}, 4)};
  for (Reconstruction r : kRules) {
    std::vector<int> order(base.size());
    std::iota(order.begin(), order.end(), 0);
    int permutations = 0;
    do {
      std::vector<Fragment> f;
      for (int i : order) f.push_back(base[static_cast<std::size_t>(i)]);
      const auto out = reconstruct_pixel(f, rule(r), 3);
      const std::string what = std::string(name(r)) + " permutation " + std::to_string(permutations);
      ASSERT_EQ(out.size(), 2u) << what;
      EXPECT_EQ(out[0].fragment_count, 3u) << what;
      EXPECT_NEAR(out[0].weight, 1.0f, kTol) << what;
      EXPECT_NEAR(out[0].depth, 2.035f, kTol) << what;
      expect_vec(out[0].base_color, {0.5f, 0.25f, 0.25f}, kTol, what);
      EXPECT_EQ(out[0].front_node, 0u) << what;
      EXPECT_EQ(out[1].fragment_count, 2u) << what;
      EXPECT_NEAR(out[1].weight, 4.0f, kTol) << what;
      EXPECT_NEAR(out[1].depth, 2.5375f, kTol) << what;
      expect_vec(out[1].base_color, {0.5f, 0.5f, 0.5f}, kTol, what);
      expect_vec(out[1].normal, {1, 0, 0}, kTol, what);
      EXPECT_EQ(out[1].front_node, 3u) << what;
      ++permutations;
    } while (std::next_permutation(order.begin(), order.end()));
    EXPECT_EQ(permutations, 120);
  }
}

TEST(Reconstruction, SecondSurfaceIsTheBackOne) {
  for (Reconstruction r : kRules) {
    const auto two = reconstruct_pixel(two_surfaces(), rule(r), 2);
    ASSERT_EQ(two.size(), 2u) << name(r);
    expect_front_of_two(two[0], name(r));
    expect_back_of_two(two[1], name(r));
    // Asking for more surfaces than there are gives just the two.
    EXPECT_EQ(reconstruct_pixel(two_surfaces(), rule(r), 16).size(), 2u) << name(r);
  }
  // Three surfaces peel in depth order whatever the list order: depths 5, 1, 3 (R = 0.1).
  const std::vector<Fragment> three = {frag(5.0f, 0.0f, 1.0f, {0, 0, 1}, {0, 0, 1}, 5),
                                       frag(1.0f, 0.0f, 1.0f, {1, 0, 0}, {0, 0, 1}, 1),
                                       frag(3.0f, 0.0f, 1.0f, {0, 1, 0}, {0, 0, 1}, 3)};
  for (Reconstruction r : kRules) {
    const auto out = reconstruct_pixel(three, rule(r), 3);
    ASSERT_EQ(out.size(), 3u) << name(r);
    EXPECT_EQ(out[0].front_node, 1u) << name(r);
    EXPECT_EQ(out[1].front_node, 3u) << name(r);
    EXPECT_EQ(out[2].front_node, 5u) << name(r);
    EXPECT_FLOAT_EQ(out[1].depth, 3.0f) << name(r);
  }
}

TEST(Reconstruction, NoFragmentsGiveNoSurface) {
  for (Reconstruction r : kRules) EXPECT_TRUE(reconstruct_pixel({}, rule(r), 2).empty()) << name(r);
}

TEST(Reconstruction, ValidateAcceptsTheDocumentedRanges) {
  EXPECT_NO_THROW(validate_quality_settings(QualitySettings{}));
  const auto ok = [](auto edit) {
    QualitySettings q;
    edit(q);
    return q;
  };
  EXPECT_NO_THROW(validate_quality_settings(ok([](QualitySettings& q) { q.z_range_margin = 0; })));
  EXPECT_NO_THROW(validate_quality_settings(ok([](QualitySettings& q) { q.radius_scale = 1; })));
  EXPECT_NO_THROW(validate_quality_settings(ok([](QualitySettings& q) { q.radius_scale = 2; })));
  EXPECT_NO_THROW(validate_quality_settings(ok([](QualitySettings& q) { q.kernel_sigma = 0.1f; })));
  EXPECT_NO_THROW(validate_quality_settings(ok([](QualitySettings& q) { q.kernel_sigma = 4; })));
  EXPECT_NO_THROW(validate_quality_settings(ok([](QualitySettings& q) { q.lowpass_radius_px = 0.5f; })));
  EXPECT_NO_THROW(validate_quality_settings(ok([](QualitySettings& q) { q.lowpass_radius_px = 16; })));
  EXPECT_NO_THROW(validate_quality_settings(ok([](QualitySettings& q) { q.opacity = 1e-3f; })));
  EXPECT_NO_THROW(validate_quality_settings(ok([](QualitySettings& q) { q.max_layers = 1; })));
  EXPECT_NO_THROW(validate_quality_settings(ok([](QualitySettings& q) { q.max_layers = 16; })));
}

TEST(Reconstruction, ValidateRejectsOutOfRangeValuesNamingTheField) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  struct Case {
    const char* field;
    void (*edit)(QualitySettings&, float, float);
  };
  const Case cases[] = {
      {"reconstruction", [](QualitySettings& q, float, float) { q.reconstruction = static_cast<Reconstruction>(7); }},
      {"z_threshold", [](QualitySettings& q, float, float) { q.z_threshold = 0; }},
      {"z_threshold", [](QualitySettings& q, float, float) { q.z_threshold = -1; }},
      {"z_threshold", [](QualitySettings& q, float n, float) { q.z_threshold = n; }},
      {"z_threshold", [](QualitySettings& q, float, float i) { q.z_threshold = i; }},
      {"z_range_margin", [](QualitySettings& q, float, float) { q.z_range_margin = -0.01f; }},
      {"z_range_margin", [](QualitySettings& q, float n, float) { q.z_range_margin = n; }},
      {"radius_scale", [](QualitySettings& q, float, float) { q.radius_scale = 0.99f; }},
      {"radius_scale", [](QualitySettings& q, float, float) { q.radius_scale = 2.01f; }},
      {"kernel_sigma", [](QualitySettings& q, float, float) { q.kernel_sigma = 0.09f; }},
      {"kernel_sigma", [](QualitySettings& q, float, float) { q.kernel_sigma = 4.01f; }},
      {"lowpass_radius_px", [](QualitySettings& q, float, float) { q.lowpass_radius_px = 0.49f; }},
      {"lowpass_radius_px", [](QualitySettings& q, float, float) { q.lowpass_radius_px = 16.1f; }},
      {"opacity", [](QualitySettings& q, float, float) { q.opacity = 0; }},
      {"opacity", [](QualitySettings& q, float, float) { q.opacity = 1.01f; }},
      {"opacity", [](QualitySettings& q, float n, float) { q.opacity = n; }},
      {"max_layers", [](QualitySettings& q, float, float) { q.max_layers = 0; }},
      {"max_layers", [](QualitySettings& q, float, float) { q.max_layers = 17; }},
  };
  for (const Case& c : cases) {
    QualitySettings q;
    c.edit(q, nan, inf);
    try {
      validate_quality_settings(q);
      ADD_FAILURE() << c.field << ": no exception";
    } catch (const OptionError& e) {
      EXPECT_NE(std::string(e.what()).find(c.field), std::string::npos) << e.what();
    }
    // reconstruct_pixel validates too.
    EXPECT_THROW(reconstruct_pixel(two_surfaces(), q), OptionError) << c.field;
  }
}
