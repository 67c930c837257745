// `pointillist render` of several models and of scene files: both models drawn, and clear
// messages (file, field) for bad scene files.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "cli/cli_run.hpp"
#include "pointillist/io/png.hpp"
#include "testing/testing.hpp"

using namespace pointillist;
using pointillist::testing::run_cli;
using ::testing::HasSubstr;

namespace {

// Foreground pixels (not black) in columns [x0, x1) of the image.
int foreground(const ImageRgb8& img, int x0, int x1) {
  int n = 0;
  for (int y = 0; y < img.height; ++y) {
    for (int x = x0; x < x1; ++x) {
      const Rgb8 p = img.pixels[std::size_t(y) * img.width + x];
      n += p.r + p.g + p.b > 0;
    }
  }
  return n;
}

class SceneCli : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_EQ(run_cli("generate --scene sphere --points 4000 -o " + dir.file("a.ply")).exit_code,
              0);
    ASSERT_EQ(run_cli("convert " + dir.file("a.ply") + " -o " + dir.file("a.ptl") + " --quiet")
                  .exit_code,
              0);
  }
  std::string scene(const std::string& json) {
    const std::string path = dir.file("scene.json");
    pointillist::testing::write_text_file(path, json);
    return path;
  }
  pointillist::testing::TempDir dir;
};

}  // namespace

TEST_F(SceneCli, SceneFileWithTwoInstancesDrawsBoth) {
  const std::string s = scene(R"({"instances": [
      {"model": "a.ptl", "translate": [-1.5, 0, 0]},
      {"model": "a.ptl", "translate": [1.5, 0, 0], "rotate_deg": [0, 45, 0], "scale": 0.8}]})");
  const auto r = run_cli("render " + s + " -o " + dir.file("s.png") + " --size 200x100");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const ImageRgb8 img = read_png_rgb8(dir.file("s.png"));
  EXPECT_GT(foreground(img, 0, 90), 200);
  EXPECT_GT(foreground(img, 110, 200), 150);
  EXPECT_EQ(foreground(img, 98, 102), 0);  // the gap between them
}

TEST_F(SceneCli, SeveralInputsAreDrawnTogether) {
  ASSERT_EQ(run_cli("generate --scene torus --points 4000 -o " + dir.file("t.ply")).exit_code, 0);
  const std::string camera = " --size 160x120 --eye 0,3,4 --target 0,0,0";
  const auto one = run_cli("render " + dir.file("a.ptl") + " -o " + dir.file("one.png") + camera);
  const auto two = run_cli("render " + dir.file("a.ptl") + " " + dir.file("t.ply") + " -o " +
                           dir.file("two.png") + camera);
  ASSERT_EQ(one.exit_code, 0) << one.output;
  ASSERT_EQ(two.exit_code, 0) << two.output;
  EXPECT_THAT(two.output, HasSubstr("a.ptl, "));
  // The torus (around the unit sphere's centre, wider than it) shows around the sphere, so the
  // pair covers more of the picture than the sphere alone.
  const ImageRgb8 a = read_png_rgb8(dir.file("one.png")), b = read_png_rgb8(dir.file("two.png"));
  EXPECT_GT(foreground(b, 0, 160), foreground(a, 0, 160) + 200);
}

TEST_F(SceneCli, BadSceneFilesAreNamedWithTheField) {
  struct Case {
    std::string json, expect;
  };
  const Case cases[] = {
      {R"({"instances": [{"model": "a.ptl"})", "not valid JSON"},
      {R"([1, 2])", "an object with \"instances\""},
      {R"({"instances": []})", "instances: must be a non-empty array"},
      {R"({"instances": [{"model": "missing.ptl"}]})", "instances[0].model: "},
      {R"({"instances": [{"model": "a.ptl"}, {"translate": [0, 0, 0]}]})",
       "instances[1].model: must be the path"},
      {R"({"instances": [{"model": "a.ptl", "scale": -1}]})",
       "instances[0].scale: must be a positive number, found -1"},
      {R"({"instances": [{"model": "a.ptl", "rotate_deg": [0, 45]}]})",
       "instances[0].rotate_deg: must be an array of three numbers"},
      {R"({"instances": [{"model": "a.ptl", "translate": "up"}]})",
       "instances[0].translate: must be an array of three numbers"},
      {R"({"instances": [{"model": "a.ptl", "scal": 2}]})", "unknown field \"scal\""},
  };
  for (const Case& c : cases) {
    const std::string s = scene(c.json);
    const auto r = run_cli("render " + s + " -o " + dir.file("bad.png") + " --size 64x48");
    EXPECT_EQ(r.exit_code, 1) << c.json << "\n" << r.output;
    EXPECT_THAT(r.output, HasSubstr(s)) << c.json;
    EXPECT_THAT(r.output, HasSubstr(c.expect)) << c.json;
  }
  EXPECT_FALSE(std::filesystem::exists(dir.file("bad.png")));
}

TEST_F(SceneCli, SceneFileCannotBeMixedWithModels) {
  const std::string s = scene(R"({"instances": [{"model": "a.ptl"}]})");
  const auto r = run_cli("render " + s + " " + dir.file("a.ptl") + " -o " + dir.file("x.png"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_THAT(r.output, HasSubstr("a scene file is rendered on its own"));
}
