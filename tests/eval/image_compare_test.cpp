// Image-quality metrics against analytic values and hand-built cases.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "pointillist/core/error.hpp"
#include "pointillist/eval/image_compare.hpp"

using namespace pointillist;

namespace {

struct Image {
  int width = 0, height = 0;
  std::vector<Rgb8> pixels;
  Image(int w, int h, Rgb8 fill = {}) : width(w), height(h), pixels(std::size_t(w) * h, fill) {}
  Rgb8& at(int x, int y) { return pixels[std::size_t(y) * width + x]; }
  ImageRgb8View view() const { return {width, height, pixels}; }
};

std::uint8_t u8(int v) { return static_cast<std::uint8_t>(v); }
Rgb8 gray(int v) { return {u8(v), u8(v), u8(v)}; }

// Each channel uniform in [lo, hi], seeded.
Image noise_image(int w, int h, int lo, int hi, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> dist(lo, hi);
  Image img(w, h);
  for (Rgb8& p : img.pixels) p = {u8(dist(rng)), u8(dist(rng)), u8(dist(rng))};
  return img;
}

Image add_to_all_channels(const Image& in, int k) {
  Image out = in;
  for (Rgb8& p : out.pixels) p = {u8(p.r + k), u8(p.g + k), u8(p.b + k)};
  return out;
}

// Filled disc: pixel centres strictly inside the circle.
void draw_disc(Image& img, double cx, double cy, double r, Rgb8 color) {
  for (int y = 0; y < img.height; ++y) {
    for (int x = 0; x < img.width; ++x) {
      const double dx = x + 0.5 - cx, dy = y + 0.5 - cy;
      if (dx * dx + dy * dy < r * r) img.at(x, y) = color;
    }
  }
}

constexpr double kC1 = (0.01 * 255) * (0.01 * 255);

}  // namespace

TEST(ImageCompare, PsnrOfUniformOffsetIs20Log10Of255OverK) {
  const Image base = noise_image(37, 23, 10, 200, 7);
  for (int k : {1, 2, 5, 17, 50}) {
    const Image shifted = add_to_all_channels(base, k);
    EXPECT_DOUBLE_EQ(mse_rgb(base.view(), shifted.view()), double(k) * k) << "k = " << k;
    EXPECT_NEAR(psnr_rgb(base.view(), shifted.view()), 20.0 * std::log10(255.0 / k), 1e-10)
        << "k = " << k;
    // Symmetric: the test darker than the reference by k gives the same value.
    EXPECT_NEAR(psnr_rgb(shifted.view(), base.view()), 20.0 * std::log10(255.0 / k), 1e-10);
  }
}

TEST(ImageCompare, PsnrOfHandBuiltPair) {
  Image a(2, 2), b(2, 2);
  a.pixels = {{10, 20, 30}, {0, 0, 0}, {255, 255, 255}, {100, 100, 100}};
  b.pixels = {{13, 16, 30}, {0, 0, 0}, {255, 255, 250}, {100, 100, 100}};
  // Squared differences 9 + 16 + 25 = 50 over 12 samples: 10·log10(255² · 12 / 50).
  EXPECT_DOUBLE_EQ(mse_rgb(a.view(), b.view()), 50.0 / 12.0);
  EXPECT_NEAR(psnr_rgb(a.view(), b.view()), 41.932916025795166, 1e-9);
}

TEST(ImageCompare, PsnrOfIdenticalImagesIsInfinite) {
  const Image a = noise_image(5, 4, 0, 255, 3);
  EXPECT_EQ(psnr_rgb(a.view(), a.view()), std::numeric_limits<double>::infinity());
  EXPECT_EQ(mse_rgb(a.view(), a.view()), 0.0);
}

TEST(ImageCompare, SsimOfIdenticalImagesIsOne) {
  const Image a = noise_image(64, 40, 0, 255, 11);
  EXPECT_NEAR(ssim_luma(a.view(), a.view()), 1.0, 1e-12);
}

TEST(ImageCompare, SsimOfConstantImagesIsTheLuminanceTerm) {
  // σ = 0 in both images, so SSIM = (2·μx·μy + C1) / (μx² + μy² + C1) in every window.
  const Image a(20, 15, gray(100)), b(20, 15, gray(120));
  const double expected = (2.0 * 100 * 120 + kC1) / (100.0 * 100 + 120.0 * 120 + kC1);
  EXPECT_NEAR(ssim_luma(a.view(), b.view()), expected, 1e-9);
}

TEST(ImageCompare, SsimOfAConstantShiftIsSlightlyBelowOne) {
  // A shift by k keeps σx = σy = σxy, so each window's SSIM is the luminance term
  // 1 − k² / (μ² + (μ+k)² + C1), which for local means μ in [40, 200] lies in the bounds below.
  const int k = 10;
  const Image a = noise_image(48, 48, 40, 200, 5);
  const Image b = add_to_all_channels(a, k);
  const double s = ssim_luma(a.view(), b.view());
  const double lower = 1.0 - k * k / (40.0 * 40 + 50.0 * 50 + kC1);
  const double upper = 1.0 - k * k / (200.0 * 200 + 210.0 * 210 + kC1);
  EXPECT_LT(s, 1.0);
  EXPECT_GE(s, lower);
  EXPECT_LE(s, upper);
}

TEST(ImageCompare, SsimOfUnrelatedNoiseIsNearZero) {
  const Image a = noise_image(96, 96, 0, 255, 1);
  const Image b = noise_image(96, 96, 0, 255, 2);
  EXPECT_NEAR(ssim_luma(a.view(), b.view()), 0.0, 0.05);
}

TEST(ImageCompare, SsimDecreasesMonotonicallyWithNoiseAmplitude) {
  // A smooth base in [90, 165] and one fixed noise pattern in [−1, 1] scaled by the amplitude;
  // no value leaves 0..255, so nothing is clipped.
  const int w = 64, h = 48;
  Image base(w, h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      base.at(x, y) = gray(int(std::lround(127.5 + 37.5 * std::sin(x * 0.2) * std::cos(y * 0.15))));
    }
  }
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<double> pattern(base.pixels.size());
  for (double& v : pattern) v = unit(rng);

  double previous = 2.0;
  for (int amplitude : {0, 2, 5, 10, 20, 40, 80}) {
    Image noisy = base;
    for (std::size_t i = 0; i < pattern.size(); ++i) {
      noisy.pixels[i] = gray(base.pixels[i].r + int(std::lround(amplitude * pattern[i])));
    }
    const double s = ssim_luma(base.view(), noisy.view());
    if (amplitude == 0) {
      EXPECT_NEAR(s, 1.0, 1e-12);
    }
    EXPECT_LT(s, previous) << "amplitude " << amplitude;
    previous = s;
  }
  EXPECT_LT(previous, 0.5);
}

TEST(ImageCompare, SsimMatchesADirectWindowSum) {
  // Oracle: the 2D definition evaluated window by window with the 11×11 Gaussian weights
  // w(i, j) ∝ exp(−((i−5)² + (j−5)²) / (2·1.5²)) and the Rec. 601 luma.
  const int w = 23, h = 17;
  const Image a = noise_image(w, h, 0, 255, 21);
  Image b = noise_image(w, h, 0, 255, 22);
  for (std::size_t i = 0; i < b.pixels.size(); ++i) {  // correlated with a, so SSIM is far from 0
    const Rgb8 p = a.pixels[i], q = b.pixels[i];
    b.pixels[i] = {u8((p.r * 3 + q.r) / 4), u8((p.g * 3 + q.g) / 4), u8((p.b * 3 + q.b) / 4)};
  }
  const auto luma = [](Rgb8 p) { return 0.299 * p.r + 0.587 * p.g + 0.114 * p.b; };
  const double c2 = (0.03 * 255) * (0.03 * 255);
  double weight[11][11], weight_sum = 0;
  for (int j = 0; j < 11; ++j) {
    for (int i = 0; i < 11; ++i) {
      weight[j][i] = std::exp(-((i - 5) * (i - 5) + (j - 5) * (j - 5)) / (2 * 1.5 * 1.5));
      weight_sum += weight[j][i];
    }
  }
  double total = 0;
  int windows = 0;
  for (int y0 = 0; y0 + 11 <= h; ++y0) {
    for (int x0 = 0; x0 + 11 <= w; ++x0) {
      double ux = 0, uy = 0;
      for (int j = 0; j < 11; ++j) {
        for (int i = 0; i < 11; ++i) {
          const double wt = weight[j][i] / weight_sum;
          ux += wt * luma(a.pixels[std::size_t(y0 + j) * w + x0 + i]);
          uy += wt * luma(b.pixels[std::size_t(y0 + j) * w + x0 + i]);
        }
      }
      double vx = 0, vy = 0, cxy = 0;
      for (int j = 0; j < 11; ++j) {
        for (int i = 0; i < 11; ++i) {
          const double wt = weight[j][i] / weight_sum;
          const double dx = luma(a.pixels[std::size_t(y0 + j) * w + x0 + i]) - ux;
          const double dy = luma(b.pixels[std::size_t(y0 + j) * w + x0 + i]) - uy;
          vx += wt * dx * dx;
          vy += wt * dy * dy;
          cxy += wt * dx * dy;
        }
      }
      total += (2 * ux * uy + kC1) * (2 * cxy + c2) / ((ux * ux + uy * uy + kC1) * (vx + vy + c2));
      ++windows;
    }
  }
  const double expected = total / windows;
  EXPECT_GT(expected, 0.5);
  EXPECT_NEAR(ssim_luma(a.view(), b.view()), expected, 1e-9);
}

TEST(ImageCompare, SsimRejectsImagesSmallerThanTheWindow) {
  const Image a(10, 20);
  try {
    ssim_luma(a.view(), a.view());
    FAIL() << "expected an Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("11x11"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("10x20"), std::string::npos) << e.what();
  }
}

TEST(ImageCompare, SizeMismatchNamesBothSizes) {
  const Image a(20, 10), b(10, 20);
  EXPECT_THROW(psnr_rgb(a.view(), b.view()), Error);
  EXPECT_THROW(ssim_luma(a.view(), b.view()), Error);
  try {
    compare_images(a.view(), b.view());
    FAIL() << "expected an Error";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("reference is 20x10"), std::string::npos) << m;
    EXPECT_NE(m.find("test is 10x20"), std::string::npos) << m;
  }
  const Image empty(0, 0);
  EXPECT_THROW(mse_rgb(empty.view(), empty.view()), Error);
}

TEST(ImageCompare, SilhouetteIouOfTwoDiscsMatchesTheLensArea) {
  // Two discs of radius r with centres d apart overlap in the lens
  // 2r²·acos(d / 2r) − (d/2)·sqrt(4r² − d²); IoU = lens / (2πr² − lens).
  const double r = 40, pi = std::acos(-1.0);
  for (double d : {40.0, 20.0, 0.0}) {
    Image a(200, 200, gray(0)), b(200, 200, gray(0));
    draw_disc(a, 100 - d / 2, 100, r, {200, 30, 30});
    draw_disc(b, 100 + d / 2, 100, r, {30, 200, 30});
    const double lens = 2 * r * r * std::acos(d / (2 * r)) - d / 2 * std::sqrt(4 * r * r - d * d);
    const double expected = lens / (2 * pi * r * r - lens);
    const ImageComparison c = compare_images(a.view(), b.view());
    EXPECT_NEAR(c.silhouette_iou, expected, 0.002) << "d = " << d;
    EXPECT_NEAR(double(c.reference_foreground_count), pi * r * r, 0.01 * pi * r * r);
  }
  // Disjoint discs.
  Image a(200, 200, gray(0)), b(200, 200, gray(0));
  draw_disc(a, 50, 100, r, gray(255));
  draw_disc(b, 150, 100, r, gray(255));
  EXPECT_EQ(compare_images(a.view(), b.view()).silhouette_iou, 0.0);
}

TEST(ImageCompare, BackgroundIsTheReferenceTopLeftPixelUnlessGiven) {
  const Rgb8 bg{50, 60, 70}, red{255, 0, 0};
  Image a(32, 32, bg), b(32, 32, bg);
  for (int y = 10; y < 20; ++y) {
    for (int x = 10; x < 20; ++x) a.at(x, y) = red;
    for (int x = 15; x < 25; ++x) b.at(x, y) = red;
  }
  // Squares of 100 px overlapping in 5×10: IoU = 50 / 150.
  const ImageComparison c = compare_images(a.view(), b.view());
  EXPECT_EQ(c.background, bg);
  EXPECT_NEAR(c.silhouette_iou, 1.0 / 3.0, 1e-12);
  EXPECT_EQ(c.reference_foreground_count, 100u);
  EXPECT_EQ(c.test_foreground_count, 100u);
  // A background color present nowhere makes every pixel foreground in both images.
  const ImageComparison all = compare_images(a.view(), b.view(), {.background = Rgb8{1, 2, 3}});
  EXPECT_EQ(all.background, (Rgb8{1, 2, 3}));
  EXPECT_EQ(all.silhouette_iou, 1.0);
  EXPECT_EQ(all.hole_count, 0u);
  EXPECT_EQ(all.reference_foreground_count, 32u * 32u);
}

TEST(ImageCompare, HoleCountCountsOnlyInteriorMisses) {
  // Reference: a 10×10 square (x, y in 5..14) with a one-pixel gap at (11, 9), and a band
  // touching the top, right and bottom borders (x in 18..23, all y). Interior pixels: 8×8 in the
  // square less the 3×3 around the gap (whose corners see it only diagonally), plus x in 19..22
  // and y in 1..18 in the band (border pixels never count): 64 − 9 + 72.
  const int w = 24, h = 20;
  const Rgb8 black{0, 0, 0}, white{255, 255, 255};
  Image a(w, h, black);
  for (int y = 5; y < 15; ++y) {
    for (int x = 5; x < 15; ++x) a.at(x, y) = white;
  }
  for (int y = 0; y < h; ++y) {
    for (int x = 18; x < w; ++x) a.at(x, y) = white;
  }
  a.at(11, 9) = black;
  Image b = a;
  for (auto [x, y] : {std::pair{8, 8}, {10, 12}, {13, 6}}) b.at(x, y) = black;  // 3 holes
  // Misses on the silhouette's edge and on the image border: not holes.
  // (10, 8) touches the gap diagonally only.
  for (auto [x, y] :
       {std::pair{5, 5}, {14, 10}, {9, 5}, {5, 9}, {18, 10}, {23, 10}, {20, 0}, {10, 8}}) {
    b.at(x, y) = black;
  }
  b.at(2, 2) = white;  // extra foreground in the test image: not a hole either

  const std::vector<std::uint8_t> ma = foreground_mask(a.view(), black);
  const std::vector<std::uint8_t> mb = foreground_mask(b.view(), black);
  const HoleCount holes = count_holes(w, h, ma, mb);
  EXPECT_EQ(holes.interior_count, 127u);
  EXPECT_EQ(holes.hole_count, 3u);

  const ImageComparison c = compare_images(a.view(), b.view());
  EXPECT_EQ(c.interior_count, 127u);
  EXPECT_EQ(c.hole_count, 3u);
  // Reference: 99 + 6·20 px; test: 11 missing, 1 extra.
  EXPECT_EQ(c.reference_foreground_count, 219u);
  EXPECT_EQ(c.test_foreground_count, 209u);
  EXPECT_NEAR(c.silhouette_iou, 208.0 / 220.0, 1e-12);
}

TEST(ImageCompare, IdenticalImagesScorePerfectly) {
  Image a(40, 30, gray(0));
  draw_disc(a, 20, 15, 10, {10, 200, 90});
  const ImageComparison c = compare_images(a.view(), a.view());
  EXPECT_EQ(c.psnr_db, std::numeric_limits<double>::infinity());
  EXPECT_NEAR(c.ssim, 1.0, 1e-12);
  EXPECT_EQ(c.silhouette_iou, 1.0);
  EXPECT_EQ(c.hole_count, 0u);
  EXPECT_GT(c.interior_count, 0u);
}
