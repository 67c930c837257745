// Normal colours (core/normal_color.hpp): the axes encode to the colours of the usual normal-map
// convention, and the round trip of any unit normal stays within the documented 0.4°.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "pointillist/core/normal_color.hpp"

using namespace pointillist;

TEST(NormalColor, AxesEncodeToTheNormalMapConvention) {
  EXPECT_EQ(encode_normal_color({0, 0, 1}), (Rgb8{128, 128, 255}));
  EXPECT_EQ(encode_normal_color({1, 0, 0}), (Rgb8{255, 128, 128}));
  EXPECT_EQ(encode_normal_color({0, -1, 0}), (Rgb8{128, 0, 128}));
  // Out of range and NaN components clamp (NaN to 0) instead of wrapping around.
  EXPECT_EQ(encode_normal_color({3, -2, std::nanf("")}), (Rgb8{255, 0, 0}));
  EXPECT_NEAR(decode_normal_color(Rgb8{128, 128, 255}).z, 1.0f, 1e-4f);
  EXPECT_NEAR(decode_normal_color(Rgb8{128, 128, 255}).x, 0.0f, 0.004f);
}

TEST(NormalColor, RoundTripStaysWithinFourTenthsOfADegree) {
  std::mt19937 rng(7);
  std::normal_distribution<float> g;
  double worst = 0;
  for (int i = 0; i < 100000; ++i) {
    const Vec3f n = normalized(Vec3f{g(rng), g(rng), g(rng)});
    const Vec3f back = decode_normal_color(encode_normal_color(n));
    EXPECT_NEAR(length(back), 1.0f, 1e-5f);
    const double c = std::min(1.0, std::max(-1.0, static_cast<double>(dot(n, back))));
    worst = std::max(worst, std::acos(c) * 180.0 / 3.141592653589793);
  }
  EXPECT_LT(worst, 0.4);
  EXPECT_GT(worst, 0.1);  // the 8-bit rounding is really there
}

TEST(NormalColor, GreyHasNoNormal) {
  const Vec3f zero = decode_normal_color(Rgb8{128, 127, 128});
  EXPECT_EQ(zero.x, 0.0f);
  EXPECT_EQ(zero.y, 0.0f);
  EXPECT_EQ(zero.z, 0.0f);
}
