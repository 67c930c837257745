// Label metrics (spec §4.5 from two images) on hand-built images with known answers: a square of
// two labels split by a straight boundary, and test images that move, blend, hole or overshoot it.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "pointillist/core/error.hpp"
#include "pointillist/core/normal_color.hpp"
#include "pointillist/eval/label_metrics.hpp"

using namespace pointillist;

namespace {

constexpr Rgb8 kPalette[3] = {{230, 25, 75}, {60, 180, 75}, {0, 130, 200}};
constexpr Rgb8 kBlack{0, 0, 0};
constexpr int kSize = 64, kLo = 8, kHi = 56;  // the square [8, 56)² on a 64×64 black image

struct Image {
  int width = kSize, height = kSize;
  std::vector<Rgb8> pixels = std::vector<Rgb8>(std::size_t(kSize) * kSize, kBlack);
  Rgb8& at(int x, int y) { return pixels[std::size_t(y) * width + x]; }
  ImageRgb8View view() const { return {width, height, pixels}; }
};

// The square, label 0 left of column `split` and label 1 from it on (vertical boundary), or
// above row `split` and below it (horizontal).
Image two_labels(int split, bool vertical = true) {
  Image img;
  for (int y = kLo; y < kHi; ++y) {
    for (int x = kLo; x < kHi; ++x) img.at(x, y) = kPalette[(vertical ? x : y) < split ? 0 : 1];
  }
  return img;
}

Rgb8 blend(Rgb8 a, Rgb8 b, double share_of_a) {
  const auto mix = [&](int u, int v) {
    return static_cast<std::uint8_t>(u * share_of_a + v * (1 - share_of_a) + 0.5);
  };
  return {mix(a.r, b.r), mix(a.g, b.g), mix(a.b, b.b)};
}

LabelComparison compare(const Image& ref, const Image& test) {
  return compare_labels(ref.view(), test.view(), {.palette = kPalette});
}

}  // namespace

TEST(LabelMetrics, IdenticalImagesHaveNoErrors) {
  const Image ref = two_labels(32);
  const LabelComparison c = compare(ref, ref);
  EXPECT_EQ(c.covered_count, 48u * 48u);
  EXPECT_EQ(c.interior_count, 46u * 46u);
  EXPECT_EQ(c.boundary_count, 2u * 48u);      // columns 31 and 32
  EXPECT_EQ(c.band_count, 10u * 48u);         // columns 27..36
  EXPECT_EQ(c.far_background_count, 64u * 64u - 50u * 50u);
  EXPECT_EQ(c.hole_count + c.overshoot_count + c.covered_error_count + c.mixed_count, 0u);
  EXPECT_EQ(c.ler_band, 0.0);
  EXPECT_EQ(c.profile_count, 64u);
  EXPECT_EQ(c.displacement_max_px, 0.0);
  EXPECT_EQ(c.transition_max_px, 0.0);
}

TEST(LabelMetrics, BoundaryMovedTwoPixelsIsDisplacedByTwo) {
  for (bool vertical : {true, false}) {
    const LabelComparison c = compare(two_labels(32, vertical), two_labels(34, vertical));
    EXPECT_EQ(c.profile_count, 64u);
    EXPECT_DOUBLE_EQ(c.displacement_mean_px, 2.0);
    EXPECT_DOUBLE_EQ(c.displacement_max_px, 2.0);
    EXPECT_EQ(c.transition_max_px, 0.0);
    // Two columns (rows) of 48 pixels show the wrong label: inside B_4 and among C*.
    EXPECT_EQ(c.wrong_count, 96u);
    EXPECT_EQ(c.band_error_count, 96u);
    EXPECT_DOUBLE_EQ(c.ler_band, 96.0 / 480.0);
    EXPECT_DOUBLE_EQ(c.ler_covered, 96.0 / 2304.0);
    EXPECT_EQ(c.mixed_count, 0u);
    EXPECT_EQ(c.hole_count, 0u);
  }
}

TEST(LabelMetrics, DiagonalBoundaryMovedIsDisplacedAlongItsNormal) {
  // x − y < 0 against x − y < 4: moved 4/√2 ≈ 2.83 px along the normal; the profiles step in
  // whole pixels along the diagonal, so the measure lies within a pixel of it.
  Image ref, test;
  for (int y = kLo; y < kHi; ++y) {
    for (int x = kLo; x < kHi; ++x) {
      ref.at(x, y) = kPalette[x - y < 0 ? 0 : 1];
      test.at(x, y) = kPalette[x - y < 4 ? 0 : 1];
    }
  }
  const LabelComparison c = compare(ref, test);
  ASSERT_GT(c.profile_count, 0u);
  EXPECT_GT(c.displacement_mean_px, 1.83);
  EXPECT_LT(c.displacement_mean_px, 3.83);
}

TEST(LabelMetrics, BlendedStripIsItsTransitionWidth) {
  const Image ref = two_labels(32);
  Image test = ref;
  // Columns 31, 32, 33 blend the two labels half and half.
  for (int y = kLo; y < kHi; ++y) {
    for (int x = 31; x <= 33; ++x) test.at(x, y) = blend(kPalette[0], kPalette[1], 0.5);
  }
  const LabelComparison c = compare(ref, test);
  EXPECT_EQ(c.profile_count, 64u);
  EXPECT_DOUBLE_EQ(c.transition_mean_px, 3.0);
  EXPECT_DOUBLE_EQ(c.transition_max_px, 3.0);
  // The best splits put the switch anywhere in the strip: at 31, 32, 33 or 34 (first pixel of
  // the right label), mean 32.5 against the reference's 32.
  EXPECT_DOUBLE_EQ(c.displacement_max_px, 0.5);
  EXPECT_EQ(c.mixed_count, 3u * 46u);       // interior rows 9..54
  EXPECT_EQ(c.mixed_band_count, 3u * 46u);
  EXPECT_EQ(c.mixed_outside_count, 3u * 2u);  // rows 8 and 55 touch the silhouette
  EXPECT_DOUBLE_EQ(c.mixed_per_boundary_px, 138.0 / 96.0);
}

TEST(LabelMetrics, FaintBlendsAreMixedButNotTransition) {
  const Image ref = two_labels(32);
  Image test = ref;
  // Shares of the left label 0.95, 0.5, 0.5, 0.05: all four mixed, two in the transition.
  const double shares[4] = {0.95, 0.5, 0.5, 0.05};
  for (int y = kLo; y < kHi; ++y) {
    for (int k = 0; k < 4; ++k) test.at(30 + k, y) = blend(kPalette[0], kPalette[1], shares[k]);
  }
  const LabelComparison c = compare(ref, test);
  EXPECT_EQ(c.mixed_count, 4u * 46u);
  EXPECT_DOUBLE_EQ(c.transition_max_px, 2.0);
  EXPECT_DOUBLE_EQ(c.transition_mean_px, 2.0);
}

TEST(LabelMetrics, ColoursWithinTheToleranceKeepTheirLabel) {
  const Image ref = two_labels(32);
  Image test = ref;
  const Rgb8 a = kPalette[0];
  test.at(12, 12) = {std::uint8_t(a.r - 2), std::uint8_t(a.g + 2), a.b};  // within 2 levels
  test.at(14, 12) = {std::uint8_t(a.r - 3), a.g, a.b};                     // 3 levels off
  const LabelComparison c = compare(ref, test);
  EXPECT_EQ(c.mixed_count, 1u);
  EXPECT_EQ(c.covered_error_count, 1u);
  const LabelComparison loose =
      compare_labels(ref.view(), test.view(), {.palette = kPalette, .tolerance = 3});
  EXPECT_EQ(loose.mixed_count, 0u);
}

TEST(LabelMetrics, HoleOfKnownSize) {
  const Image ref = two_labels(32);
  Image test = ref;
  for (int y = 20; y < 24; ++y) {
    for (int x = 12; x < 17; ++x) test.at(x, y) = kBlack;  // 5×4 inside label 0
  }
  test.at(kLo, 40) = kBlack;  // on the silhouette: a miss, not a hole
  const LabelComparison c = compare(ref, test);
  EXPECT_EQ(c.hole_count, 20u);
  EXPECT_EQ(c.covered_error_count, 21u);
  EXPECT_EQ(c.wrong_count, 0u);
  EXPECT_EQ(c.mixed_count, 0u);
  EXPECT_EQ(c.band_error_count, 0u);
}

TEST(LabelMetrics, OvershootBeyondOnePixelOfTheSilhouette) {
  const Image ref = two_labels(32);
  Image test = ref;
  for (int y = kLo; y < kHi; ++y) {
    for (int x = 4; x < kLo; ++x) test.at(x, y) = kPalette[0];  // columns 4..7
  }
  test.at(60, 2) = blend(kPalette[0], kBlack, 0.5);  // a stray blend far away
  const LabelComparison c = compare(ref, test);
  // Column 7 touches the square (within 1 px): columns 4, 5, 6 of 48 rows, and the stray pixel.
  EXPECT_EQ(c.overshoot_count, 3u * 48u + 1u);
  EXPECT_EQ(c.far_background_count, 64u * 64u - 50u * 50u);
  EXPECT_EQ(c.mixed_outside_count, 1u);
  EXPECT_EQ(c.covered_error_count, 0u);
}

TEST(LabelMetrics, MixedPixelsCountedInsideAndOutsideTheBand) {
  const Image ref = two_labels(32);
  Image test = ref;
  const Rgb8 grey{128, 128, 128};
  for (int k = 0; k < 5; ++k) test.at(12 + k, 40) = grey;  // interior, far from the boundary
  test.at(36, 20) = grey;                                   // interior, 4 px from column 32
  test.at(45, kLo) = grey;                                  // on the silhouette
  const LabelComparison c = compare(ref, test);
  EXPECT_EQ(c.mixed_count, 6u);
  EXPECT_EQ(c.mixed_band_count, 1u);
  EXPECT_EQ(c.mixed_outside_count, 1u);
  EXPECT_EQ(c.mix_band_count, 18u * 46u);  // columns 23..40 of the interior rows
  EXPECT_EQ(c.wrong_count, 0u);
}

TEST(LabelMetrics, TestWithoutOneOfTheLabelsIsUnmatched) {
  Image test;
  for (int y = kLo; y < kHi; ++y) {
    for (int x = kLo; x < kHi; ++x) test.at(x, y) = kPalette[2];
  }
  const LabelComparison c = compare(two_labels(32), test);
  EXPECT_EQ(c.profile_count, 0u);
  EXPECT_EQ(c.unmatched_profile_count, 64u);
  EXPECT_EQ(c.wrong_count, 48u * 48u);
  EXPECT_DOUBLE_EQ(c.ler_covered, 1.0);
}

TEST(LabelMetrics, ReferenceColourOutsideThePaletteNamesThePixel) {
  Image ref = two_labels(32);
  ref.at(40, 30) = {1, 2, 3};
  try {
    compare_labels(ref.view(), ref.view(), {.palette = kPalette, .reference_name = "ref.png"});
    FAIL() << "expected an error";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("ref.png: pixel (40, 30) is 1,2,3"), std::string::npos) << m;
    EXPECT_NE(m.find("generate --reference"), std::string::npos) << m;
  }
}

TEST(LabelMetrics, RejectsPaletteThatCannotBeToldApartAndSizeMismatch) {
  const Image ref = two_labels(32);
  const Rgb8 close[2] = {{100, 100, 100}, {103, 100, 100}};
  try {
    compare_labels(ref.view(), ref.view(), {.palette = close});
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("palette colours 0 and 1"), std::string::npos)
        << e.what();
  }
  const Rgb8 dark[1] = {{2, 0, 0}};
  EXPECT_THROW(compare_labels(ref.view(), ref.view(), {.palette = dark}), Error);
  std::vector<Rgb8> small(32 * 32, kBlack);
  EXPECT_THROW(compare_labels(ref.view(), {32, 32, small}, {.palette = kPalette}), Error);
  EXPECT_THROW(compare_labels(ref.view(), ref.view(), {}), Error);  // no palette
}

namespace {

// Depth images for the square: every covered pixel at depth 2, the background +inf.
std::vector<float> flat_depth(const Image& img, float d = 2.0f) {
  std::vector<float> out(img.pixels.size(), std::numeric_limits<float>::infinity());
  for (std::size_t i = 0; i < out.size(); ++i) {
    if (!(img.pixels[i] == kBlack)) out[i] = d;
  }
  return out;
}

}  // namespace

TEST(LabelMetrics, SeeThroughCountsOtherSurfacesFartherThanTheGap) {
  const Image ref = two_labels(32);
  Image test = ref;
  std::vector<float> test_depth = flat_depth(ref);
  // 3×2 pixels of label 0 show label 1 from 0.5 behind: see-through at a gap of 0.1.
  for (int y = 20; y < 22; ++y) {
    for (int x = 12; x < 15; ++x) test.at(x, y) = kPalette[1], test_depth[y * kSize + x] = 2.5f;
  }
  // 4 pixels show label 1 only 0.05 behind (within the gap), 2 a blend far behind (MIXED
  // counts), 5 are holes (background: HOLE, not see-through), and 1 shows the right label far
  // behind (not another surface).
  for (int x = 40; x < 44; ++x) test.at(x, 12) = kPalette[0], test_depth[12 * kSize + x] = 2.05f;
  for (int x = 40; x < 42; ++x) {
    test.at(x, 30) = blend(kPalette[0], kPalette[1], 0.5), test_depth[30 * kSize + x] = 4.0f;
  }
  for (int x = 20; x < 25; ++x) test.at(x, 40) = kBlack, test_depth[40 * kSize + x] = 9.0f;
  test_depth[45 * kSize + 20] = 9.0f;
  const std::vector<float> ref_depth = flat_depth(ref);
  const LabelComparison c =
      compare_labels(ref.view(), test.view(),
                     {.palette = kPalette, .reference_depth = ref_depth, .test_depth = test_depth,
                      .see_through_gap = 0.1f});
  EXPECT_TRUE(c.depth_compared);
  EXPECT_EQ(c.see_through_count, 6u + 2u);
  EXPECT_EQ(c.hole_count, 5u);
  // Without depth it is not measured.
  const LabelComparison plain = compare(ref, test);
  EXPECT_FALSE(plain.depth_compared);
  EXPECT_EQ(plain.see_through_count, 0u);
}

TEST(LabelMetrics, DepthImagesMustComeInPairsOfTheImageSizeWithAGap) {
  const Image ref = two_labels(32);
  const std::vector<float> d = flat_depth(ref), short_d(10, 1.0f);
  EXPECT_THROW(compare_labels(ref.view(), ref.view(),
                              {.palette = kPalette, .reference_depth = d, .see_through_gap = 1}),
               Error);
  EXPECT_THROW(compare_labels(ref.view(), ref.view(),
                              {.palette = kPalette, .reference_depth = d, .test_depth = short_d,
                               .see_through_gap = 1}),
               Error);
  EXPECT_THROW(compare_labels(ref.view(), ref.view(),
                              {.palette = kPalette, .reference_depth = d, .test_depth = d}),
               Error);
}

TEST(LabelMetrics, PsnrInsideTheEightPixelBand) {
  const Image ref = two_labels(32);
  Image test = ref;
  test.at(30, 20) = {200, 25, 75};  // label 0 is (230, 25, 75): one channel 30 levels off
  test.at(10, 20) = {0, 0, 0};      // outside B_8 (columns 23..40): does not count
  // B_8: boundary columns 31 and 32 widened by 8, columns 23..40, 48 rows.
  const double mse = 30.0 * 30.0 / (3.0 * 18 * 48);
  EXPECT_NEAR(compare(ref, test).psnr_band_db, 10 * std::log10(255.0 * 255.0 / mse), 1e-9);
  EXPECT_TRUE(std::isinf(compare(ref, ref).psnr_band_db));
  const Image one = two_labels(kHi);  // a single label: no boundary
  EXPECT_TRUE(std::isnan(compare(one, one).psnr_band_db));
}

TEST(LabelMetrics, NormalErrorMeasuresAnglesInTheBandOverCoveredPixels) {
  // Reference normals: label 0's face faces the eye, label 1's is turned 60° about y. The test
  // has the same labels; its normals equal the reference's except a column of label 0 in B_8
  // turned 10° about x (over the 5° threshold) and a column far from the boundary turned 3°.
  const Image ref = two_labels(32);
  Image ref_n, test_n;
  const double rad = 3.14159265358979323846 / 180.0;
  const auto about_x = [&](double deg) {
    return encode_normal_color({0, static_cast<float>(std::sin(deg * rad)),
                                static_cast<float>(std::cos(deg * rad))});
  };
  const Rgb8 face0 = about_x(0);
  const Rgb8 face1 = encode_normal_color(
      {static_cast<float>(std::sin(60 * rad)), 0, static_cast<float>(std::cos(60 * rad))});
  for (int y = kLo; y < kHi; ++y) {
    for (int x = kLo; x < kHi; ++x) {
      ref_n.at(x, y) = test_n.at(x, y) = x < 32 ? face0 : face1;
    }
    test_n.at(28, y) = about_x(10);  // column 28: 4 px from the boundary, in B_8
    test_n.at(12, y) = about_x(3);   // column 12: 20 px away, outside B_8
  }
  LabelCompareOptions o{.palette = kPalette};
  o.reference_normals = ref_n.pixels;
  o.test_normals = test_n.pixels;
  const LabelComparison c = compare_labels(ref.view(), ref.view(), o);
  ASSERT_TRUE(c.normals_compared);
  // B_8: columns 23..40 (8 either side of the boundary columns 31 and 32), 48 rows.
  EXPECT_EQ(c.normal_band_count, 18u * 48u);
  EXPECT_EQ(c.normal_band_over, 48u);
  EXPECT_NEAR(c.normal_band_mean_deg, 10.0 * 48 / (18.0 * 48), 0.03);
  EXPECT_EQ(c.normal_covered_count, 48u * 48u);
  EXPECT_EQ(c.normal_covered_over, 48u);
  EXPECT_NEAR(c.normal_covered_mean_deg, (10.0 + 3.0) * 48 / (48.0 * 48), 0.02);

  // A hole is HOLE's, not a normal error: the test's empty pixels are left out.
  Image holed = ref;
  holed.at(30, 30) = kBlack;
  const LabelComparison h = compare_labels(ref.view(), holed.view(), o);
  EXPECT_EQ(h.hole_count, 1u);
  EXPECT_EQ(h.normal_band_count, 18u * 48u - 1);

  // Both images or neither, of the colour images' size.
  LabelCompareOptions one = o;
  one.test_normals = {};
  EXPECT_THROW(compare_labels(ref.view(), ref.view(), one), Error);
  const std::vector<Rgb8> small(10);
  one.test_normals = small;
  EXPECT_THROW(compare_labels(ref.view(), ref.view(), one), Error);
  EXPECT_FALSE(compare(ref, ref).normals_compared);
}
