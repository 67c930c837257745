// Single splats against analytic pixel sets and hand-computed shading.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>

#include "pointillist/core/error.hpp"
#include "pointillist/render/render.hpp"
#include "render_test_util.hpp"

using namespace pointillist;
using namespace pointillist::render_test;

namespace {

// Compares the covered pixels with an analytic set given as a signed function (≤ 0 inside);
// pixels whose centre is within `band` of the boundary (|g| < band) are not compared.
// Returns the number of pixels compared and inside.
struct SetCheck {
  int mismatches = 0, inside = 0;
};
SetCheck compare_pixel_set(const Frame& f, const std::function<double(double, double)>& g,
                           double band) {
  SetCheck r;
  for (int j = 0; j < f.height; ++j) {
    for (int i = 0; i < f.width; ++i) {
      const double v = g(i + 0.5, j + 0.5);
      if (std::abs(v) < band) continue;
      const bool want = v < 0;
      r.inside += want;
      r.mismatches += want != covered(f, i, j);
    }
  }
  return r;
}

Frame render_one(const SphereTree& tree, const Camera& cam, RenderSettings s = {},
                 unsigned threads = 1) {
  ThreadPool pool(threads);
  Frame f;
  render(tree.view(), cam, s, pool, f);
  return f;
}

}  // namespace

TEST(SplatRaster, SingleLeafHasAnalyticCentreDiameterAndDepth) {
  const Camera cam = axis_camera(64, 48);
  const double f = focal_px(cam);
  const SphereTree tree = single_leaf_tree(leaf({0.3f, -0.2f, -4.0f}, 0.25f, {0, 0, 1}));
  const Frame frame = render_one(tree, cam);
  ASSERT_EQ(frame.splats.size(), 1u);
  const SplatChunk* chunk = nullptr;
  for (std::size_t c = 0; c < frame.splats.chunk_count; ++c) {
    if (frame.splats.chunks[c].count) chunk = &frame.splats.chunks[c];
  }
  ASSERT_NE(chunk, nullptr);
  const double x = 32 + f * 0.3 / 4, y = 24 - f * -0.2 / 4, d = 2 * 0.25 * f / 4;
  EXPECT_NEAR(chunk->x_px[0], x, 1e-4);
  EXPECT_NEAR(chunk->y_px[0], y, 1e-4);
  EXPECT_NEAR(chunk->size_px[0], d, 1e-4);
  EXPECT_EQ(chunk->depth[0], 4.0f);
  EXPECT_EQ(chunk->node[0], 0u);
  EXPECT_EQ(frame.stats.splats, 1u);
  EXPECT_EQ(frame.stats.width, 64);
  EXPECT_EQ(frame.stats.height, 48);

  const SetCheck c = compare_pixel_set(
      frame, [&](double px, double py) { return std::hypot(px - x, py - y) - d / 2; }, 1e-3);
  EXPECT_EQ(c.mismatches, 0);
  EXPECT_GT(c.inside, 15);
  for (std::size_t i = 0; i < frame.depth.size(); ++i) {
    if (std::isfinite(frame.depth[i])) {
      EXPECT_EQ(frame.depth[i], 4.0f);
    }
  }
}

TEST(SplatRaster, SquareCoversPixelCentresInsideTheSquare) {
  const Camera cam = axis_camera(64, 48);
  const double f = focal_px(cam);
  const SphereTree tree = single_leaf_tree(leaf({-0.21f, 0.13f, -3.0f}, 0.3f, {0, 0, 1}));
  RenderSettings s;
  s.shape = SplatShape::Square;
  const Frame frame = render_one(tree, cam, s);
  const double x = 32 + f * -0.21 / 3, y = 24 - f * 0.13 / 3, half = 0.3 * f / 3;
  const SetCheck c = compare_pixel_set(
      frame,
      [&](double px, double py) { return std::max(std::abs(px - x), std::abs(py - y)) - half; },
      1e-3);
  EXPECT_EQ(c.mismatches, 0);
  EXPECT_GT(c.inside, 30);
}

TEST(SplatRaster, EllipseOfTiltedDiscHasMinorOverMajorEqualToCosineOfTilt) {
  const Camera cam = axis_camera(64, 48);
  const double f = focal_px(cam);
  RenderSettings s;
  s.shape = SplatShape::Ellipse;
  const double radius_px = 0.5 * 2 * 0.6 * f / 3;  // semi-major axis
  struct Case {
    Vec3f normal;
    double minor_over_major;
    bool minor_along_x;
  };
  const float s60 = std::sin(60.0f * kPi / 180), c60 = std::cos(60.0f * kPi / 180);
  for (const Case& k : {Case{{s60, 0, c60}, 0.5, true}, Case{{0, s60, c60}, 0.5, false},
                        Case{{1, 0, 0}, 0.1, true},  // seen edge on: clamped to 0.1
                        Case{{0, 0, 1}, 1.0, true}}) {
    const SphereTree tree = single_leaf_tree(leaf({0, 0, -3.0f}, 0.6f, k.normal));
    const Frame frame = render_one(tree, cam, s);
    const double a = radius_px * k.minor_over_major;  // semi-minor
    const SetCheck c = compare_pixel_set(
        frame,
        [&](double px, double py) {
          const double dx = px - 32, dy = py - 24;
          const double u = k.minor_along_x ? dx : dy, w = k.minor_along_x ? dy : dx;
          return std::sqrt(u * u / (a * a) + w * w / (radius_px * radius_px)) - 1;
        },
        1e-3);
    EXPECT_EQ(c.mismatches, 0) << "ratio " << k.minor_over_major;
    EXPECT_GT(c.inside, 10);
  }
}

TEST(SplatRaster, TinySplatCoversExactlyThePixelHoldingItsCentre) {
  const Camera cam = axis_camera(64, 48);
  const double f = focal_px(cam);
  for (SplatShape shape : {SplatShape::Square, SplatShape::Circle, SplatShape::Ellipse}) {
    RenderSettings s;
    s.shape = shape;
    const SphereTree tree = single_leaf_tree(leaf({0.123f, 0.0456f, -2.0f}, 1e-4f, {0, 0, 1}));
    const Frame frame = render_one(tree, cam, s);
    const int pi = static_cast<int>(std::floor(32 + f * 0.123 / 2));
    const int pj = static_cast<int>(std::floor(24 - f * 0.0456 / 2));
    int count = 0;
    for (int j = 0; j < 48; ++j)
      for (int i = 0; i < 64; ++i) count += covered(frame, i, j);
    EXPECT_EQ(count, 1);
    EXPECT_TRUE(covered(frame, pi, pj));
  }
}

TEST(SplatRaster, NothingDrawnLeavesBackgroundAndInfiniteDepth) {
  const Camera cam = axis_camera(40, 30);
  RenderSettings s;
  s.background = {10, 20, 30};
  // One leaf behind the eye, then one splat far to the side (outside the image).
  for (Vec3f c : {Vec3f{0, 0, 2}, Vec3f{50, 0, -2}}) {
    const Frame frame = render_one(single_leaf_tree(leaf(c, 0.1f, {0, 0, 1})), cam, s, 2);
    for (std::size_t i = 0; i < frame.color.size(); ++i) {
      ASSERT_EQ(frame.color[i], (Rgb8{10, 20, 30}));
      ASSERT_EQ(frame.depth[i], std::numeric_limits<float>::infinity());
    }
  }
  // Around a drawn splat the rest stays background too.
  const Frame frame = render_one(single_leaf_tree(leaf({0, 0, -2}, 0.05f, {0, 0, 1})), cam, s);
  EXPECT_EQ(frame.color[0], (Rgb8{10, 20, 30}));
  EXPECT_EQ(frame.depth[0], std::numeric_limits<float>::infinity());
  EXPECT_TRUE(covered(frame, 20, 15));
}

TEST(SplatRaster, SplatFacingTheHeadlightGetsAmbientPlusDiffusePlusSpecular) {
  const Camera cam = axis_camera(41, 31);  // odd: the image centre is a pixel centre
  RenderSettings s;
  const Frame frame = render_one(single_leaf_tree(leaf({0, 0, -3}, 0.2f, {0, 0, 1})), cam, s);
  // n = v = l: n·l = 1, n·h = 1 → 0.8·(0.08 + 0.85) + 0.25 = 0.994 → round(253.47) = 253.
  const Rgb8 c = frame.color[15 * 41 + 20];
  EXPECT_EQ(c, (Rgb8{253, 253, 253}));
}

TEST(SplatRaster, ShadingMatchesBlinnPhongComputedByHand) {
  const Camera cam = axis_camera(41, 31);
  struct Case {
    Vec3f light, normal;
    bool colored;
  };
  for (const Case& t : {Case{{1, 0, 1}, {0, 0, 1}, false}, Case{{1, 0, 1}, {0, 0, 1}, true},
                        Case{{0, 1, 2}, {0.6f, 0, 0.8f}, true},
                        Case{{1, 0, 0}, {-0.6f, 0, 0.8f}, false}}) {  // light behind: ambient
    RenderSettings s;
    s.light_dir_eye = t.light;
    s.base_color = {0.7f, 0.5f, 0.3f};
    const Rgb8 node_color{200, 100, 50};
    const SphereTree tree = single_leaf_tree(leaf({0, 0, -3}, 0.2f, t.normal, node_color), t.colored);
    const Frame frame = render_one(tree, cam, s);
    // By hand, in double: eye space = world space here, v = (0, 0, 1) at the image centre.
    const double ll = std::sqrt(double(t.light.x) * t.light.x + double(t.light.y) * t.light.y +
                                double(t.light.z) * t.light.z);
    const double l[3] = {t.light.x / ll, t.light.y / ll, t.light.z / ll};
    const double n[3] = {t.normal.x, t.normal.y, t.normal.z};
    const double ndl = n[0] * l[0] + n[1] * l[1] + n[2] * l[2];
    double hv[3] = {l[0], l[1], l[2] + 1};
    const double hl = std::sqrt(hv[0] * hv[0] + hv[1] * hv[1] + hv[2] * hv[2]);
    const double ndh = (n[0] * hv[0] + n[1] * hv[1] + n[2] * hv[2]) / hl;
    const double spec = ndl > 0 ? 0.25 * std::pow(std::max(ndh, 0.0), 32.0) : 0.0;
    const double diff = 0.08 + 0.85 * std::max(ndl, 0.0);
    const double base[3] = {t.colored ? 200 / 255.0 : 0.7, t.colored ? 100 / 255.0 : 0.5,
                            t.colored ? 50 / 255.0 : 0.3};
    const Rgb8 got = frame.color[15 * 41 + 20];
    const int channels[3] = {got.r, got.g, got.b};
    for (int ch = 0; ch < 3; ++ch) {
      const double want = std::clamp(base[ch] * diff + spec, 0.0, 1.0) * 255;
      EXPECT_NEAR(channels[ch], want, 0.51 + 0.25 * 255 * 1e-3) << "channel " << ch;
    }
  }
}

TEST(SplatRaster, EqualDepthGoesToTheSmallerColourInAnyOrderAndThreadCount) {
  const Camera cam = axis_camera(64, 48);
  // Three splats at one depth over the centre pixel, in every order of the stream: the pixel
  // shows the splat whose packed colour r | g << 8 | b << 16 is smallest, whatever came first.
  // Shaded with the white highlight: red → (255, 64, 64) = 0x4040FF, green → (64, 255, 64) =
  // 0x40FF40, blue → (64, 64, 255) = 0xFF4040; the smallest is red.
  const SphereNode red = leaf({0, 0, -2}, 0.3f, {0, 0, 1}, {255, 0, 0});
  const SphereNode green = leaf({0.01f, 0, -2}, 0.3f, {0, 0, 1}, {0, 255, 0});
  const SphereNode blue = leaf({0, 0.01f, -2}, 0.3f, {0, 0, 1}, {0, 0, 255});
  const std::vector<std::vector<SphereNode>> orders = {
      {red, green, blue}, {green, red, blue}, {blue, green, red}, {green, blue, red}};
  for (const auto& order : orders) {
    const SphereTree tree = root_with_leaves(order, true);
    for (unsigned threads : {1u, 2u, 3u}) {
      const Frame frame = render_one(tree, cam, {}, threads);
      EXPECT_EQ(frame.color[24 * 64 + 32], (Rgb8{255, 64, 64})) << threads;
    }
  }
  // Without red, green (0x40FF40) beats blue (0xFF4040) in either order.
  for (const auto& order : std::vector<std::vector<SphereNode>>{{green, blue}, {blue, green}}) {
    EXPECT_EQ(render_one(root_with_leaves(order, true), cam, {}, 2).color[24 * 64 + 32],
              (Rgb8{64, 255, 64}));
  }
  // A nearer later splat wins whatever its colour.
  const SphereTree nearer = root_with_leaves(
      {leaf({0, 0, -2}, 0.3f, {0, 0, 1}, {255, 0, 0}), leaf({0, 0, -1.9f}, 0.3f, {0, 0, 1}, {0, 0, 255})},
      true);
  EXPECT_EQ(render_one(nearer, cam, {}, 2).color[24 * 64 + 32], (Rgb8{64, 64, 255}));
}

TEST(SplatRaster, RejectsInvalidSettings) {
  const Camera cam = axis_camera(16, 16);
  const SphereTree tree = single_leaf_tree(leaf({0, 0, -2}, 0.1f, {0, 0, 1}));
  ThreadPool pool(1);
  Frame f;
  for (float t : {0.0f, -1.0f, std::numeric_limits<float>::quiet_NaN(),
                  std::numeric_limits<float>::infinity()}) {
    RenderSettings s;
    s.threshold_px = t;
    EXPECT_THROW(render(tree.view(), cam, s, pool, f), OptionError) << t;
  }
  RenderSettings dark;
  dark.light_dir_eye = {0, 0, 0};
  EXPECT_THROW(render(tree.view(), cam, dark, pool, f), OptionError);
  Camera bad = cam;
  bad.width = 0;
  EXPECT_THROW(render(tree.view(), bad, {}, pool, f), OptionError);
  try {
    RenderSettings s;
    s.threshold_px = -2;
    render(tree.view(), cam, s, pool, f);
  } catch (const OptionError& e) {
    EXPECT_NE(std::string(e.what()).find("threshold"), std::string::npos) << e.what();
  }
}

TEST(SplatRaster, ImagesNarrowerThanFourPixelsUseTheSameRule) {
  const double f = focal_px(axis_camera(3, 5));
  for (SplatShape shape : {SplatShape::Square, SplatShape::Circle, SplatShape::Ellipse}) {
    RenderSettings s;
    s.shape = shape;
    const Camera cam = axis_camera(3, 5);
    const Frame frame = render_one(single_leaf_tree(leaf({0.0f, 0.0f, -2.0f}, 0.6f, {0, 0, 1})),
                                   cam, s, 2);
    const double x = 1.5, y = 2.5, r = 0.6 * f / 2;  // 1.3 px
    const SetCheck c = compare_pixel_set(
        frame,
        [&](double px, double py) {
          return shape == SplatShape::Square
                     ? std::max(std::abs(px - x), std::abs(py - y)) - r
                     : std::hypot(px - x, py - y) - r;
        },
        1e-3);
    EXPECT_EQ(c.mismatches, 0) << int(shape);
    EXPECT_GT(c.inside, 2);
  }
}

TEST(SplatRaster, SplatsNextToTheEyeAreDroppedOrClippedSafely) {
  const Camera cam = axis_camera(32, 24);
  for (SplatShape shape : {SplatShape::Square, SplatShape::Circle, SplatShape::Ellipse}) {
    RenderSettings s;
    s.shape = shape;
    // A hair in front of the eye, off axis: projects beyond 1e9 px and is dropped.
    const Frame hair = render_one(single_leaf_tree(leaf({1, 0, -1e-30f}, 0.1f, {0, 0, 1})), cam, s);
    EXPECT_EQ(hair.stats.splats, 0u);
    // Close and huge: a splat far bigger than the image covers every pixel.
    const Frame huge = render_one(single_leaf_tree(leaf({0, 0, -1e-3f}, 10.0f, {0, 0, 1})), cam, s, 2);
    EXPECT_EQ(huge.stats.splats, 1u);
    for (std::size_t i = 0; i < huge.depth.size(); ++i) ASSERT_EQ(huge.depth[i], 1e-3f) << i;
  }
}
