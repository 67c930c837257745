// Depth image mapping and the point projection baseline.
#include <gtest/gtest.h>

#include <limits>

#include "pointillist/render/depth_image.hpp"
#include "render/point_baseline.hpp"
#include "render_test_util.hpp"

using namespace pointillist;
using namespace pointillist::render_test;

TEST(DepthImage, MapsNearestToZeroFarthestTo65534AndBackgroundTo65535) {
  constexpr float kInf = std::numeric_limits<float>::infinity();
  Frame f;
  f.width = 5;
  f.height = 1;
  f.depth = {2.0f, 4.0f, kInf, 3.0f, 2.5f};
  const std::vector<std::uint16_t> g = depth_to_gray16(f);
  ASSERT_EQ(g.size(), 5u);
  EXPECT_EQ(g[0], 0);
  EXPECT_EQ(g[1], 65534);
  EXPECT_EQ(g[2], 65535);
  EXPECT_EQ(g[3], 32767);  // round(65534 · 0.5)
  EXPECT_EQ(g[4], 16384);  // round(65534 · 0.25) = round(16383.5)
  // Explicit range: clamped at both ends.
  const std::vector<std::uint16_t> h = depth_to_gray16(f.depth, 2.5f, 3.0f);
  EXPECT_EQ(h[0], 0);
  EXPECT_EQ(h[1], 65534);
  EXPECT_EQ(h[3], 65534);
  EXPECT_EQ(h[4], 0);
  // A single drawn depth maps to 0; nothing drawn gives all 65535.
  f.depth = {kInf, 7.0f, kInf, kInf, kInf};
  EXPECT_EQ(depth_to_gray16(f)[1], 0);
  f.depth.assign(5, kInf);
  for (std::uint16_t v : depth_to_gray16(f)) EXPECT_EQ(v, 65535);
}

TEST(PointBaseline, KeepsTheNearestDepthOfPointsInTheirPixels) {
  const Camera cam = axis_camera(40, 30);
  const CameraFrame cf = make_camera_frame(cam);
  const double f = focal_px(cam);
  // Two points in the pixel of the image centre (20, 15), one behind the eye, one outside.
  const std::vector<Vec3f> pts = {{0.01f, -0.01f, -3.0f}, {0.02f, -0.02f, -2.5f},
                                  {0, 0, 1.0f}, {100.0f, 0, -1.0f}};
  std::vector<float> depth(40 * 30, -1.0f);
  EXPECT_EQ(project_points_baseline(pts, cf, depth), 2u);
  const int i = int(20 + f * 0.01 / 3), j = int(15 + f * 0.01 / 3);
  ASSERT_EQ(i, int(20 + f * 0.02 / 2.5));
  EXPECT_EQ(depth[j * 40 + i], 2.5f);
  int drawn = 0;
  for (float d : depth) drawn += std::isfinite(d);
  EXPECT_EQ(drawn, 1);
}
