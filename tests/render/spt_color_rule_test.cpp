// The colour rule of the Sequential Point Tree (spec occlusion-simplification-hybrid.md §3.2):
// on a plane with a fine colour checkerboard the rule keeps the detail that the geometric error
// alone would average away (PSNR against a full-detail render at least 3 dB higher with it), and
// on a plane of smooth colour it costs no extra splats.
#include <gtest/gtest.h>

#include <cmath>

#include "pointillist/eval/image_compare.hpp"
#include "pointillist/lod/sequential_point_tree.hpp"
#include "pointillist/render/render.hpp"
#include "pointillist/render/spt_render.hpp"

using namespace pointillist;

namespace {

constexpr int kSide = 256;  // samples along each side of the unit plane

// The unit square on z = 0 sampled on a grid, normals +z, discs that cover it; colour from
// `color(i, j)`.
template <class Color>
PointSet plane(const Color& color) {
  PointSet p;
  const float h = 1.0f / kSide;
  for (int j = 0; j < kSide; ++j) {
    for (int i = 0; i < kSide; ++i) {
      p.positions.push_back({(i + 0.5f) * h - 0.5f, (j + 0.5f) * h - 0.5f, 0});
      p.normals.push_back({0, 0, 1});
      p.radii.push_back(0.75f * h);
      p.colors.push_back(color(i, j));
    }
  }
  return p;
}

// Squares of 2 samples: period 4 × the leaf spacing.
PointSet checkerboard() {
  return plane([](int i, int j) {
    const bool white = ((i / 2) + (j / 2)) % 2 == 0;
    return white ? Rgb8{240, 240, 240} : Rgb8{20, 20, 20};
  });
}

PointSet smooth() {
  return plane([](int i, int j) {
    return Rgb8{static_cast<std::uint8_t>(i * 255 / kSide), static_cast<std::uint8_t>(j * 255 / kSide),
                128};
  });
}

Frame draw(const SequentialPointTree& tree, float distance, float epsilon_px, ThreadPool& pool) {
  // Looking at the plane from `distance` model radii, obliquely (facing it squarely, every
  // splat would be at the same depth and overlaps would go to the darker colour).
  Camera cam = orbit_camera(tree.view_sphere, {.azimuth_deg = 0, .elevation_deg = 3,
                                               .distance = distance, .width = 768, .height = 768});
  RenderSettings s;
  s.ambient = 1.0f;  // unlit: the splats' own colours
  s.diffuse = 0.0f;
  s.specular = 0.0f;
  Frame f;
  render_spt(tree, cam, s, {.epsilon_px = epsilon_px}, pool, f);
  return f;
}

ImageRgb8View view_of(const Frame& f) { return {f.width, f.height, f.color}; }

}  // namespace

TEST(SptColorRule, KeepsACheckerboardsDetail) {
  ThreadPool pool(2);
  const PointSet board = checkerboard();
  const SequentialPointTree with_rule = build_sequential_point_tree(board, pool);
  const SequentialPointTree without =
      build_sequential_point_tree(board, pool, Progress::none(), {.color_tolerance = INFINITY});
  for (const float d : {4.0f, 8.0f, 12.0f}) {
    const Frame full = draw(with_rule, d, 1e-6f, pool);  // every leaf
    const Frame a = draw(with_rule, d, 1.0f, pool);
    const Frame b = draw(without, d, 1.0f, pool);
    const double pa = psnr_rgb(view_of(full), view_of(a));
    const double pb = psnr_rgb(view_of(full), view_of(b));
    EXPECT_GE(pa - pb, 3.0) << "distance " << d << ": " << pa << " dB with the rule, " << pb
                            << " dB without (" << a.stats.splats << " and " << b.stats.splats
                            << " splats)";
  }
}

TEST(SptColorRule, CostsNothingWhereColourIsSmooth) {
  ThreadPool pool(2);
  const PointSet soft = smooth();
  const SequentialPointTree with_rule = build_sequential_point_tree(soft, pool);
  const SequentialPointTree without =
      build_sequential_point_tree(soft, pool, Progress::none(), {.color_tolerance = INFINITY});
  for (const float d : {2.0f, 4.0f, 8.0f}) {
    const Frame a = draw(with_rule, d, 1.0f, pool);
    const Frame b = draw(without, d, 1.0f, pool);
    EXPECT_LE(double(a.stats.splats), 1.05 * double(b.stats.splats)) << "distance " << d;
  }
}
