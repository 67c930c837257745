// What the tests of rendering with sharp features share: the CSG test scenes as models with a
// colour per surface, unlit renders, and counts against the exact ray-cast reference.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "pointillist/eval/label_metrics.hpp"
#include "pointillist/format/ptl_v2.hpp"
#include "pointillist/format/ptl_v2_pages.hpp"
#include "pointillist/lod/tree_features.hpp"
#include "pointillist/prep/radii.hpp"
#include "pointillist/render/renderer.hpp"
#include "pointillist/scene/csg.hpp"
#include "testing/testing.hpp"

namespace features_test {

using namespace pointillist;

// Eight colours that RGB 565 keeps exactly (a .ptl v2 file stores colours so).
constexpr Rgb8 kColors[8] = {{255, 0, 0},     {0, 255, 0},   {0, 0, 255},     {255, 255, 0},
                             {0, 255, 255},   {255, 0, 255}, {255, 255, 255}, {132, 130, 132}};

// A scene's samples with a colour per surface: faces on one plane share it (the step's front
// faces are one surface), and the reference uses the same map.
struct Model {
  CsgScene scene;
  SphereTree tree;
  TreeFeatures features;
  RenderModel render;
  std::vector<int> colour_of_label;
};

inline std::unique_ptr<Model> make_model(const std::string& id, ThreadPool& pool, bool quantized = false,
                                  SamplingMode mode = SamplingMode::Jittered,
                                  std::uint64_t seed = 9);

// Spec §4.1: J mode, radius = the mean distance to the 5 nearest (coverage 1); R mode, uniform
// random samples with Pointillist's default radii (coverage 2.5).
inline std::unique_ptr<Model> make_model(const std::string& id, ThreadPool& pool, bool quantized,
                                  SamplingMode mode, std::uint64_t seed) {
  auto m = std::make_unique<Model>();
  m->scene = csg_scene(id);
  CsgSamples s = sample_csg(m->scene, mode, seed);
  CloudRadiusOptions radius;
  if (mode == SamplingMode::Jittered) radius.coverage = 1.0f;
  s.points.radii = cloud_radii(s.points.positions, pool, Progress::none(), radius);
  // A colour per surface of the result (faces on one plane share it).
  const std::vector<std::uint32_t> group = csg_surface_groups(m->scene, s);
  for (const std::uint32_t g : group) m->colour_of_label.push_back(int(g % 8));
  for (std::uint32_t l : s.labels) s.points.colors.push_back(kColors[m->colour_of_label[l]]);
  m->tree = build_sphere_tree(s.points, pool);
  if (quantized) {
    // As a .ptl v2 file stores it (quantized centres, normals, radii, colours).
    pointillist::testing::TempDir dir;
    write_ptl_v2(dir.file("m.ptl"), m->tree, "");
    m->tree = PtlV2File::open(dir.file("m.ptl"))->decode_all();
  }
  FeatureOptions options;
  if (quantized) options = for_quantized_model(options);
  m->features = compute_tree_features(m->tree.view(), pool, options);
  m->render.tree = m->tree.view();
  m->render.tree.features = &m->features;
  return m;
}

struct Image {
  std::vector<Rgb8> color;
  int width = 0, height = 0;
};

// Unlit: each splat its own colour.
inline RenderSettings unlit() {
  RenderSettings settings;
  settings.ambient = 1.0f;
  settings.diffuse = 0.0f;
  settings.specular = 0.0f;
  return settings;
}

inline Image render(const Model& m, const Camera& camera, ThreadPool& pool, bool features,
             Rasterizer rasterizer = Rasterizer::Quality, LodScheme lod = LodScheme::QSplat) {
  const RenderSettings settings = unlit();
  FrameSettings fs;
  fs.rasterizer = rasterizer;
  fs.features = features;
  fs.lod = lod;
  Renderer renderer;
  Frame frame;
  const SceneInstance instance{&m.render, {}};
  renderer.render({&instance, 1}, camera, settings, fs, pool, frame);
  return {std::vector<Rgb8>(frame.color.begin(), frame.color.end()), frame.width, frame.height};
}

struct LabelMetrics {
  std::size_t covered = 0;  // reference pixels on a surface, away from the silhouette
  std::size_t holes = 0;    // of those, background in the test
  std::size_t wrong = 0;    // of those, a pure colour of another surface
  std::size_t mixed = 0;    // of those, no pure colour at all (blended surfaces)
};

// Counts over reference pixels more than 2 px (Chebyshev) from the silhouette.
inline LabelMetrics measure(const Model& m, const Camera& camera, const Image& img) {
  const CsgImage ref = ray_cast_csg_image(m.scene, camera);
  LabelMetrics out;
  const auto covered = [&](int x, int y) {
    return x >= 0 && y >= 0 && x < ref.width && y < ref.height &&
           ref.label[std::size_t(y) * ref.width + x] != kNoLabel;
  };
  for (int y = 0; y < ref.height; ++y) {
    for (int x = 0; x < ref.width; ++x) {
      bool interior = true;
      for (int dy = -2; dy <= 2 && interior; ++dy) {
        for (int dx = -2; dx <= 2 && interior; ++dx) interior = covered(x + dx, y + dy);
      }
      if (!interior) continue;
      const std::size_t p = std::size_t(y) * ref.width + x;
      ++out.covered;
      const Rgb8 got = img.color[p];
      if (got == Rgb8{0, 0, 0}) {
        ++out.holes;
        continue;
      }
      const Rgb8 want = kColors[m.colour_of_label[ref.label[p]]];
      if (got == want) continue;
      bool pure = false;
      for (Rgb8 c : kColors) pure = pure || c == got;
      ++(pure ? out.wrong : out.mixed);
    }
  }
  return out;
}

inline Camera look(Vec3f eye, Vec3f target, int size = 256) {
  Camera c;
  c.eye = eye;
  c.target = target;
  c.width = c.height = size;
  return c;
}

// The reference of spec §4.1 as an image: each pixel the colour of its face (black: background).
inline Image reference_image(const Model& m, const Camera& camera) {
  const CsgImage ref = ray_cast_csg_image(m.scene, camera);
  Image out{std::vector<Rgb8>(ref.label.size(), Rgb8{0, 0, 0}), ref.width, ref.height};
  for (std::size_t p = 0; p < ref.label.size(); ++p) {
    if (ref.label[p] != kNoLabel) out.color[p] = kColors[m.colour_of_label[ref.label[p]]];
  }
  return out;
}

inline LabelComparison label_metrics(const Model& m, const Camera& camera, const Image& test) {
  const Image ref = reference_image(m, camera);
  LabelCompareOptions o;
  o.palette = kColors;
  o.background = Rgb8{0, 0, 0};
  return compare_labels({ref.width, ref.height, ref.color}, {test.width, test.height, test.color},
                        o);
}

// A 512-px close-up of a crease in both modes: no hole, at most 0.5 % wrong-face pixels, and
// (check_mixed) no blended pixel.
inline void expect_close_up_without_holes(const char* id, const Model& m, const Camera& cam,
                                          ThreadPool& pool, bool check_mixed) {
  for (Rasterizer r : {Rasterizer::Quality, Rasterizer::Fast}) {
    const LabelMetrics with = measure(m, cam, render(m, cam, pool, true, r));
    std::cout << id << " " << (r == Rasterizer::Fast ? "fast" : "quality") << ": covered "
              << with.covered << " wrong " << with.wrong << " mixed " << with.mixed << " holes "
              << with.holes << "\n";
    EXPECT_GT(with.covered, 100000u) << id;
    EXPECT_EQ(with.holes, 0u) << id;
    if (check_mixed) {
      EXPECT_EQ(with.mixed, 0u) << id;
    }
    EXPECT_LE(with.wrong, with.covered / 200) << id;
  }
}

}  // namespace features_test
