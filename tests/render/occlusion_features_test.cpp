// Occlusion culling in quality mode with sharp features: the per-surface rule blends a pixel
// from its front fragment's surface only, up to that fragment's own bound, so the occluders
// bound it with the widest bound any drawn splat can have (quality_occluders.hpp). Every method
// must give the image of no culling, bit for bit, along a camera path, for both reconstruction
// rules, thread counts and latencies; and culling must still skip what is hidden.
#include <gtest/gtest.h>

#include <vector>

#include "render/features_render_support.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/pipeline/scene.hpp"
#include "render_test_util.hpp"

using namespace pointillist;
using namespace features_test;
using pointillist::render_test::capture;
using pointillist::render_test::same_bits;
using pointillist::render_test::Shot;
using pointillist::render_test::StrafePath;


namespace {

struct FeatureScene {
  std::unique_ptr<features_test::Model> cube, spheres, step;
  std::vector<SceneInstance> instances;

  explicit FeatureScene(ThreadPool& pool) {
    cube = make_model("T1", pool, false, SamplingMode::Random, 3);
    spheres = make_model("T9", pool, false, SamplingMode::Random, 3);
    step = make_model("T8", pool, false, SamplingMode::Jittered, 3);
    // A large cube in front hides a row of models behind it; two stand past its side (seen as
    // the camera moves), one half hidden above it, one in front.
    instances.push_back({&cube->render, make_transform({0, 0, 0}, {0, 0, 0}, 2.0f)});
    for (int i = 0; i < 4; ++i) {
      const features_test::Model& m = i % 2 == 0 ? *spheres : *step;
      instances.push_back({&m.render, make_transform({-1.5f + 1.0f * float(i), 0.0f, -4.0f},
                                                     {0, 30.0f * float(i), 0}, 0.5f)});
    }
    instances.push_back({&spheres->render, make_transform({4.0f, 0, -3.0f}, {0, 20, 0}, 0.6f)});
    instances.push_back({&step->render, make_transform({5.5f, 0, -5.0f}, {0, 70, 0}, 0.8f)});
    instances.push_back({&step->render, make_transform({0.5f, 2.4f, -2.0f}, {0, 45, 0}, 0.6f)});
    instances.push_back({&cube->render, make_transform({-1.0f, -0.5f, 3.0f}, {0, 25, 0}, 0.3f)});
  }
};

// Frame k of a strafe from x = 0 to x = 3.
constexpr StrafePath kPath{.span = 3.0f, .eye_y = 1.2f, .target_y = 0.5f, .distance = 9.0f,
                           .fov_deg = 45.0f, .width = 200, .height = 150};
Camera path_camera(int k, int frames) { return kPath.camera(k, frames); }

std::vector<Shot> render_path(const FeatureScene& scene, const FrameSettings& fs,
                              unsigned threads, int frames) {
  return render_test::render_path(scene.instances, kPath, unlit(), fs, threads, frames);
}

}  // namespace

TEST(OcclusionFeatures, QualityModeWithFeaturesGivesTheImageOfNoCulling) {
  ThreadPool build(2);
  const FeatureScene scene(build);
  constexpr int kFrames = 4;
  std::size_t compared = 0, fewer = 0;
  for (Reconstruction rule : {Reconstruction::ZRange, Reconstruction::ZThreshold}) {
    FrameSettings none;
    none.rasterizer = Rasterizer::Quality;
    none.features = true;
    none.quality.reconstruction = rule;
    const std::vector<Shot> want = render_path(scene, none, 2, kFrames);
    for (OcclusionMethod m : {OcclusionMethod::StopAndWait, OcclusionMethod::ChcPlusPlus}) {
      for (unsigned latency : {0u, 2u}) {
        for (unsigned threads : {1u, 2u}) {
          FrameSettings fs = none;
          fs.occlusion.method = m;
          fs.occlusion.query_latency = latency;
          fs.occlusion.leaf_points = 64;
          fs.occlusion.min_query_splats = 0;
          const std::vector<Shot> got = render_path(scene, fs, threads, kFrames);
          for (int k = 0; k < kFrames; ++k) {
            EXPECT_TRUE(same_bits(got[k], want[k]))
                << name(m) << " rule " << int(rule) << " threads " << threads << " latency "
                << latency << " frame " << k;
            fewer += got[k].splats < want[k].splats;
            ++compared;
          }
        }
      }
    }
  }
  EXPECT_EQ(compared, 2u * 2u * 2u * 2u * kFrames);
  // Culling still works with the wider bound: the models behind the big cube are skipped.
  EXPECT_GT(fewer, compared / 2);
}

TEST(OcclusionFeatures, SinglePointLeavesAreCulledWithTheSameImage) {
  // Every splat its own culling leaf, each queried: the finest test of the occluders' bound
  // against fragments of every surface, near the creases and where the spheres cross.
  ThreadPool pool(2);
  const FeatureScene scene(pool);
  for (Reconstruction rule : {Reconstruction::ZRange, Reconstruction::ZThreshold}) {
    FrameSettings fs;
    fs.rasterizer = Rasterizer::Quality;
    fs.features = true;
    fs.quality.reconstruction = rule;
    for (int k = 0; k < 3; ++k) {
      Renderer plain, culled;
      Frame a, b;
      plain.render(scene.instances, path_camera(k, 3), unlit(), fs, pool, a);
      FrameSettings c = fs;
      c.occlusion.method = OcclusionMethod::StopAndWait;
      c.occlusion.leaf_points = 1;
      c.occlusion.min_query_splats = 0;
      culled.render(scene.instances, path_camera(k, 3), unlit(), c, pool, b);
      const Shot want = capture(a);
      const Shot got = capture(b);
      EXPECT_TRUE(same_bits(got, want)) << "rule " << int(rule) << " frame " << k;
      EXPECT_LT(got.splats, want.splats) << "rule " << int(rule) << " frame " << k;
    }
  }
}

TEST(OcclusionFeatures, ListsAndPagesWithFeaturesAreRefusedInQualityMode) {
  ThreadPool pool(1);
  const FeatureScene scene(pool);
  Renderer renderer;
  Frame frame;
  FrameSettings fs;
  fs.rasterizer = Rasterizer::Quality;
  fs.features = true;
  fs.lod = LodScheme::Spt;
  fs.occlusion.method = OcclusionMethod::ChcPlusPlus;
  try {
    renderer.render(scene.instances, path_camera(0, 2), unlit(), fs, pool, frame);
    FAIL() << "--lod spt with features, quality mode and culling was accepted";
  } catch (const OptionError& e) {
    EXPECT_NE(std::string(e.what()).find("--lod spt"), std::string::npos) << e.what();
  }
}

namespace {

// Hand-made features: every node of the tree on one surface, no clip planes.
TreeFeatures one_surface(const SphereTree& tree) {
  TreeFeatures f;
  const std::size_t n = tree.view().nodes.size();
  f.surface.assign(n, 0);
  f.clip_mode.assign(n, ClipMode::None);
  f.clip_offset.assign(n + 1, 0);
  f.surface_count = 1;
  return f;
}

}  // namespace

TEST(OcclusionFeatures, AFrontSurfaceReachingFarBehindItsOccluderKeepsItsSplats) {
  // Surface A is a large disc F tilted 60° (its depth interval, and so its bound, reaches far
  // behind its centre) and a patch of small discs f behind everything; surface B (another model) is a
  // dense plane between them. Where F is in front, the per-surface rule blends A's fragments up
  // to F's bound, so f shows through B's plane there; f lies behind B's discs, which surely
  // cover its pixels, by more than their own bounds. An occluder bound that ignored how far the
  // front surface's bound may reach would cull f and change the image.
  ThreadPool pool(2);
  PointSet a;
  a.positions = {{0, 0, -10}};
  a.normals = {{0, 0.8660254f, 0.5f}};
  a.radii = {1.0f};
  a.colors = {{220, 30, 30}};
  for (int j = 0; j < 8; ++j) {  // the small discs f, a patch around (0, −0.2, −10.8)
    for (int i = 0; i < 8; ++i) {
      a.positions.push_back({-0.07f + 0.02f * float(i), -0.27f + 0.02f * float(j), -10.8f});
      a.normals.push_back({0, 0, 1});
      a.radii.push_back(0.02f);
      a.colors.push_back({30, 30, 220});
    }
  }
  PointSet b;
  for (int j = 0; j <= 50; ++j) {
    for (int i = 0; i <= 60; ++i) {
      b.positions.push_back({-0.6f + 0.02f * float(i), -0.6f + 0.02f * float(j), -10.3f});
      b.normals.push_back({0, 0, 1});
      b.radii.push_back(0.02f);
      b.colors.push_back({30, 200, 30});
    }
  }
  const SphereTree tree_a = build_sphere_tree(a, pool), tree_b = build_sphere_tree(b, pool);
  const TreeFeatures feat_a = one_surface(tree_a), feat_b = one_surface(tree_b);
  RenderModel model_a, model_b, model_f_only;
  model_a.tree = tree_a.view();
  model_a.tree.features = &feat_a;
  model_a.name = "A";
  model_b.tree = tree_b.view();
  model_b.tree.features = &feat_b;
  model_b.name = "B";
  // A without the patch, to check that it shows at all.
  PointSet big = a;
  big.positions.resize(1), big.normals.resize(1), big.radii.resize(1), big.colors.resize(1);
  const SphereTree tree_big = build_sphere_tree(big, pool);
  const TreeFeatures feat_big = one_surface(tree_big);
  model_f_only.tree = tree_big.view();
  model_f_only.tree.features = &feat_big;
  const std::vector<SceneInstance> scene = {{&model_a, {}}, {&model_b, {}}};
  const std::vector<SceneInstance> without_f = {{&model_f_only, {}}, {&model_b, {}}};
  Camera cam;
  cam.eye = {0, 0, 0};
  cam.target = {0, 0, -1};
  cam.fov_deg = 30.0f;
  cam.width = cam.height = 200;
  for (Reconstruction rule : {Reconstruction::ZRange, Reconstruction::ZThreshold}) {
    FrameSettings fs;
    fs.rasterizer = Rasterizer::Quality;
    fs.features = true;
    fs.quality.reconstruction = rule;
    fs.quality.z_threshold = 2.0f;  // F's bound then reaches past f too
    const auto shot = [&](const std::vector<SceneInstance>& s, const FrameSettings& f) {
      Renderer renderer;
      Frame frame;
      renderer.render(s, cam, unlit(), f, pool, frame);
      return capture(frame);
    };
    const Shot want = shot(scene, fs);
    ASSERT_FALSE(same_bits(want, shot(without_f, fs))) << "f does not show: no test";
    FrameSettings culled = fs;
    culled.occlusion.method = OcclusionMethod::StopAndWait;
    culled.occlusion.leaf_points = 1;
    culled.occlusion.min_query_splats = 0;
    // (A bound from B's discs alone culls the patch's 60 leaves and changes the image.)
    EXPECT_TRUE(same_bits(shot(scene, culled), want)) << "rule " << int(rule);
  }
}
