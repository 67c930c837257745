// Rendering with sharp features against the exact ray-cast reference of the CSG test scenes
// (spec §4.5–4.6): with unlit colours (ambient 1, no diffuse or specular), a pixel shows exactly
// its surface's colour unless it blends two surfaces, so label errors and mixed pixels can be
// counted exactly.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <map>
#include <tuple>

#include "render/features_render_support.hpp"
#include "pointillist/eval/label_metrics.hpp"
#include "pointillist/format/ptl_v2.hpp"
#include "pointillist/format/ptl_v2_pages.hpp"
#include "pointillist/lod/tree_features.hpp"
#include "pointillist/prep/radii.hpp"
#include "pointillist/render/renderer.hpp"
#include "pointillist/render/sequence.hpp"
#include "pointillist/scene/csg.hpp"
#include "testing/testing.hpp"

using namespace pointillist;

namespace {

using namespace features_test;

TEST(FeaturesRender, PlanarCreasesMeetTheA2Bars) {
  // Spec §4.6 A2 on the cube (T1) and the step (T8), overview (V1) and close-up (V2), in both
  // sampling modes, quality mode: no holes, no blended pixels off the silhouette, label errors
  // <= 0.2 % of the crease band B_4, the label switch across a crease within 0.25 px of the
  // reference's on average (at most 1 px) and no transition wider than 1 px.
  ThreadPool pool(2);
  for (const SamplingMode mode : {SamplingMode::Jittered, SamplingMode::Random}) {
    for (const char* id : {"T1", "T8"}) {
      const auto m = make_model(id, pool, false, mode);
      const bool cube = std::string(id) == "T1";
      const Camera close = cube ? look({2.0f, 2.1f, 1.9f}, {1, 1, 1}, 320)
                                : look({1.0f, 0.9f, 2.1f}, {0, 0, 1}, 320);
      const Camera overview = look({3.2f, 2.4f, 4.1f}, {0, 0, 0}, 320);
      for (int v = 0; v < 2; ++v) {
        const Camera& cam = v == 0 ? close : overview;
        const LabelComparison c = label_metrics(*m, cam, render(*m, cam, pool, true));
        const LabelComparison off = label_metrics(*m, cam, render(*m, cam, pool, false));
        const char* which = v == 0 ? "V2" : "V1";
        std::cout << id << " " << (mode == SamplingMode::Jittered ? "J " : "R ") << which
                  << ": holes " << c.hole_count << " mixed " << c.mixed_count << " LER(B4) "
                  << 100 * c.ler_band << "% (" << c.band_error_count << " of " << c.band_count
                  << " px, " << c.wrong_count << " wrong) displacement " << c.displacement_mean_px << "/"
                  << c.displacement_max_px << " transition " << c.transition_max_px
                  << " profiles " << c.profile_count << " / without: mixed " << off.mixed_count
                  << " LER(B4) " << 100 * off.ler_band << "% transition "
                  << off.transition_max_px << "\n";
        EXPECT_EQ(c.hole_count, 0u) << id << " " << which;
        EXPECT_EQ(c.mixed_count, 0u) << id << " " << which;
        EXPECT_LE(c.ler_band, 0.002) << id << " " << which;
        EXPECT_GT(c.profile_count, 8u) << id << " " << which;
        EXPECT_LE(c.displacement_mean_px, 0.25) << id << " " << which;
        EXPECT_LE(c.displacement_max_px, 1.0) << id << " " << which;
        EXPECT_LE(c.transition_max_px, 1.0) << id << " " << which;
        EXPECT_GT(off.mixed_count, 50u) << id << " " << which;  // what the bars measure
      }
    }
  }
}

TEST(FeaturesRender, CubeCornerIsSharpWithoutHolesOrBlends) {
  ThreadPool pool(2);
  const auto m = make_model("T1", pool);
  // V2: 1.5 from the corner (1, 1, 1); V1: the overview.
  for (const Camera& cam : {look({2.0f, 2.1f, 1.9f}, {1, 1, 1}), look({3.2f, 2.4f, 4.1f}, {0, 0, 0})}) {
    const LabelMetrics with = measure(*m, cam, render(*m, cam, pool, true));
    const LabelMetrics without = measure(*m, cam, render(*m, cam, pool, false));
    std::cout << "covered " << with.covered << " wrong " << with.wrong << " mixed " << with.mixed << " holes " << with.holes << " / without: wrong " << without.wrong << " mixed " << without.mixed << " holes " << without.holes << "\n";
    EXPECT_EQ(with.holes, 0u);
    EXPECT_EQ(with.mixed, 0u);                        // A2: no blended pixels
    EXPECT_LE(with.wrong, with.covered / 500);        // A2: label errors <= 0.2 %
    EXPECT_GT(without.mixed, 50u);                    // what the features remove
  }
}

TEST(FeaturesRender, StepCornersAreSharp) {
  ThreadPool pool(2);
  const auto m = make_model("T8", pool);
  // Close-ups of the mixed corner (0, 0, 1) and of the reflex vertex of the front face.
  for (const Camera& cam : {look({1.0f, 0.9f, 2.1f}, {0, 0, 1}), look({0.4f, 0.5f, 2.4f}, {0, 0, 1})}) {
    const LabelMetrics with = measure(*m, cam, render(*m, cam, pool, true));
    const LabelMetrics without = measure(*m, cam, render(*m, cam, pool, false));
    std::cout << "T8: covered " << with.covered << " wrong " << with.wrong << " mixed "
              << with.mixed << " holes " << with.holes << " / without: wrong " << without.wrong
              << " mixed " << without.mixed << "\n";
    EXPECT_GT(without.mixed, 50u);
    EXPECT_EQ(with.holes, 0u);
    EXPECT_EQ(with.mixed, 0u);
    EXPECT_LE(with.wrong, with.covered / 500);
  }
}

TEST(FeaturesRender, InterpenetratingSpheresShowNoMagenta) {
  ThreadPool pool(2);
  const auto m = make_model("T9", pool);
  // A point of the intersection curve x = 0, y² + z² = 0.64, seen from 1.5 away, and the
  // overview.
  for (const Camera& cam : {look({0.3f, 0.6f, 2.05f}, {0, 0, 0.8f}), look({1.2f, 1.5f, 3.4f}, {0, 0, 0})}) {
    const LabelMetrics with = measure(*m, cam, render(*m, cam, pool, true));
    const LabelMetrics without = measure(*m, cam, render(*m, cam, pool, false));
    std::cout << "covered " << with.covered << " wrong " << with.wrong << " mixed " << with.mixed << " holes " << with.holes << " / without: wrong " << without.wrong << " mixed " << without.mixed << " holes " << without.holes << "\n";
    EXPECT_EQ(with.holes, 0u);
    EXPECT_EQ(with.mixed, 0u);  // A5
    EXPECT_GT(without.mixed, 20u);
  }
}

TEST(FeaturesRender, SurfaceSwitchesAreWhereTheSpheresWouldBlend) {
  // The pixels where the per-surface rule kept the other sphere out of the blend are the
  // pixels that blend without features (a fragment of the other sphere within the front
  // surface's depth window there too: the front surface's window is at least as wide as the
  // window over all fragments); none on the smooth sphere, none without features.
  ThreadPool pool(2);
  const auto m = make_model("T9", pool);
  Renderer renderer;
  Frame frame;
  const SceneInstance instance{&m->render, {}};
  FrameSettings fs;
  fs.rasterizer = Rasterizer::Quality;
  for (const Camera& cam : {look({0.3f, 0.6f, 2.05f}, {0, 0, 0.8f}), look({1.2f, 1.5f, 3.4f}, {0, 0, 0})}) {
    const LabelMetrics without = measure(*m, cam, render(*m, cam, pool, false));
    renderer.render({&instance, 1}, cam, unlit(), fs, pool, frame);
    const std::uint64_t switches = frame.stats.surface_switch_pixels;
    std::cout << "surface switches " << switches << ", blended without features "
              << without.mixed << "\n";
    EXPECT_GE(double(switches), 0.95 * double(without.mixed));
    EXPECT_LE(double(switches), 1.1 * double(without.mixed) + 20);
    EXPECT_LE(switches, frame.stats.other_surface_fragments);
  }
  const auto sphere = make_model("T13", pool);
  const SceneInstance one{&sphere->render, {}};
  renderer.render({&one, 1}, look({0, 0, 3}, {0, 0, 0}), unlit(), fs, pool, frame);
  EXPECT_EQ(frame.stats.surface_switch_pixels, 0u);
  fs.features = false;
  renderer.render({&instance, 1}, look({0.3f, 0.6f, 2.05f}, {0, 0, 0.8f}), unlit(), fs, pool,
                  frame);
  EXPECT_EQ(frame.stats.surface_switch_pixels, 0u);
}

TEST(FeaturesRender, CurvedCreasesAndThinPartsReport) {
  // A3 (curved rims: cylinder cap, plate with a hole), A5 (crossed cylinders: rims clipped,
  // crossing not), A6 (thin slab: front and back never blend): holes and blends against the
  // exact reference, with and without features.
  ThreadPool pool(2);
  struct View {
    const char* id;
    Camera cam;
  };
  const View views[] = {
      {"T3", look({1.3f, 1.7f, 1.0f}, {0.8f * 0.7071f, 0.8f, 0.8f * 0.7071f})},  // cap rim
      {"T4", look({0.9f, 1.4f, 0.9f}, {0.5f * 0.7071f, 0.2f, 0.5f * 0.7071f})},  // hole rim
      {"T10", look({1.2f, 1.4f, 1.6f}, {0, 0.3f, 0.3f})},                         // crossing
      {"T11", look({1.6f, 1.2f, 1.9f}, {1, 1, 0})},                               // slab corner
  };
  for (const View& v : views) {
    const auto m = make_model(v.id, pool);
    const LabelMetrics with = measure(*m, v.cam, render(*m, v.cam, pool, true));
    const LabelMetrics without = measure(*m, v.cam, render(*m, v.cam, pool, false));
    std::cout << v.id << ": covered " << with.covered << " wrong " << with.wrong << " mixed "
              << with.mixed << " holes " << with.holes << " / without: wrong " << without.wrong
              << " mixed " << without.mixed << " holes " << without.holes << "\n";
    EXPECT_EQ(with.holes, 0u) << v.id;
    EXPECT_EQ(with.mixed, 0u) << v.id;
    EXPECT_LE(with.wrong, with.covered / 50) << v.id;  // A3: LER <= 2 % on curved creases
    EXPECT_GT(with.covered, 10000u) << v.id;
  }
}

TEST(FeaturesRender, CrossedCylindersWithLargeDiscsStayTwoSurfaces) {
  // T10 with random sampling's discs (2.5 times the coverage): the cylinders' nearly parallel
  // parts (0.15 apart, normals within 26°) are neighbours; taken as one surface, the quality
  // rule blended them along the whole crossing curve (45,987 mixed pixels at 512 px).
  ThreadPool pool(2);
  const auto m = make_model("T10", pool, false, SamplingMode::Random);
  const Camera cam = look({0.35f + 1.0607f, 0, 0.5f + 1.0607f}, {0.35f, 0, 0.5f}, 384);
  const LabelMetrics with = measure(*m, cam, render(*m, cam, pool, true));
  const LabelMetrics without = measure(*m, cam, render(*m, cam, pool, false));
  std::cout << "T10 R: covered " << with.covered << " wrong " << with.wrong << " mixed "
            << with.mixed << " holes " << with.holes << " / without: mixed " << without.mixed
            << "\n";
  EXPECT_GT(without.mixed, 1000u);
  EXPECT_EQ(with.mixed, 0u);
  EXPECT_EQ(with.holes, 0u);
  EXPECT_LE(with.wrong, with.covered / 20);
}

TEST(FeaturesRender, FastModeClipsAtCreasesToo) {
  ThreadPool pool(2);
  for (const char* id : {"T1", "T8"}) {
    const auto m = make_model(id, pool);
    const Camera cam = std::string(id) == "T1" ? look({2.0f, 2.1f, 1.9f}, {1, 1, 1})
                                               : look({1.0f, 0.9f, 2.1f}, {0, 0, 1});
    const LabelMetrics with = measure(*m, cam, render(*m, cam, pool, true, Rasterizer::Fast));
    const LabelMetrics without = measure(*m, cam, render(*m, cam, pool, false, Rasterizer::Fast));
    std::cout << id << " fast: wrong " << with.wrong << " holes " << with.holes
              << " / without: wrong " << without.wrong << "\n";
    EXPECT_EQ(with.holes, 0u) << id;
    EXPECT_EQ(with.mixed, 0u) << id;  // opaque splats never blend
    EXPECT_GT(without.wrong, 200u) << id;  // discs of one face over the other
    EXPECT_LE(with.wrong, with.covered / 500) << id;
  }
}

TEST(FeaturesRender, SequentialPointTreesDrawThemToo) {
  // The SPT's leaves carry their splats' planes and ids, its interior entries the common id of
  // their subtree: close up (leaves) and from afar (interior entries near the corner), both
  // rasterizers.
  ThreadPool pool(2);
  for (const char* id : {"T1", "T8"}) {
    const auto m = make_model(id, pool);
    const bool cube = std::string(id) == "T1";
    const Camera near = cube ? look({2.0f, 2.1f, 1.9f}, {1, 1, 1})
                             : look({1.0f, 0.9f, 2.1f}, {0, 0, 1});
    const Camera far = look({3.2f, 2.4f, 4.1f}, {0, 0, 0});
    for (const Camera& cam : {near, far}) {
      for (Rasterizer r : {Rasterizer::Quality, Rasterizer::Fast}) {
        const LabelMetrics with = measure(*m, cam, render(*m, cam, pool, true, r, LodScheme::Spt));
        const LabelMetrics without =
            measure(*m, cam, render(*m, cam, pool, false, r, LodScheme::Spt));
        std::cout << id << " spt " << name(r) << ": covered " << with.covered << " wrong "
                  << with.wrong << " mixed " << with.mixed << " holes " << with.holes
                  << " / without: wrong " << without.wrong << " mixed " << without.mixed << "\n";
        EXPECT_EQ(with.holes, 0u) << id << " " << name(r);
        EXPECT_EQ(with.mixed, 0u) << id << " " << name(r);
        EXPECT_LE(with.wrong, with.covered / 500) << id << " " << name(r);
        EXPECT_GT(without.mixed + without.wrong, 50u) << id << " " << name(r);
      }
    }
  }
}

// Renders until every page the view needs is loaded (a paged model), as `render` does.
Image render_paged(const RenderModel& model, const Camera& camera, ThreadPool& pool,
                   bool features, Rasterizer rasterizer, const RendererOptions& options = {}) {
  const RenderSettings settings = unlit();
  FrameSettings fs;
  fs.rasterizer = rasterizer;
  fs.features = features;
  Renderer renderer(options);
  Frame frame;
  const SceneInstance instance{&model, {}};
  render_settled(renderer, {&instance, 1}, camera, settings, fs, pool, frame);
  return {std::vector<Rgb8>(frame.color.begin(), frame.color.end()), frame.width, frame.height};
}

TEST(FeaturesRender, PagedModelsDrawThemAsModelsHeldWhole) {
  // A .ptl v2 file with its features stored page by page, drawn from its pages (small ones, so
  // the close-up needs many) and decoded whole: the same image bits; and a model held whole,
  // cut into pages in memory, draws as it does whole.
  ThreadPool pool(2);
  for (const char* id : {"T1", "T8"}) {
    const auto m = make_model(id, pool, true);
    pointillist::testing::TempDir dir;
    const std::string path = dir.file("m.ptl");
    write_ptl_v2(path, m->tree, "", {.page_bytes = 2048, .features = &m->features});
    const auto file = PtlV2File::open(path);
    ASSERT_GT(file->page_count(), 10u);
    TreeFeatures stored;
    const SphereTree whole_tree = file->decode_all(&stored);
    RenderModel whole{.tree = whole_tree.view()};
    whole.tree.features = &stored;
    const auto source = ptl_v2_page_source(*file);
    const RenderModel paged{.tree = source->summary(), .pages = source.get()};
    const Camera cam = std::string(id) == "T1" ? look({2.0f, 2.1f, 1.9f}, {1, 1, 1})
                                               : look({1.0f, 0.9f, 2.1f}, {0, 0, 1});
    for (Rasterizer r : {Rasterizer::Quality, Rasterizer::Fast}) {
      const Image a = render_paged(paged, cam, pool, true, r);
      const Image b = render_paged(whole, cam, pool, true, r);
      EXPECT_TRUE(a.color == b.color) << id << " " << name(r);
      const Image off = render_paged(paged, cam, pool, false, r);
      EXPECT_FALSE(a.color == off.color) << id << " " << name(r) << ": features not drawn";
      const LabelMetrics with = measure(*m, cam, a);
      EXPECT_EQ(with.holes, 0u) << id << " " << name(r);
      // In memory, cut into pages.
      const Image cut = render_paged(m->render, cam, pool, true, r, {.page_all = true});
      const Image flat = render_paged(m->render, cam, pool, true, r);
      EXPECT_TRUE(cut.color == flat.color) << id << " " << name(r);
    }
  }
}

// The frame's statistics of what the features did, for the fast rasterizer against a brute-force
// count: every pixel centre inside a clipped splat's circle (or, covering none, the pixel holding
// its centre) whose ray meets the splat's plane where its planes discard (clip_discards).
TEST(FeaturesRender, StatisticsCountClippedFragmentsAndOtherSurfaces) {
  ThreadPool pool(2);
  const auto m = make_model("T1", pool);
  const Camera cam = look({2.0f, 2.1f, 1.9f}, {1, 1, 1}, 128);
  RenderSettings settings;
  settings.shape = SplatShape::Circle;
  FrameSettings fs;
  Renderer renderer;
  Frame frame;
  const SceneInstance instance{&m->render, {}};
  renderer.render({&instance, 1}, cam, settings, fs, pool, frame);
  const CameraFrame cf = make_camera_frame(cam);
  std::uint64_t clipped_splats = 0, oracle = 0;
  for (std::size_t c = 0; c < frame.splats.chunk_count; ++c) {
    const SplatChunk& ch = frame.splats.chunks[c];
    for (std::size_t i = 0; i < ch.count; ++i) {
      const std::uint32_t count = clip_count(ch.clip_code[i]);
      if (count == 0) continue;
      ++clipped_splats;
      const std::span<const ClipPlane> planes(ch.clip_planes.data() + ch.clip_first[i], count);
      const float r = 0.5f * ch.size_px[i], x = ch.x_px[i], y = ch.y_px[i];
      const auto discards = [&](int px, int py) {
        const Vec3f ray = pixel_ray(cf, px, py);
        const float t = dot(ch.normal[i], ch.center[i] - cf.eye) / dot(ch.normal[i], ray);
        const Vec3f p = t > 0 && std::isfinite(t) ? cf.eye + ray * t : ch.center[i];
        return clip_discards(planes, clip_mode(ch.clip_code[i]), p);
      };
      bool any = false;
      for (int py = std::max(0, int(y - r) - 1); py <= std::min(127, int(y + r) + 1); ++py) {
        for (int px = std::max(0, int(x - r) - 1); px <= std::min(127, int(x + r) + 1); ++px) {
          const float dx = px + 0.5f - x, dy = py + 0.5f - y;
          if (dx * dx + dy * dy > r * r) continue;
          any = true;
          oracle += discards(px, py);
        }
      }
      if (!any && x >= 0 && y >= 0 && x < 128 && y < 128) oracle += discards(int(x), int(y));
    }
  }
  const RenderStats& st = frame.stats;
  std::cout << "fast: clipped splats " << st.clipped_splats << " fragments "
            << st.clipped_fragments << " (brute force " << oracle << ")\n";
  EXPECT_EQ(st.clipped_splats, clipped_splats);
  EXPECT_GT(oracle, 500u);
  EXPECT_NEAR(double(st.clipped_fragments), double(oracle), 0.01 * double(oracle));
  EXPECT_EQ(st.other_surface_fragments, 0u);  // the fast mode draws opaque discs

  // Quality: fragments clipped at the cube's creases (its discs reach further: the low-pass
  // and the drawn radius); fragments of the other sphere left out where T9's spheres cross (no
  // clip there: the ids separate them), the same for any thread count; none of either on the
  // smooth sphere, and none counted without features.
  fs.rasterizer = Rasterizer::Quality;
  renderer.render({&instance, 1}, cam, settings, fs, pool, frame);
  EXPECT_GT(frame.stats.clipped_fragments, oracle / 4);
  const auto spheres = make_model("T9", pool);
  const SceneInstance crossing{&spheres->render, {}};
  const Camera curve = look({0.3f, 0.6f, 2.05f}, {0, 0, 0.8f}, 128);
  renderer.render({&crossing, 1}, curve, settings, fs, pool, frame);
  std::cout << "T9 quality: other-surface fragments " << frame.stats.other_surface_fragments
            << ", clipped " << frame.stats.clipped_fragments << "\n";
  EXPECT_GT(frame.stats.other_surface_fragments, 100u);
  const std::uint64_t two_threads = frame.stats.other_surface_fragments;
  ThreadPool one(1);
  renderer.render({&crossing, 1}, curve, settings, fs, one, frame);
  EXPECT_EQ(frame.stats.other_surface_fragments, two_threads);
  fs.features = false;
  renderer.render({&crossing, 1}, curve, settings, fs, pool, frame);
  EXPECT_EQ(frame.stats.clipped_fragments + frame.stats.other_surface_fragments, 0u);
  const auto sphere = make_model("T13", pool);
  const SceneInstance smooth{&sphere->render, {}};
  fs.features = true;
  renderer.render({&smooth, 1}, look({1.5f, 1.2f, 2.5f}, {0, 0, 0}, 128), settings, fs, pool,
                  frame);
  EXPECT_EQ(frame.stats.clipped_fragments + frame.stats.other_surface_fragments, 0u);
}

TEST(FeaturesRender, QuantizedModelsKeepMostOfIt) {
  // The same scenes as a .ptl v2 file decodes them: centres, normals and radii quantized, colours
  // in RGB 565 (so the pure-colour test compares with the quantized palette).
  ThreadPool pool(2);
  for (const char* id : {"T1", "T8"}) {
    const auto m = make_model(id, pool, true);
    const Camera cam = std::string(id) == "T1" ? look({2.0f, 2.1f, 1.9f}, {1, 1, 1})
                                               : look({1.0f, 0.9f, 2.1f}, {0, 0, 1});
    const LabelMetrics with = measure(*m, cam, render(*m, cam, pool, true));
    const LabelMetrics without = measure(*m, cam, render(*m, cam, pool, false));
    std::cout << id << " quantized: covered " << with.covered << " wrong " << with.wrong
              << " mixed " << with.mixed << " holes " << with.holes << " / without: mixed "
              << without.mixed << "\n";
    EXPECT_EQ(with.holes, 0u) << id;
    EXPECT_LT(with.mixed + with.wrong, (without.mixed + without.wrong) / 4) << id;
  }
}

TEST(FeaturesRender, SmoothSphereIsBitIdenticalWithFeatures) {
  ThreadPool pool(2);
  const auto m = make_model("T13", pool);
  ASSERT_EQ(m->features.stats.sharp_edges, 0u);
  const Camera cam = look({1.5f, 1.2f, 2.5f}, {0, 0, 0});
  const Image with = render(*m, cam, pool, true), without = render(*m, cam, pool, false);
  EXPECT_TRUE(with.color == without.color);  // A7
}

TEST(FeaturesRender, ImagesDoNotDependOnTheThreadCount) {
  ThreadPool one(1), two(2);
  const auto m = make_model("T8", two);
  const Camera cam = look({1.0f, 0.9f, 2.1f}, {0, 0, 1});
  EXPECT_TRUE(render(*m, cam, one, true).color == render(*m, cam, two, true).color);  // A9
}

}  // namespace
