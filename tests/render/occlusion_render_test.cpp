// Occlusion culling in the renderer: every method gives the image of no culling, bit for bit
// (colour and depth), for every kernel, thread count and query latency, frame after frame along
// a camera path; nothing that wins a pixel without culling is culled; and culling does skip the
// models hidden behind the wall.
#include <gtest/gtest.h>

#include <cstring>
#include <iostream>
#include <set>
#include <vector>

#include "pointillist/core/error.hpp"
#include "pointillist/lod/sphere_tree.hpp"
#include "pointillist/pipeline/scene.hpp"
#include "pointillist/render/renderer.hpp"
#include "pointillist/scene/analytic.hpp"
#include "render_test_util.hpp"

using namespace pointillist;
using namespace pointillist::render_test;

namespace {

// A wall x ∈ [−4, 4], y ∈ [0, 3] at z = 0 facing +z (a grid, so that neighbouring splats tie in
// depth when it is seen square on), coloured by position.
PointSet wall_points() {
  PointSet p;
  const float step = 0.05f;
  for (int j = 0; j <= 60; ++j) {
    for (int i = 0; i <= 160; ++i) {
      p.positions.push_back({-4.0f + step * float(i), step * float(j), 0.0f});
      p.normals.push_back({0, 0, 1});
      p.radii.push_back(0.75f * step);
      p.colors.push_back({static_cast<std::uint8_t>(40 + i), static_cast<std::uint8_t>(60 + 3 * j),
                          120});
    }
  }
  return p;
}

// A unit sphere of samples with exact normals; colours unique per sample when `unique`.
PointSet ball_points(std::size_t count, bool unique) {
  SurfaceSamples s = sample_scene(sphere_scene(1.0f), count, 3);
  PointSet p = std::move(s.points);
  p.normals = s.true_normals;
  p.radii.assign(p.positions.size(), 0.09f);
  for (std::size_t i = 0; i < p.positions.size(); ++i) {
    const std::uint32_t c = unique ? static_cast<std::uint32_t>(i + 1) * 2654435761u >> 8
                                   : static_cast<std::uint32_t>(i % 7) * 30u;
    p.colors.push_back({static_cast<std::uint8_t>(c), static_cast<std::uint8_t>(c >> 8),
                        static_cast<std::uint8_t>(c >> 16)});
  }
  return p;
}

struct TestScene {
  SphereTree wall_tree, ball_tree;
  RenderModel wall, ball;
  std::vector<SceneInstance> instances;

  explicit TestScene(bool unique_colors) {
    ThreadPool pool(2);
    wall_tree = build_sphere_tree(wall_points(), pool);
    ball_tree = build_sphere_tree(ball_points(3000, unique_colors), pool);
    wall.tree = wall_tree.view();
    wall.name = "wall";
    ball.tree = ball_tree.view();
    ball.name = "ball";
    instances.push_back({&wall, {}});
    // Balls behind the wall (hidden from the start), two past its end (seen once the camera
    // moves), one in front, one half hidden above its top edge.
    for (int i = 0; i < 5; ++i) {
      for (int k = 0; k < 2; ++k) {
        instances.push_back(
            {&ball, make_transform({-3.2f + 1.6f * float(i), 1.0f, -2.0f - 2.5f * float(k)},
                                   {0, 36.0f * float(i + k), 0}, 0.8f)});
      }
    }
    instances.push_back({&ball, make_transform({6.0f, 1.0f, -3.0f}, {}, 1.0f)});
    instances.push_back({&ball, make_transform({7.5f, 1.0f, -6.0f}, {0, 90, 0}, 1.0f)});
    instances.push_back({&ball, make_transform({-1.5f, 1.0f, 2.5f}, {}, 0.5f)});
    instances.push_back({&ball, make_transform({1.0f, 3.2f, -1.5f}, {}, 0.6f)});
  }
};

// Frame k of a strafe from x = 0 to x = 6 (eye and target together).
constexpr StrafePath kPath{.span = 6.0f, .eye_y = 1.5f, .target_y = 1.5f, .distance = 9.0f,
                           .fov_deg = 40.0f, .width = 160, .height = 120};
Camera path_camera(int k, int frames) { return kPath.camera(k, frames); }

using Image = Shot;

std::vector<Image> render_path(const TestScene& scene, const RenderSettings& settings,
                               const FrameSettings& fs, unsigned threads, int frames) {
  return render_test::render_path(scene.instances, kPath, settings, fs, threads, frames);
}

}  // namespace

TEST(OcclusionRender, EveryMethodGivesTheImageOfNoCullingForEveryKernelThreadsAndLatency) {
  const TestScene scene(false);
  constexpr int kFrames = 6;
  std::size_t compared = 0;
  for (SplatShape shape : {SplatShape::Square, SplatShape::Circle, SplatShape::Ellipse}) {
    RenderSettings settings;
    settings.shape = shape;
    FrameSettings none;
    const std::vector<Image> want = render_path(scene, settings, none, 2, kFrames);
    for (OcclusionMethod m : {OcclusionMethod::StopAndWait, OcclusionMethod::Chc,
                              OcclusionMethod::ChcPlusPlus}) {
      for (unsigned latency : {0u, 2u}) {
        FrameSettings fs;
        fs.occlusion.method = m;
        fs.occlusion.query_latency = latency;
        fs.occlusion.leaf_points = 256;
        std::vector<Image> by_threads[2];
        for (unsigned threads : {1u, 2u}) {
          const std::vector<Image>& got = by_threads[threads - 1] =
              render_path(scene, settings, fs, threads, kFrames);
          for (int k = 0; k < kFrames; ++k) {
            EXPECT_TRUE(same_bits(got[k], want[k]))
                << name(m) << " shape " << int(shape) << " threads " << threads << " latency "
                << latency << " frame " << k;
            ++compared;
            // Culling skips what the wall hides (the balls behind it hold most of the points).
            // Plain CHC with latency queries the balls before the wall's answers arrive, finds
            // them visible, and draws them until their next query n_av frames later (the
            // conservatism CHC++'s batching removes).
            if (latency == 0 || m != OcclusionMethod::Chc) {
              EXPECT_LT(got[k].splats, want[k].splats)
                  << name(m) << " latency " << latency << " frame " << k;
            }
          }
        }
        // What culling does and counts does not depend on the thread count.
        for (int k = 0; k < kFrames; ++k) {
          const Image& a = by_threads[0][k];
          const Image& b = by_threads[1][k];
          EXPECT_EQ(a.splats, b.splats);
          EXPECT_EQ(a.occlusion.queries_single, b.occlusion.queries_single);
          EXPECT_EQ(a.occlusion.queries_multi, b.occlusion.queries_multi);
          EXPECT_EQ(a.occlusion.leaves_culled, b.occlusion.leaves_culled);
          EXPECT_EQ(a.occlusion.flushes, b.occlusion.flushes);
        }
      }
    }
  }
  EXPECT_EQ(compared, 3u * 3u * 2u * 2u * kFrames);
}

TEST(OcclusionRender, NothingThatWinsAPixelWithoutCullingIsCulled) {
  // Unlit, every ball sample has its own colour: the colours of the image without culling are
  // the splats that win a pixel; each must be among the splats the culled frame drew.
  const TestScene scene(true);
  RenderSettings settings;
  settings.ambient = 1.0f;
  settings.diffuse = 0.0f;
  settings.specular = 0.0f;
  settings.threshold_px = 0.5f;
  ThreadPool pool(2);
  for (int k : {0, 3, 5}) {
    const Camera camera = path_camera(k, 6);
    Renderer plain, culled;
    Frame a, b;
    plain.render(scene.instances, camera, settings, {}, pool, a);
    FrameSettings fs;
    fs.occlusion.method = OcclusionMethod::ChcPlusPlus;
    fs.occlusion.leaf_points = 128;
    culled.render(scene.instances, camera, settings, fs, pool, b);
    std::set<std::uint32_t> drawn;
    for (std::size_t c = 0; c < b.splats.chunk_count; ++c) {
      for (std::size_t i = 0; i < b.splats.chunks[c].count; ++i) {
        drawn.insert(b.splats.chunks[c].shaded[i]);
      }
    }
    std::size_t checked = 0, missing = 0;
    for (std::size_t p = 0; p < a.color.size(); ++p) {
      if (!(a.depth[p] < std::numeric_limits<float>::infinity())) continue;
      const Rgb8 c = a.color[p];
      const std::uint32_t packed = c.r | std::uint32_t(c.g) << 8 | std::uint32_t(c.b) << 16;
      ++checked;
      missing += drawn.count(packed) == 0;
    }
    EXPECT_GT(checked, 1000u);
    EXPECT_EQ(missing, 0u) << "frame " << k;
    EXPECT_GT(b.stats.occlusion.leaves_culled, 0u) << "frame " << k;
  }
}

TEST(OcclusionRender, SptChunksAreCulledWithTheSameImage) {
  // With --lod spt the culling leaves are the Sequential Point Tree's list ranges (the top list
  // and the chunks), in the fast mode (two kernels) and the quality mode.
  const TestScene scene(false);
  constexpr int kFrames = 4;
  for (int variant = 0; variant < 3; ++variant) {
    RenderSettings settings;
    settings.shape = variant == 0 ? SplatShape::Square : SplatShape::Ellipse;
    const SplatShape shape = settings.shape;
    FrameSettings none;
    none.lod = LodScheme::Spt;
    if (variant == 2) none.rasterizer = Rasterizer::Quality;
    const std::vector<Image> want = render_path(scene, settings, none, 2, kFrames);
    for (OcclusionMethod m : {OcclusionMethod::StopAndWait, OcclusionMethod::ChcPlusPlus}) {
      for (unsigned threads : {1u, 2u}) {
        FrameSettings fs = none;
        fs.occlusion.method = m;
        const std::vector<Image> got = render_path(scene, settings, fs, threads, kFrames);
        for (int k = 0; k < kFrames; ++k) {
          EXPECT_TRUE(same_bits(got[k], want[k])) << name(m) << " variant " << variant
                                                  << " shape " << int(shape) << " threads "
                                                  << threads << " frame " << k;
          EXPECT_LT(got[k].splats, want[k].splats) << name(m) << " frame " << k;
          EXPECT_GT(got[k].occlusion.leaves_culled, 0u);
        }
      }
    }
  }
}

TEST(OcclusionRender, QualityModeGivesTheImageOfNoCullingForBothReconstructionRules) {
  // The occluder pass bounds each pixel's reconstruction bound from above and the quality pass
  // sums the visible leaves in the order of no culling, so the image is the same bits.
  const TestScene scene(false);
  constexpr int kFrames = 4;
  std::size_t compared = 0;
  for (Reconstruction rule : {Reconstruction::ZRange, Reconstruction::ZThreshold}) {
    RenderSettings settings;
    FrameSettings none;
    none.rasterizer = Rasterizer::Quality;
    none.quality.reconstruction = rule;
    const std::vector<Image> want = render_path(scene, settings, none, 2, kFrames);
    for (OcclusionMethod m : {OcclusionMethod::StopAndWait, OcclusionMethod::ChcPlusPlus}) {
      for (unsigned latency : {0u, 2u}) {
        for (unsigned threads : {1u, 2u}) {
          FrameSettings fs = none;
          fs.occlusion.method = m;
          fs.occlusion.query_latency = latency;
          fs.occlusion.leaf_points = 256;
          const std::vector<Image> got = render_path(scene, settings, fs, threads, kFrames);
          for (int k = 0; k < kFrames; ++k) {
            EXPECT_TRUE(same_bits(got[k], want[k]))
                << name(m) << " rule " << int(rule) << " threads " << threads << " latency "
                << latency << " frame " << k;
            // Culling skips the balls behind the wall; with latency, answers of the first
            // frames arrive after the balls are drawn (no history yet), so from frame 2 on.
            if (latency == 0 || k >= 2) {
              EXPECT_LT(got[k].splats, want[k].splats)
                  << name(m) << " latency " << latency << " frame " << k;
            }
            ++compared;
          }
        }
      }
    }
  }
  EXPECT_EQ(compared, 2u * 2u * 2u * 2u * kFrames);
}

TEST(OcclusionRender, QualityModeCullsSingleSplatLeavesWithTheSameImage) {
  // The finest culling: leaves of one point, each queried (no minimum), so every splat's
  // fragments are tested against the occluders of the splats drawn before it.
  const TestScene scene(false);
  ThreadPool pool(2);
  RenderSettings settings;
  for (Reconstruction rule : {Reconstruction::ZRange, Reconstruction::ZThreshold}) {
    FrameSettings fs;
    fs.rasterizer = Rasterizer::Quality;
    fs.quality.reconstruction = rule;
    Renderer plain;
    Frame frame;
    plain.render(scene.instances, path_camera(1, 4), settings, fs, pool, frame);
    FrameSettings culled = fs;
    culled.occlusion.method = OcclusionMethod::StopAndWait;
    culled.occlusion.leaf_points = 1;
    culled.occlusion.min_query_splats = 0;
    Renderer r;
    Frame f;
    r.render(scene.instances, path_camera(1, 4), settings, culled, pool, f);
    std::size_t covered = 0;
    for (std::size_t p = 0; p < frame.depth.size(); ++p) {
      covered += frame.depth[p] < std::numeric_limits<float>::infinity();
      ASSERT_EQ(std::memcmp(&frame.color[p], &f.color[p], sizeof(Rgb8)), 0) << "pixel " << p;
      ASSERT_EQ(std::memcmp(&frame.depth[p], &f.depth[p], sizeof(float)), 0) << "pixel " << p;
    }
    EXPECT_GT(covered, 5000u);
    EXPECT_GT(f.stats.occlusion.leaves_culled, 100u);
  }
}

TEST(OcclusionRender, HiddenPagedModelsLoadNoPages) {
  // Every model drawn page by page: each instance of a paged model is one culling leaf (and
  // inside a visible one, its pages are tested: the next test). Balls of a model seen nowhere
  // else stand well behind the wall: found hidden, they select nothing, so their model loads no
  // page beyond its root page, and the settled image (every page the view needs resident) is
  // the one of no culling.
  const TestScene scene(false);
  ThreadPool pool(2);
  SphereTree hidden_tree = build_sphere_tree(ball_points(3000, false), pool);
  RenderModel hidden;
  hidden.tree = hidden_tree.view();
  hidden.name = "hidden";
  std::vector<SceneInstance> instances{scene.instances[0], scene.instances.back()};
  const std::vector<SceneInstance> without_hidden = instances;
  for (int i = 0; i < 4; ++i) {
    instances.push_back({&hidden, make_transform({-2.0f + 1.3f * float(i), 1.5f, -5.0f},
                                                 {0, 20.0f * float(i), 0}, 0.4f)});
  }
  const Camera camera = path_camera(0, 4);
  struct Settled {
    Image image;
    std::uint64_t pages_loaded = 0;
  };
  // Frames until every page the view needs is resident, then `more` frames (CHC++ keeps
  // drawing what was visible until its next query).
  const auto settle = [&](std::span<const SceneInstance> scene_instances, const FrameSettings& fs,
                          int more) {
    Settled out;
    out.image = settle_paged(scene_instances, camera, fs, more, pool, out.pages_loaded);
    return out;
  };
  for (Rasterizer mode : {Rasterizer::Fast, Rasterizer::Quality}) {
    FrameSettings none;
    none.rasterizer = mode;
    const Settled plain = settle(instances, none, 0);
    const Settled visible_only = settle(without_hidden, none, 0);
    for (OcclusionMethod m : {OcclusionMethod::StopAndWait, OcclusionMethod::ChcPlusPlus}) {
      FrameSettings fs = none;
      fs.occlusion.method = m;
      const Settled culled = settle(instances, fs, 12);
      EXPECT_TRUE(same_bits(culled.image, plain.image)) << name(m) << " mode " << int(mode);
      // The visible models' hidden pages are culled too (inside each model), so at most the
      // splats of the scene without the hidden balls.
      EXPECT_LE(culled.image.splats, visible_only.image.splats) << name(m) << " " << int(mode);
      EXPECT_GE(culled.image.occlusion.leaves_culled, 4u) << name(m) << " " << int(mode);
      if (m == OcclusionMethod::StopAndWait) {
        // Hidden from the first frame: the hidden model's root page (loaded when the model is
        // first met) and nothing more than the same culling of the scene without it.
        const Settled culled_visible = settle(without_hidden, fs, 12);
        EXPECT_EQ(culled.image.splats, culled_visible.image.splats) << int(mode);
        EXPECT_EQ(culled.pages_loaded, culled_visible.pages_loaded + 1) << int(mode);
        EXPECT_GT(plain.pages_loaded, culled.pages_loaded + 4) << int(mode);
      }
    }
  }
}

TEST(OcclusionRender, HiddenPagesOfAVisibleModelAreNeitherDrawnNorLoaded) {
  // A second wall behind the first, mostly hidden by it but for a strip past its end: the
  // instance is visible, so it is drawn, and inside it each subtree in another page is tested
  // against what is drawn so far. The hidden pages are neither drawn nor requested, and the
  // settled image is the one of no culling.
  const TestScene scene(false);
  ThreadPool pool(2);
  const SphereTree back_tree = build_sphere_tree(wall_points(), pool);  // its own pages
  RenderModel back;
  back.tree = back_tree.view();
  back.name = "back wall";
  const std::vector<SceneInstance> instances{
      scene.instances[0], {&back, make_transform({3.0f, 0.0f, -3.0f}, {}, 1.0f)}};
  const Camera camera = path_camera(0, 4);
  const auto settle = [&](const FrameSettings& fs, int more, std::uint64_t& pages_loaded) {
    return settle_paged(instances, camera, fs, more, pool, pages_loaded);
  };
  for (Rasterizer mode : {Rasterizer::Fast, Rasterizer::Quality}) {
    FrameSettings none;
    none.rasterizer = mode;
    std::uint64_t plain_pages = 0;
    const Image plain = settle(none, 0, plain_pages);
    for (OcclusionMethod m : {OcclusionMethod::StopAndWait, OcclusionMethod::ChcPlusPlus}) {
      FrameSettings fs = none;
      fs.occlusion.method = m;
      std::uint64_t pages = 0;
      const Image culled = settle(fs, 12, pages);
      EXPECT_TRUE(same_bits(culled, plain)) << name(m) << " mode " << int(mode);
      EXPECT_GT(culled.occlusion.paged_subtrees_culled, 0u) << name(m) << " " << int(mode);
      EXPECT_LT(culled.splats, plain.splats) << name(m) << " " << int(mode);
      EXPECT_LT(pages, plain_pages) << name(m) << " " << int(mode);
      std::cout << name(m) << (mode == Rasterizer::Fast ? " fast" : " quality") << ": splats "
                << culled.splats << " of " << plain.splats << ", pages loaded " << pages
                << " of " << plain_pages << ", subtrees culled "
                << culled.occlusion.paged_subtrees_culled << "\n";
    }
  }
}

TEST(OcclusionRender, AFarEyeOverSmallInstancesRendersAsInTheWorld) {
  // The path fuzzer's camera (fuzz/findings): an eye 1.3e19 away is a valid world camera, but
  // scaled into a 0.4-sized ball's space the view vector's length overflowed a float and the
  // model-space frame was refused as "up parallel to the view". Every method renders it, the
  // same image, and the balls a far eye sees as less than a pixel leave no trace.
  const TestScene scene(false);
  ThreadPool pool(2);
  Camera far = path_camera(0, 2);
  far.eye = {3.0f, 1.0f, 1.3333333e19f};
  far.target = {-1.0f, 0.5f, -2.0f};
  std::vector<Image> shots;
  for (OcclusionMethod m : {OcclusionMethod::None, OcclusionMethod::StopAndWait,
                            OcclusionMethod::ChcPlusPlus}) {
    FrameSettings fs;
    fs.occlusion.method = m;
    Renderer renderer;
    Frame frame;
    ASSERT_NO_THROW(renderer.render(scene.instances, far, {}, fs, pool, frame)) << name(m);
    shots.push_back(capture(frame));
  }
  EXPECT_TRUE(same_bits(shots[1], shots[0]));
  EXPECT_TRUE(same_bits(shots[2], shots[0]));
  EXPECT_LE(shots[0].splats, scene.instances.size());
}

TEST(OcclusionRender, AnEmptySceneIsTheBackground) {
  ThreadPool pool(2);
  Renderer renderer;
  Frame frame;
  FrameSettings fs;
  fs.occlusion.method = OcclusionMethod::ChcPlusPlus;
  RenderSettings settings;
  settings.background = {10, 20, 30};
  renderer.render({}, path_camera(0, 2), settings, fs, pool, frame);
  ASSERT_EQ(frame.color.size(), 160u * 120u);
  for (std::size_t p = 0; p < frame.color.size(); ++p) {
    ASSERT_EQ(frame.color[p], (Rgb8{10, 20, 30}));
    ASSERT_EQ(frame.depth[p], std::numeric_limits<float>::infinity());
  }
  EXPECT_EQ(frame.stats.splats, 0u);
}

TEST(OcclusionRender, CombinationsNotYetSupportedAreRefusedWithAMessage) {
  const TestScene scene(false);
  ThreadPool pool(1);
  Renderer renderer;
  Frame frame;
  FrameSettings fs;
  fs.occlusion.method = OcclusionMethod::ChcPlusPlus;
  fs.rasterizer = Rasterizer::Quality;
  fs.quality.opacity = 0.5f;  // culling would hide what shows through
  try {
    renderer.render(scene.instances, path_camera(0, 2), {}, fs, pool, frame);
    FAIL() << "semi-transparent quality mode with occlusion culling was accepted";
  } catch (const OptionError& e) {
    EXPECT_NE(std::string(e.what()).find("--opacity"), std::string::npos) << e.what();
  }
  fs.quality.opacity = 1.0f;
  // A hierarchy too large for the scene (culling leaves of one point: 4,000 instances of a 4,500-node tree).
  {
    FrameSettings tiny;
    tiny.occlusion.method = OcclusionMethod::Chc;
    tiny.occlusion.leaf_points = 1;
    std::vector<SceneInstance> many(4000, scene.instances[1]);
    try {
      renderer.render(many, path_camera(0, 2), {}, tiny, pool, frame);
      FAIL() << "a hierarchy of millions of nodes was built";
    } catch (const OptionError& e) {
      EXPECT_NE(std::string(e.what()).find("--cull-leaf"), std::string::npos) << e.what();
    }
  }
}
