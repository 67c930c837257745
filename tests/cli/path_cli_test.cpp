// `pointillist generate --scene wall|city|field|row` and `render --path FILE`: the files a scene
// needs, every frame of a camera path file rendered, the fov rule, and messages naming the
// place at fault.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "cli/cli_run.hpp"
#include "pointillist/io/png.hpp"
#include "testing/testing.hpp"

using namespace pointillist;
using pointillist::testing::run_cli;
using pointillist::testing::write_text_file;
using ::testing::HasSubstr;
namespace fs = std::filesystem;

namespace {

// A small row scene (32 statues of 300 points) in `dir`.
std::string make_row(const pointillist::testing::TempDir& dir) {
  const auto r = run_cli("generate --scene row --points 300 -o " + dir.file("row.json"));
  EXPECT_EQ(r.exit_code, 0) << r.output;
  return dir.file("row.json");
}

std::string frame_file(const std::string& dir, int index) {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%05d.png", index);
  return (fs::path(dir) / name).string();
}

}  // namespace

TEST(PathCli, GenerateWritesTheSceneItsModelsAndPaths) {
  pointillist::testing::TempDir dir;
  const auto r = run_cli("generate --scene wall --spacing-scale 10 --points 300 -o " +
                         dir.file("out/wall.json"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output,
              HasSubstr("generated the wall scene: 101 instances, 100 of them scanned models"));
  EXPECT_THAT(r.output, HasSubstr("wall-wall.ptl 10251 points x1"));
  EXPECT_THAT(r.output, HasSubstr("wall-statue.ptl 300 points x100"));
  EXPECT_THAT(r.output, HasSubstr("wall.path 180 frames"));
  for (const char* f : {"wall.json", "wall-wall.ptl", "wall-statue.ptl", "wall.path"}) {
    EXPECT_TRUE(fs::exists(dir.file("out/") + f)) << f;
  }
  const auto quiet = run_cli("generate --scene city --spacing-scale 20 --points 100 --quiet -o " +
                             dir.file("city.json"));
  ASSERT_EQ(quiet.exit_code, 0) << quiet.output;
  EXPECT_EQ(quiet.output, "");
  for (const char* f : {"city-walk.path", "city-static.path", "city-fly.path", "city-turn.path",
                        "city-panel.ptl", "city-statue.ptl"}) {
    EXPECT_TRUE(fs::exists(dir.file(f))) << f;
  }
}

TEST(PathCli, RenderDrawsEveryFrameOfAPathFileAndEndsWithTheLast) {
  pointillist::testing::TempDir dir;
  const std::string scene = make_row(dir);
  write_text_file(dir.file("three.path"),
                  "# three frames\n0 1 5  0 1 0\n\n0.5 1.5 6  0 1 0\n-0.5 1 5  0 1 -3  0 1 0\n");
  const std::string frames = dir.file("frames");
  const auto r = run_cli("render " + scene + " --path " + dir.file("three.path") + " -o " +
                         dir.file("last.png") + " --size 64x48 --frames-out " + frames +
                         " --stats -");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto stats = nlohmann::json::parse(r.output);
  const auto& f = stats.at("frames");
  ASSERT_EQ(f.size(), 3u);
  for (const auto& frame : f) {
    EXPECT_EQ(frame.at("phase"), "path");
    EXPECT_FALSE(frame.contains("azimuth"));
    EXPECT_GT(frame.at("splats").get<int>(), 0);
  }
  for (int i = 0; i < 3; ++i) EXPECT_TRUE(fs::exists(frame_file(frames, i))) << i;
  EXPECT_FALSE(fs::exists(frame_file(frames, 3)));
  EXPECT_EQ(read_png_rgb8(frame_file(frames, 2)).pixels,
            read_png_rgb8(dir.file("last.png")).pixels);
  // Each frame is the image of its camera given with --eye/--target.
  const auto one = run_cli("render " + scene + " -o " + dir.file("one.png") +
                           " --size 64x48 --eye 0.5,1.5,6 --target 0,1,0");
  ASSERT_EQ(one.exit_code, 0) << one.output;
  EXPECT_EQ(read_png_rgb8(frame_file(frames, 1)).pixels, read_png_rgb8(dir.file("one.png")).pixels);
}

TEST(PathCli, TheFileFovAppliesUnlessFovIsGiven) {
  pointillist::testing::TempDir dir;
  const std::string scene = make_row(dir);
  write_text_file(dir.file("fov.path"), "fov 60\n0 1 5  0 1 0\n");
  const std::string camera = " --size 64x48 --eye 0,1,5 --target 0,1,0";
  ASSERT_EQ(run_cli("render " + scene + " -o " + dir.file("fov60.png") + camera + " --fov 60")
                .exit_code, 0);
  ASSERT_EQ(run_cli("render " + scene + " -o " + dir.file("fov20.png") + camera + " --fov 20")
                .exit_code, 0);
  ASSERT_EQ(run_cli("render " + scene + " --path " + dir.file("fov.path") + " -o " +
                    dir.file("file.png") + " --size 64x48").exit_code, 0);
  ASSERT_EQ(run_cli("render " + scene + " --path " + dir.file("fov.path") + " -o " +
                    dir.file("given.png") + " --size 64x48 --fov 20").exit_code, 0);
  const auto pixels = [&](const char* name) { return read_png_rgb8(dir.file(name)).pixels; };
  EXPECT_EQ(pixels("file.png"), pixels("fov60.png"));
  EXPECT_EQ(pixels("given.png"), pixels("fov20.png"));
  EXPECT_NE(pixels("fov60.png"), pixels("fov20.png"));
}

TEST(PathCli, FrameTimeAndRefinementWorkAlongAPathFile) {
  pointillist::testing::TempDir dir;
  const std::string scene = make_row(dir);
  const auto r = run_cli("render " + scene + " --path " + dir.file("row.path") + " -o " +
                         dir.file("x.png") + " --size 48x32 --threshold 4 --frame-ms 1000 "
                         "--refine 2 --stats -");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto stats = nlohmann::json::parse(r.output);
  EXPECT_EQ(stats.at("target_ms").get<double>(), 1000.0);
  const auto& f = stats.at("frames");
  ASSERT_EQ(f.size(), 32u);  // row.path's 30 frames, then 2 refining to 1 px
  EXPECT_EQ(f[29].at("phase"), "path");
  EXPECT_EQ(f[31].at("phase"), "refine");
  EXPECT_NEAR(f[31].at("detail").get<double>(), 1.0, 1e-6);
}

TEST(PathCli, BadPathFilesAndOptionsAreNamed) {
  pointillist::testing::TempDir dir;
  const std::string scene = make_row(dir);
  write_text_file(dir.file("bad.path"), "fov 30\n0 1 5  0 1 0\n0 1 5  0 1\n");
  const std::string base = "render " + scene + " -o " + dir.file("x.png") + " --size 32x32 ";
  auto r = run_cli(base + "--path " + dir.file("bad.path"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.output, HasSubstr("bad.path: line 3: expected 6 numbers"));
  r = run_cli(base + "--path " + dir.file("none.path"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.output, HasSubstr("no such camera path file"));
  r = run_cli(base + "--path " + dir.file("row.path") + " --eye 0,0,1 --target 0,0,0");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.output, HasSubstr("--eye/--target"));
  r = run_cli(base + "--path " + dir.file("row.path") + " --stats " + dir.file("row.path"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.output, HasSubstr("names an input"));
  r = run_cli(base + "--path " + dir.file("row.path") + " --view 10,10");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("--view is ignored: the camera path file places the camera"));
  r = run_cli("generate --scene row --models " + dir.file("nope.ptl") + " -o " +
              dir.file("r2.json"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.output, HasSubstr("nope.ptl: no such model file"));
  r = run_cli("generate --scene field -o " + dir.file("field.ply"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.output, HasSubstr("give a path ending in .json"));
}
