// End-to-end tests of the `pointillist` command: exit codes, messages, outputs.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "pointillist/io/ply.hpp"
#include "pointillist/io/png.hpp"
#include "cli/cli_run.hpp"
#include "testing/testing.hpp"

using namespace pointillist;
using ::testing::HasSubstr;
namespace fs = std::filesystem;

namespace {

using Result = pointillist::testing::CliResult;
Result run(const std::string& args) { return pointillist::testing::run_cli(args); }

void write_text(const std::string& path, const std::string& text) {
  pointillist::testing::write_text_file(path, text);
}

}  // namespace

TEST(Cli, GenerateConvertInfoRenderRoundTrip) {
  pointillist::testing::TempDir dir;
  const auto ply = dir.file("scene.ply"), ptl = dir.file("scene.ptl"), png = dir.file("scene.png");
  ASSERT_EQ(run("generate --scene sphere --points 20000 -o " + ply).exit_code, 0);
  const Result conv = run("convert " + ply + " -o " + ptl);
  ASSERT_EQ(conv.exit_code, 0) << conv.output;
  EXPECT_THAT(conv.output, HasSubstr("converted 20000 points"));
  const Result info = run("info " + ptl);
  ASSERT_EQ(info.exit_code, 0) << info.output;
  EXPECT_THAT(info.output, HasSubstr("points:      20000"));
  const Result ren = run("render " + ptl + " -o " + png + " --size 160x120 --view 30,20");
  ASSERT_EQ(ren.exit_code, 0) << ren.output;
  const ImageRgb8 img = read_png_rgb8(png);
  EXPECT_EQ(img.width, 160);
  EXPECT_EQ(img.height, 120);
  // The sphere is in the middle of the picture; the corners are background (black by default).
  const Rgb8 centre = img.pixels[60 * 160 + 80];
  EXPECT_GT(int(centre.r) + centre.g + centre.b, 100);
  EXPECT_EQ(img.pixels[0], (Rgb8{0, 0, 0}));
}

// generate --colors: each sample coloured by its exact normal, here the sphere's radial
// direction.
TEST(Cli, GenerateColoursEachSampleByItsExactNormal) {
  pointillist::testing::TempDir dir;
  const auto ply = dir.file("sphere.ply");
  ASSERT_EQ(run("generate --scene sphere --points 2000 --colors -q -o " + ply).exit_code, 0);
  const pointillist::PointSet p = pointillist::read_ply(ply);
  ASSERT_EQ(p.size(), 2000u);
  ASSERT_EQ(p.colors.size(), 2000u);
  int worst = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const pointillist::Vec3f n = pointillist::normalized(p.positions[i]);
    const int expect[3] = {int(127.5f + 127 * n.x), int(127.5f + 127 * n.y),
                           int(127.5f + 127 * n.z)};
    const int got[3] = {p.colors[i].r, p.colors[i].g, p.colors[i].b};
    for (int a = 0; a < 3; ++a) worst = std::max(worst, std::abs(got[a] - expect[a]));
  }
  EXPECT_LE(worst, 1);
}

TEST(Cli, RenderStatsJsonHasTheRequiredFields) {
  pointillist::testing::TempDir dir;
  const auto ply = dir.file("scene.ply");
  ASSERT_EQ(run("generate --scene torus --points 5000 --with-normals -o " + ply).exit_code, 0);
  const Result r = run("render " + ply + " -o " + dir.file("t.png") + " --size 64x48 --stats -");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const char* key : {"\"splats\"", "\"nodes_visited\"", "\"culled_frustum\"",
                          "\"culled_backface\"", "\"width\": 64", "\"height\": 48", "\"threads\"",
                          "\"select\"", "\"raster\"", "\"total\""}) {
    EXPECT_THAT(r.output, HasSubstr(key));
  }
}

TEST(Cli, ConvertToPlyWritesNormalsAndRadii) {
  pointillist::testing::TempDir dir;
  const auto in = dir.file("in.ply"), out = dir.file("out.ply");
  ASSERT_EQ(run("generate --scene sphere --points 3000 -o " + in).exit_code, 0);
  ASSERT_EQ(run("convert -q " + in + " -o " + out).exit_code, 0);
  const PointSet p = read_ply(out);
  EXPECT_EQ(p.size(), 3000u);
  ASSERT_TRUE(p.has_normals());
  ASSERT_TRUE(p.has_radii());
  for (std::size_t i = 0; i < p.size(); ++i) {
    EXPECT_GT(dot(p.normals[i], p.positions[i]), 0.0f) << "normal " << i << " faces inward";
    EXPECT_GT(p.radii[i], 0.0f);
  }
}

TEST(Cli, TruncatedInputFailsWithFileAndPositionAndLeavesNoOutput) {
  pointillist::testing::TempDir dir;
  const auto bad = dir.file("bad.ply"), out = dir.file("out.ptl");
  write_text(bad,
             "ply\nformat binary_little_endian 1.0\nelement vertex 10\nproperty float x\n"
             "property float y\nproperty float z\nend_header\n\x01\x02\x03");
  const Result r = run("convert " + bad + " -o " + out);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_THAT(r.output, HasSubstr("bad.ply"));
  EXPECT_THAT(r.output, HasSubstr("byte"));
  EXPECT_FALSE(fs::exists(out));
  for (const auto& entry : fs::directory_iterator(dir.path())) {
    EXPECT_THAT(entry.path().filename().string(), ::testing::Not(HasSubstr("out")))
        << "left a partial file behind";
  }
}

TEST(Cli, AsciiErrorNamesTheLine) {
  pointillist::testing::TempDir dir;
  const auto bad = dir.file("bad.ply");
  write_text(bad,
             "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
             "property float z\nend_header\n0 0 0\n1 oops 2\n");
  const Result r = run("convert " + bad + " -o " + dir.file("o.ptl"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_THAT(r.output, HasSubstr("bad.ply"));
  EXPECT_THAT(r.output, HasSubstr("line 9"));
}

TEST(Cli, UnknownOutputExtensionIsExplained) {
  pointillist::testing::TempDir dir;
  const auto in = dir.file("in.ply");
  ASSERT_EQ(run("generate --points 100 -o " + in).exit_code, 0);
  const Result r = run("convert " + in + " -o " + dir.file("model.xyz"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_THAT(r.output, HasSubstr(".ptl"));
}

TEST(Cli, MissingInputAndBadOptionsFailCleanly) {
  EXPECT_NE(run("render /nonexistent/model.ptl -o /tmp/x.png").exit_code, 0);
  pointillist::testing::TempDir dir;
  const auto in = dir.file("in.ply");
  ASSERT_EQ(run("generate --points 100 -o " + in).exit_code, 0);
  const Result r = run("render " + in + " -o " + dir.file("x.png") + " --view 10,91");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_THAT(r.output, HasSubstr("elevation"));
  const Result s = run("render " + in + " -o " + dir.file("x.png") + " --size 12by4");
  EXPECT_NE(s.exit_code, 0);
  EXPECT_THAT(s.output, HasSubstr("--size"));
}

TEST(Cli, RenderingAPtlIsNotConvertedAgain) {
  pointillist::testing::TempDir dir;
  const auto in = dir.file("in.ply"), ptl = dir.file("m.ptl");
  ASSERT_EQ(run("generate --points 1000 -o " + in).exit_code, 0);
  ASSERT_EQ(run("convert -q " + in + " -o " + ptl).exit_code, 0);
  const Result r = run("convert " + ptl + " -o " + dir.file("again.ptl"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_THAT(r.output, HasSubstr("already a splat model (.ptl)"));
}

TEST(Cli, OrbitPathWithRefinementWritesEveryFrameAndEndsAtFullDetail) {
  pointillist::testing::TempDir dir;
  const auto ply = dir.file("scene.ply");
  ASSERT_EQ(run("generate --scene torus --points 20000 -o " + ply).exit_code, 0);
  const std::string frames = dir.file("frames");
  const Result r = run("render " + ply + " -o " + dir.file("last.png") +
                       " --size 96x64 --threshold 6 --path orbit:4 --refine 3 --frames-out " +
                       frames + " --stats -");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // 4 path frames at azimuths 0, 90, 180, 270 (threshold 6), then 3 refining to 1 px: 6, √6, 1.
  const auto stats = nlohmann::json::parse(r.output);
  const auto& f = stats.at("frames");
  ASSERT_EQ(f.size(), 7u);
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(f[i].at("phase"), "path");
    EXPECT_DOUBLE_EQ(f[i].at("azimuth").get<double>(), 90.0 * i);
    EXPECT_DOUBLE_EQ(f[i].at("detail").get<double>(), 6.0);
  }
  for (int i = 4; i < 7; ++i) EXPECT_EQ(f[i].at("phase"), "refine");
  EXPECT_NEAR(f[4].at("detail").get<double>(), 6.0, 1e-5);
  EXPECT_NEAR(f[5].at("detail").get<double>(), std::sqrt(6.0), 1e-5);
  EXPECT_NEAR(f[6].at("detail").get<double>(), 1.0, 1e-6);
  for (int i = 0; i < 7; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "/frame_%05d.png", i);
    EXPECT_TRUE(fs::exists(frames + name)) << name;
  }
  EXPECT_FALSE(fs::exists(frames + "/frame_00007.png"));
  // The last frame is the -o image and is the full-detail one.
  const ImageRgb8 last_png = read_png_rgb8(dir.file("last.png"));
  const ImageRgb8 last_frame = read_png_rgb8(frames + "/frame_00006.png");
  EXPECT_EQ(last_png.pixels, last_frame.pixels);
}

TEST(Cli, FrameTimeControlReportsAHitRate) {
  pointillist::testing::TempDir dir;
  const auto ply = dir.file("scene.ply");
  ASSERT_EQ(run("generate --scene sphere --points 5000 -o " + ply).exit_code, 0);
  // A generous target: a small image renders far faster, so every frame is at full detail and
  // counts as a hit.
  const Result r = run("render " + ply + " -o " + dir.file("x.png") +
                       " --size 64x48 --path orbit:12 --frame-ms 1000 --stats -");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto stats = nlohmann::json::parse(r.output);
  EXPECT_EQ(stats.at("target_ms").get<double>(), 1000.0);
  EXPECT_EQ(stats.at("hit_rate").get<double>(), 1.0);
}

TEST(Cli, BadSequenceOptionsAreExplained) {
  pointillist::testing::TempDir dir;
  const auto ply = dir.file("scene.ply");
  ASSERT_EQ(run("generate --points 500 -o " + ply).exit_code, 0);
  const std::string base = "render " + ply + " -o " + dir.file("x.png") + " --size 32x32 ";
  Result r = run(base + "--path circle:4");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_THAT(r.output, HasSubstr("orbit:N"));
  r = run(base + "--path orbit:0");
  EXPECT_NE(r.exit_code, 0);
  r = run(base + "--frame-ms 10");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_THAT(r.output, HasSubstr("--path"));
  r = run(base + "--frames-out " + dir.file("f"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_THAT(r.output, HasSubstr("--refine"));
  r = run(base + "--path orbit:3 --eye 1,1,1 --target 0,0,0");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_THAT(r.output, HasSubstr("--eye"));
}

TEST(Cli, SequentialPointTreeRenderAndInfo) {
  pointillist::testing::TempDir dir;
  const auto ply = dir.file("scene.ply");
  ASSERT_EQ(run("generate --scene torus --points 20000 -o " + ply).exit_code, 0);
  const Result r = run("render " + ply + " -o " + dir.file("spt.png") +
                       " --size 160x120 --lod spt --epsilon 2 --stats -");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("\"lod\": \"spt\""));
  EXPECT_THAT(r.output, HasSubstr("\"fraction_scanned\""));
  EXPECT_THAT(r.output, HasSubstr("\"list_length\""));
  const ImageRgb8 img = read_png_rgb8(dir.file("spt.png"));
  const Rgb8 centre_left = img.pixels[60 * 160 + 40];  // on the torus ring
  EXPECT_GT(int(centre_left.r) + centre_left.g + centre_left.b, 60);
  const Result i = run("info " + ply + " --spt --view 30,20 --epsilon 1");
  ASSERT_EQ(i.exit_code, 0) << i.output;
  EXPECT_THAT(i.output, HasSubstr("sequential point tree"));
  EXPECT_THAT(i.output, HasSubstr("% of the list"));
  EXPECT_NE(run("render " + ply + " -o " + dir.file("x.png") + " --lod octree").exit_code, 0);
}

TEST(Cli, ChunkCullingSkipsChunksInACloseUpWithoutChangingTheImage) {
  // A close-up of the torus: part of it is outside the view. With chunk culling some chunks
  // are culled; without, none are, and the image is the same (culling only skips chunks no
  // entry of which could be drawn).
  pointillist::testing::TempDir dir;
  const auto ply = dir.file("scene.ply"), ptl = dir.file("scene.ptl");
  ASSERT_EQ(run("generate --scene torus --points 40000 -o " + ply).exit_code, 0);
  ASSERT_EQ(run("convert -q " + ply + " -o " + ptl).exit_code, 0);
  const std::string common = " --size 200x150 --lod spt --distance 0.5 --view 20,10 --stats -";
  const Result on = run("render " + ptl + " -o " + dir.file("on.png") + common);
  const Result off =
      run("render " + ptl + " -o " + dir.file("off.png") + common + " --no-chunk-culling");
  ASSERT_EQ(on.exit_code, 0) << on.output;
  ASSERT_EQ(off.exit_code, 0) << off.output;
  EXPECT_THAT(off.output, HasSubstr("\"chunks_culled\": 0,"));
  EXPECT_THAT(on.output, ::testing::Not(HasSubstr("\"chunks_culled\": 0,")));
  EXPECT_EQ(read_png_rgb8(dir.file("on.png")).pixels, read_png_rgb8(dir.file("off.png")).pixels);
}

// Asked to (POINTILLIST_HUGE_PAGES=1), convert restarts itself once with glibc's huge-page
// tunable (cli/util.hpp use_huge_pages): the restart may not lose an argument or change a byte.
// The reference is the same conversion with no restart (the default, and the tunable given as
// off).
TEST(Cli, MemoryTuningChangesNoByteOfTheOutput) {
  pointillist::testing::TempDir dir;
  Result r = pointillist::testing::run_cli("generate --scene demo --points 30000 --quiet -o " +
                                           dir.file("in.ply"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = pointillist::testing::run_shell("env POINTILLIST_HUGE_PAGES=1 " +
                                      std::string(POINTILLIST_CLI_PATH) + " convert " +
                                      dir.file("in.ply") + " -o " + dir.file("tuned.ptl") +
                                      " --quiet");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = pointillist::testing::run_shell(
      "env -u POINTILLIST_HUGE_PAGES GLIBC_TUNABLES=glibc.malloc.hugetlb=0 " +
      std::string(POINTILLIST_CLI_PATH) + " convert " + dir.file("in.ply") + " -o " +
      dir.file("plain.ptl") + " --quiet");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream a(dir.file("tuned.ptl"), std::ios::binary), b(dir.file("plain.ptl"), std::ios::binary);
  const std::string tuned{std::istreambuf_iterator<char>(a), {}};
  const std::string plain{std::istreambuf_iterator<char>(b), {}};
  ASSERT_GT(tuned.size(), 1000u);
  EXPECT_TRUE(tuned == plain) << "the tuned conversion wrote different bytes";
}
