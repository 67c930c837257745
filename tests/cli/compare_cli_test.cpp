// End-to-end tests of `pointillist compare`: output fields, JSON, exit codes and messages.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "pointillist/io/png.hpp"
#include "cli/cli_run.hpp"
#include "testing/testing.hpp"

using namespace pointillist;
using ::testing::HasSubstr;

namespace {

using Result = pointillist::testing::CliResult;
Result run(const std::string& args) { return pointillist::testing::run_cli(args); }

// A black w×h image with a white w/2 × h/2 rectangle whose top-left corner is (x0, y0).
void write_rect_png(const std::string& path, int w, int h, int x0, int y0) {
  std::vector<Rgb8> pixels(std::size_t(w) * h, Rgb8{0, 0, 0});
  for (int y = y0; y < y0 + h / 2; ++y) {
    for (int x = x0; x < x0 + w / 2; ++x) pixels[std::size_t(y) * w + x] = {255, 255, 255};
  }
  write_png_rgb8(path, w, h, pixels);
}

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace

TEST(CompareCli, PrintsEveryMetric) {
  pointillist::testing::TempDir dir;
  const auto ref = dir.file("ref.png"), test = dir.file("test.png");
  // 32×32 with 16×16 squares, the test's shifted 8 px right: overlap 8×16 of a union 24×16.
  write_rect_png(ref, 32, 32, 8, 8);
  write_rect_png(test, 32, 32, 16, 8);
  const Result r = run("compare " + ref + " " + test);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("size:           32x32"));
  EXPECT_THAT(r.output, HasSubstr("background:     0,0,0"));
  EXPECT_THAT(r.output, HasSubstr("PSNR:"));
  EXPECT_THAT(r.output, HasSubstr("SSIM:"));
  // Interior of the reference square: 14×14; the test misses its left 7 columns of it.
  EXPECT_THAT(r.output, HasSubstr("hole pixels:    98 of 196 interior"));
  EXPECT_THAT(r.output, HasSubstr("silhouette IoU: 0.33333"));
  // 256 pixels differ by 255 in all three channels: MSE = 255² · 256 / 1024, PSNR = 10·log10(4).
  EXPECT_THAT(r.output, HasSubstr("PSNR:           6.02 dB"));
}

TEST(CompareCli, IdenticalImagesReportInfinitePsnr) {
  pointillist::testing::TempDir dir;
  const auto ref = dir.file("ref.png");
  write_rect_png(ref, 24, 20, 3, 4);
  const Result r = run("compare " + ref + " " + ref);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("PSNR:           inf dB"));
  EXPECT_THAT(r.output, HasSubstr("SSIM:           1.00000"));
  EXPECT_THAT(r.output, HasSubstr("hole pixels:    0 of"));
  EXPECT_THAT(r.output, HasSubstr("silhouette IoU: 1.00000"));
}

TEST(CompareCli, JsonToStdoutAndToFileWithBackgroundOverride) {
  pointillist::testing::TempDir dir;
  const auto ref = dir.file("ref.png"), test = dir.file("test.png"), json = dir.file("m.json");
  write_rect_png(ref, 32, 32, 8, 8);
  write_rect_png(test, 32, 32, 16, 8);
  const Result r = run("compare " + ref + " " + test + " --json -");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const char* key : {"\"psnr_db\": 6.0206", "\"ssim\": ", "\"hole_pixels\": 98",
                          "\"interior_pixels\": 196", "\"silhouette_iou\": 0.333333",
                          "\"width\": 32", "\"height\": 32", "\"background\": [0, 0, 0]"}) {
    EXPECT_THAT(r.output, HasSubstr(key));
  }
  EXPECT_THAT(r.output, ::testing::Not(HasSubstr("PSNR:")));  // JSON only on stdout

  // White as background: the black surround becomes the silhouette. Reference foreground
  // 1024 − 256 = 768, overlap 1024 − 384 = 640, IoU 640 / 896.
  const Result f = run("compare " + ref + " " + test + " --background 255,255,255 --json " + json);
  ASSERT_EQ(f.exit_code, 0) << f.output;
  EXPECT_THAT(f.output, HasSubstr("background:     255,255,255 (--background)"));
  const std::string text = read_text(json);
  EXPECT_THAT(text, HasSubstr("\"background\": [255, 255, 255]"));
  EXPECT_THAT(text, HasSubstr("\"silhouette_iou\": 0.714286"));
  EXPECT_THAT(text, HasSubstr("\"reference_foreground_pixels\": 768"));
}

TEST(CompareCli, IdenticalImagesGiveNullPsnrInJson) {
  pointillist::testing::TempDir dir;
  const auto ref = dir.file("ref.png");
  write_rect_png(ref, 16, 16, 2, 2);
  const Result r = run("compare " + ref + " " + ref + " --json -");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("\"psnr_db\": null"));
  EXPECT_THAT(r.output, HasSubstr("\"mse\": 0.000000"));
}

TEST(CompareCli, SizeMismatchFailsWithBothSizes) {
  pointillist::testing::TempDir dir;
  const auto ref = dir.file("ref.png"), test = dir.file("small.png");
  write_rect_png(ref, 32, 24, 4, 4);
  write_rect_png(test, 16, 24, 4, 4);
  const Result r = run("compare " + ref + " " + test);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_THAT(r.output, HasSubstr("small.png is 16x24"));
  EXPECT_THAT(r.output, HasSubstr("ref.png is 32x24"));
  EXPECT_THAT(r.output, HasSubstr("--size 32x24"));
}

TEST(CompareCli, MissingFileAndBadBackgroundFail) {
  pointillist::testing::TempDir dir;
  const auto ref = dir.file("ref.png");
  write_rect_png(ref, 16, 16, 2, 2);
  const Result missing = run("compare " + ref + " " + dir.file("nope.png"));
  EXPECT_NE(missing.exit_code, 0);
  EXPECT_THAT(missing.output, HasSubstr("nope.png"));
  const Result bad = run("compare " + ref + " " + ref + " --background 1,2");
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_THAT(bad.output, HasSubstr("--background"));
  const Result range = run("compare " + ref + " " + ref + " --background 0,300,0");
  EXPECT_NE(range.exit_code, 0);
  EXPECT_THAT(range.output, HasSubstr("0-255"));
  const Result not_png = run("compare " + ref + " " + POINTILLIST_CLI_PATH);
  EXPECT_NE(not_png.exit_code, 0);
  EXPECT_THAT(not_png.output, HasSubstr("error"));
}
