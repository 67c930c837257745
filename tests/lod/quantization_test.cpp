// Quantized normals: the atan-free cell lookup against QSplat's own cells.
#include "pointillist/lod/quantization.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

namespace pointillist {
namespace {

TEST(NormalCodes, CellBoundsGiveQSplatsCodes) {
  // The oracle: QSplat's own atan-warped cells (encode_normal). Random directions, the cube's
  // edges and corners, components at and beside every cell boundary of the atan grid, and
  // vectors that are not unit length, zero or NaN.
  std::mt19937 rng(7);
  std::normal_distribution<float> g(0.0f, 1.0f);
  std::vector<Vec3f> normals;
  for (int i = 0; i < 200000; ++i) normals.push_back(normalized(Vec3f{g(rng), g(rng), g(rng)}));
  for (int cell = 0; cell <= quant::kNormalGrid; ++cell) {
    // where normal_cell's warped value crosses cell boundary `cell`
    const double w = 2.0 * cell / quant::kNormalGrid - 1.0;
    const float t = float(std::tan(w * std::numbers::pi / 4.0));
    for (float s : {std::nextafter(t, -2.0f), t, std::nextafter(t, 2.0f)}) {
      normals.push_back({1.0f, s, 0.3f});
      normals.push_back({-0.2f, -1.0f, s});
      normals.push_back({s, -0.7f, 1.0f});
    }
  }
  for (const Vec3f n : {Vec3f{1, 1, 1}, Vec3f{-1, 1, 0}, Vec3f{0, 0, -1}, Vec3f{3, -2, 0.5f},
                        Vec3f{0, 0, 0}, Vec3f{std::nanf(""), 0.5f, 0.5f}, Vec3f{-0.0f, 0, 1}}) {
    normals.push_back(n);
  }
  std::size_t differ = 0;
  for (const Vec3f n : normals) differ += quant::encode_normal_by_bounds(n) != quant::encode_normal(n);
  EXPECT_EQ(differ, 0u) << "of " << normals.size();
}

}  // namespace
}  // namespace pointillist
