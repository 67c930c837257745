// The library pipeline: merging scans, open_model for every kind of model and its paging
// decision, and convert.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include "pointillist/core/error.hpp"
#include "pointillist/io/merge.hpp"
#include "pointillist/io/ply.hpp"
#include "pointillist/pipeline/convert.hpp"
#include "pointillist/pipeline/model.hpp"
#include "pointillist/render/sequence.hpp"
#include "pointillist/scene/analytic.hpp"
#include "pointillist/scene/csg.hpp"
#include "testing/testing.hpp"

using namespace pointillist;
using ::testing::HasSubstr;

namespace {

OpenModelOptions paging(Paging mode, std::uint64_t memory_bytes = 0) {
  OpenModelOptions o;
  o.paging = mode;
  o.memory_bytes = memory_bytes;
  return o;
}

// A text scan of n points on a line, at coordinates large enough that the reader moves them to
// a local origin: x = base + i (metres), y = z = 0.5 + i / 10.
void write_xyz(const std::string& path, double base, int n) {
  std::ofstream out(path);
  out.precision(12);
  for (int i = 0; i < n; ++i) {
    out << base + i << " " << 0.5 + i / 10.0 << " " << 0.5 + i / 10.0 << "\n";
  }
}

// A sampled sphere (no normals) written as PLY.
std::string write_sphere(const pointillist::testing::TempDir& dir, std::size_t n) {
  const SurfaceSamples s = sample_scene(sphere_scene(), n, 3);
  const std::string path = dir.file("sphere.ply");
  write_ply(path, s.points, {});
  return path;
}

}  // namespace

TEST(MergeInputs, TilesWithTheirOwnOriginsLineUpInTheFirstOnesFrame) {
  pointillist::testing::TempDir dir;
  // Two tiles 1000 km apart in x: each reader picks its own origin, the merge must undo that.
  write_xyz(dir.file("a.xyz"), 6.0e6, 10);
  write_xyz(dir.file("b.xyz"), 7.0e6, 10);
  ThreadPool pool(2);
  const std::vector<std::string> paths = {dir.file("a.xyz"), dir.file("b.xyz")};
  const PointSet merged = merge_inputs(paths, pool, Progress::none());
  ASSERT_EQ(merged.size(), 20u);
  // Same position within each tile's step, and 1e6 apart between the tiles (float precision of
  // a 1e6 offset: 0.0625).
  EXPECT_NEAR(merged.positions[10].x - merged.positions[0].x, 1.0e6, 0.125);
  EXPECT_NEAR(merged.positions[11].x - merged.positions[10].x, 1.0, 0.125);
  EXPECT_FLOAT_EQ(merged.positions[13].y, merged.positions[3].y);
  EXPECT_EQ(merged.origin, (std::array<double, 3>{6.0e6, 0, 0}));  // the first tile's
}

// The frame travels: a LAS-like scan's origin and up axis survive .ply export, the .ptl v2
// header and opening the model; a model without them keeps the old header bytes.
TEST(ModelFrame, OriginAndUpAxisSurviveExportConvertAndOpen) {
  pointillist::testing::TempDir dir;
  const SurfaceSamples s = sample_scene(sphere_scene(), 2000, 3);
  PointSet p = s.points;
  p.origin = {512000.5, 5403000.25, 120};
  p.up = {0, 0, 1};
  write_ply(dir.file("geo.ply"), p, {});
  ThreadPool pool(2);
  const std::vector<std::string> in = {dir.file("geo.ply")};
  const PointSet back = merge_inputs(in, pool, Progress::none());
  EXPECT_EQ(back.origin, p.origin);
  EXPECT_EQ(back.up, p.up);
  for (const auto& c : back.comments) EXPECT_EQ(c.rfind("origin", 0), std::string::npos) << c;
  convert(in, dir.file("geo.ptl"), {}, pool, Progress::none());
  for (Paging mode : {Paging::Never, Paging::Always}) {
    const Model m = open_model(dir.file("geo.ptl"), paging(mode), pool, Progress::none());
    EXPECT_EQ(m.tree().origin, p.origin);
    EXPECT_EQ(m.tree().up, p.up);
  }
}

TEST(MergeInputs, CommentsRepeatedByTheTilesAreKeptOnce) {
  pointillist::testing::TempDir dir;
  PointSet p;
  p.positions = {{0, 0, 0}, {1, 0, 0}};
  p.comments = {"survey 7", "tile a"};
  write_ply(dir.file("a.ply"), p, {});
  p.comments = {"survey 7", "tile b"};
  write_ply(dir.file("b.ply"), p, {});
  ThreadPool pool(1);
  const std::vector<std::string> paths = {dir.file("a.ply"), dir.file("b.ply")};
  const PointSet merged = merge_inputs(paths, pool, Progress::none());
  EXPECT_EQ(merged.comments, (std::vector<std::string>{"survey 7", "tile a", "tile b"}));
}

TEST(MergeInputs, MissingFileIsNamed) {
  ThreadPool pool(1);
  const std::vector<std::string> paths = {"/nonexistent/scan.ply"};
  try {
    merge_inputs(paths, pool, Progress::none());
    FAIL() << "expected IoError";
  } catch (const IoError& e) {
    EXPECT_THAT(e.what(), HasSubstr("/nonexistent/scan.ply: no such file"));
  }
}

TEST(OpenModel, EveryKindOfModelOpensWithTheSameLeaves) {
  pointillist::testing::TempDir dir;
  const std::string scan = write_sphere(dir, 3000);
  ThreadPool pool(2);
  const std::vector<std::string> in = {scan};
  convert(in, dir.file("s.ptl"), {}, pool, Progress::none());
  ConvertOptions v1;
  v1.ptl_version = 1;
  convert(in, dir.file("s1.ptl"), v1, pool, Progress::none());
  convert(in, dir.file("s.qs"), {}, pool, Progress::none());
  struct Case {
    std::string path;
    ModelKind kind;
  };
  for (const Case& c : {Case{scan, ModelKind::Scan}, Case{dir.file("s.ptl"), ModelKind::PtlV2},
                        Case{dir.file("s1.ptl"), ModelKind::PtlV1},
                        Case{dir.file("s.qs"), ModelKind::Qsplat}}) {
    const Model m = open_model(c.path, paging(Paging::Never), pool, Progress::none());
    EXPECT_EQ(m.kind(), c.kind) << c.path;
    EXPECT_EQ(m.tree().leaf_count, 3000u) << c.path;
    EXPECT_FALSE(m.paged()) << c.path;
    EXPECT_FALSE(m.paging_reason().empty()) << c.path;
  }
}

TEST(OpenModel, AutoPagingPagesWhatWouldTakeMoreThanAQuarterOfTheMemory) {
  pointillist::testing::TempDir dir;
  const std::vector<std::string> in = {write_sphere(dir, 3000)};
  ThreadPool pool(2);
  convert(in, dir.file("s.ptl"), {}, pool, Progress::none());
  // 3000 leaves give some 4000 nodes of 40 bytes: about 160 KB decoded.
  const Model small_machine =
      open_model(dir.file("s.ptl"), paging(Paging::Auto, 400'000), pool, Progress::none());
  EXPECT_TRUE(small_machine.paged());
  EXPECT_TRUE(small_machine.tree().nodes.empty());
  EXPECT_EQ(small_machine.tree().leaf_count, 3000u);
  EXPECT_THAT(small_machine.paging_reason(), HasSubstr("more than a quarter"));
  const Model big_machine =
      open_model(dir.file("s.ptl"), paging(Paging::Auto, 1'000'000'000), pool,
                 Progress::none());
  EXPECT_FALSE(big_machine.paged());
  EXPECT_EQ(big_machine.tree().leaf_count, 3000u);
  EXPECT_GT(big_machine.tree().nodes.size(), 3000u);
  EXPECT_TRUE(open_model(dir.file("s.ptl"), paging(Paging::Always), pool, Progress::none()).paged());
}

TEST(OpenModel, AutoPagingPagesASingleImageWhenDecodingCostsMoreAndDecodesASequence) {
  pointillist::testing::TempDir dir;
  const std::vector<std::string> in = {write_sphere(dir, 3000)};
  ThreadPool pool(2);
  convert(in, dir.file("s.ptl"), {}, pool, Progress::none());
  // About 4000 nodes: decoding them (~0.4 ms) costs more than paging adds to one 64x48 image
  // (~8 us), less than paging adds to one 1280x720 image (~2.5 ms).
  OpenModelOptions small = paging(Paging::Auto, 1'000'000'000);
  small.frame_pixels = 64 * 48;
  const Model paged = open_model(dir.file("s.ptl"), small, pool, Progress::none());
  EXPECT_TRUE(paged.paged());
  EXPECT_THAT(paged.paging_reason(), HasSubstr("less than decoding"));
  OpenModelOptions large = small;
  large.frame_pixels = 1280 * 720;
  EXPECT_FALSE(open_model(dir.file("s.ptl"), large, pool, Progress::none()).paged());
  // A sequence is decoded whole, whatever the sizes.
  OpenModelOptions sequence = small;
  sequence.frames = 2;
  const Model whole = open_model(dir.file("s.ptl"), sequence, pool, Progress::none());
  EXPECT_FALSE(whole.paged());
  EXPECT_THAT(whole.paging_reason(), HasSubstr("sequence"));

  // The single image is the same either way: the paged model, settled, against the decoded one.
  Frame a, b;
  const Camera cam = orbit_camera(whole.tree().view_sphere, {.width = 64, .height = 48});
  Renderer ra, rb;
  const SceneInstance ia{&paged.renderable(), {}}, ib{&whole.renderable(), {}};
  render_settled(ra, {&ia, 1}, cam, RenderSettings{}, FrameSettings{}, pool, a);
  render_settled(rb, {&ib, 1}, cam, RenderSettings{}, FrameSettings{}, pool, b);
  EXPECT_TRUE(ra.paging());
  EXPECT_FALSE(rb.paging());
  ASSERT_GT(b.stats.splats, 100u);
  EXPECT_TRUE(std::equal(a.color.begin(), a.color.end(), b.color.begin(), b.color.end()));
}

TEST(OpenModel, KeepsTheScanOnlyWhenAsked) {
  pointillist::testing::TempDir dir;
  const std::string scan = write_sphere(dir, 500);
  ThreadPool pool(1);
  EXPECT_EQ(open_model(scan, {}, pool, Progress::none()).source().size(), 0u);
  OpenModelOptions keep;
  keep.keep_source = true;
  const Model kept = open_model(scan, keep, pool, Progress::none());
  ASSERT_EQ(kept.source().size(), 500u);
  EXPECT_TRUE(kept.source().has_normals());
  EXPECT_EQ(kept.scan_input().points, 500u);
  EXPECT_FALSE(kept.scan_input().has_normals);
}

TEST(Convert, RefusesAModelAsInputAndAnUnknownOutput) {
  pointillist::testing::TempDir dir;
  const std::vector<std::string> in = {write_sphere(dir, 500)};
  ThreadPool pool(1);
  convert(in, dir.file("s.ptl"), {}, pool, Progress::none());
  const std::vector<std::string> model_in = {dir.file("s.ptl")};
  try {
    convert(model_in, dir.file("t.ptl"), {}, pool, Progress::none());
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_THAT(e.what(), HasSubstr("is already a splat model"));
  }
  EXPECT_THROW(convert(in, dir.file("t.obj"), {}, pool, Progress::none()), OptionError);
  EXPECT_FALSE(std::filesystem::exists(dir.file("t.ptl")));
  EXPECT_FALSE(std::filesystem::exists(dir.file("t.obj")));
}

TEST(Convert, DroppedOutliersAreCounted) {
  pointillist::testing::TempDir dir;
  const SurfaceSamples s = sample_scene(sphere_scene(), 3000, 3);
  PointSet p = s.points;
  // Five strays far from the unit sphere.
  for (int i = 0; i < 5; ++i) p.positions.push_back({3.0f + i, 3.0f, -3.0f - i});
  write_ply(dir.file("strays.ply"), p, {});
  ThreadPool pool(2);
  ConvertOptions o;
  o.prepare.drop_outliers = true;
  const std::vector<std::string> in = {dir.file("strays.ply")};
  const ConvertResult r = convert(in, dir.file("s.ptl"), o, pool, Progress::none());
  EXPECT_EQ(r.input_points, 3005u);
  EXPECT_EQ(r.output_points, 3000u);
}

namespace {

// A T1 cube scan with exact normals and a colour per face, written as PLY.
std::string write_cube_scan(const pointillist::testing::TempDir& dir) {
  CsgScene cube = csg_scene("T1");
  cube.spacing = 0.08f;
  CsgSamples s = sample_csg(cube, SamplingMode::Jittered, 5);
  for (std::uint32_t l : s.labels) {
    s.points.colors.push_back({static_cast<std::uint8_t>(40 * l), 100, 200});
  }
  const std::string path = dir.file("cube.ply");
  write_ply(path, s.points);
  return path;
}

Frame render_model(const Model& m, ThreadPool& pool, bool features) {
  Renderer renderer;
  Frame frame;
  FrameSettings fs;
  fs.rasterizer = Rasterizer::Quality;
  fs.features = features;
  Camera cam;
  cam.eye = {2.0f, 2.1f, 1.9f};
  cam.target = {1, 1, 1};
  cam.width = cam.height = 96;
  const SceneInstance inst{&m.renderable(), {}};
  renderer.render({&inst, 1}, cam, RenderSettings{}, fs, pool, frame);
  return frame;
}

}  // namespace

TEST(ConvertFeatures, StoredFeaturesDrawAsFeaturesComputedOnTheDecodedModel) {
  pointillist::testing::TempDir dir;
  ThreadPool pool(2);
  const std::string in[] = {write_cube_scan(dir)};
  ConvertOptions with;
  with.features = FeatureOptions{};
  convert(in, dir.file("f.ptl"), with, pool, Progress::none());
  convert(in, dir.file("plain.ptl"), {}, pool, Progress::none());
  const Model stored = open_model(dir.file("f.ptl"), {}, pool, Progress::none());
  ASSERT_NE(stored.features(), nullptr);  // decoded whole to draw them, by default
  EXPECT_FALSE(stored.paged());
  EXPECT_GT(stored.features()->stats.clipped, 0u);
  // Default options: open_model gives a quantized model the margin convert uses.
  const Model computed =
      open_model(dir.file("plain.ptl"), {.paging = Paging::Never, .features = FeatureOptions{}},
                 pool, Progress::none());
  EXPECT_EQ(computed.features()->options.clip_margin, kQuantizedClipMargin);
  ASSERT_NE(computed.features(), nullptr);
  const Frame a = render_model(stored, pool, true), b = render_model(computed, pool, true);
  EXPECT_TRUE(std::equal(a.color.begin(), a.color.end(), b.color.begin()));
  // --no-features: the stored ones are not drawn.
  const Frame off = render_model(stored, pool, false);
  EXPECT_FALSE(std::equal(a.color.begin(), a.color.end(), off.color.begin()));
}

TEST(ConvertFeatures, OnlyPtlVersion2StoresThem) {
  pointillist::testing::TempDir dir;
  ThreadPool pool(1);
  const std::string in[] = {write_cube_scan(dir)};
  ConvertOptions with;
  with.features = FeatureOptions{};
  for (const char* out : {"x.qs", "x.ply"}) {
    try {
      convert(in, dir.file(out), with, pool, Progress::none());
      FAIL() << out;
    } catch (const OptionError& e) {
      EXPECT_THAT(e.what(), HasSubstr("--features are stored only in .ptl version 2"));
    }
  }
}
