// The command line itself: exit codes (2 bad usage, 1 failed work), one error prefix for every
// error (CLI11's included), --version, readable --help, warnings for options that do not apply,
// and the view-time splat size.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <string>

#include "cli/cli_run.hpp"
#include "pointillist/io/png.hpp"
#include "testing/testing.hpp"

using namespace pointillist;
using pointillist::testing::run_cli;
using ::testing::HasSubstr;
using ::testing::Not;

namespace {

int foreground(const ImageRgb8& img) {
  int n = 0;
  for (const Rgb8& p : img.pixels) n += p.r + p.g + p.b > 0;
  return n;
}

}  // namespace

TEST(UsageCli, BadUsageExitsTwoWithTheProgramsPrefix) {
  for (const char* args : {"render", "render --no-such-option x", "frobnicate",
                           "convert a.ply", "render /nonexistent.ptl -o x.png"}) {
    const auto r = run_cli(args);
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.output;
    EXPECT_THAT(r.output, HasSubstr("pointillist: error: ")) << args;
  }
  pointillist::testing::TempDir dir;
  ASSERT_EQ(run_cli("generate --points 500 -o " + dir.file("a.ply")).exit_code, 0);
  // A bad option value found after parsing (ours, not CLI11's): still bad usage.
  const auto size = run_cli("render " + dir.file("a.ply") + " -o " + dir.file("a.png") +
                            " --size 0x10");
  EXPECT_EQ(size.exit_code, 2) << size.output;
  EXPECT_THAT(size.output, HasSubstr("pointillist: error: --size"));
}

TEST(UsageCli, FailedWorkExitsOne) {
  pointillist::testing::TempDir dir;
  pointillist::testing::write_text_file(dir.file("bad.ply"), "ply\nformat ascii 1.0\nelement");
  const auto r = run_cli("render " + dir.file("bad.ply") + " -o " + dir.file("x.png"));
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_THAT(r.output, HasSubstr("pointillist: error: " + dir.file("bad.ply")));
}

TEST(UsageCli, VersionAndHelp) {
  const auto v = run_cli("--version");
  EXPECT_EQ(v.exit_code, 0);
  EXPECT_THAT(v.output, HasSubstr("pointillist 0.1.0"));
  const auto convert = run_cli("convert --help");
  EXPECT_EQ(convert.exit_code, 0);
  EXPECT_THAT(convert.output, HasSubstr("{sixteenths,eighths}"));
  EXPECT_THAT(convert.output, HasSubstr("{auto,keep,mesh,pca}"));
  for (char c : convert.output) {
    EXPECT_TRUE(c == '\n' || (c >= 0x20 && c < 0x7f) || (c & 0x80)) << int(c);
  }
  const auto render = run_cli("render --help");
  for (const char* group : {"Camera:", "Look:", "Level of detail:", "Frame sequences:",
                            "Paging (models larger than memory):", "Scan preparation"}) {
    EXPECT_THAT(render.output, HasSubstr(group));
  }
  EXPECT_THAT(render.output, HasSubstr("{fast,quality,reference}"));
}

TEST(UsageCli, OptionsThatDoNotApplyAreNamedInAWarning) {
  pointillist::testing::TempDir dir;
  ASSERT_EQ(run_cli("generate --scene sphere --points 3000 -o " + dir.file("a.ply")).exit_code, 0);
  ASSERT_EQ(run_cli("convert " + dir.file("a.ply") + " -o " + dir.file("a.ptl") + " -q").exit_code,
            0);
  const auto r = run_cli("render " + dir.file("a.ptl") + " -o " + dir.file("x.png") +
                         " --size 64x48 --epsilon 2 --opacity 0.5 --k 8 -q");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("warning: --epsilon is ignored"));
  EXPECT_THAT(r.output, HasSubstr("warning: --opacity is ignored"));
  EXPECT_THAT(r.output, HasSubstr("warning: --k is ignored"));
  const auto clean = run_cli("render " + dir.file("a.ptl") + " -o " + dir.file("x.png") +
                             " --size 64x48 --lod spt --epsilon 2 -q");
  EXPECT_THAT(clean.output, Not(HasSubstr("warning")));
}

TEST(UsageCli, RadiusScaleOnAModelChangesTheDrawnSplatsOnly) {
  pointillist::testing::TempDir dir;
  ASSERT_EQ(run_cli("generate --scene sphere --points 2000 -o " + dir.file("a.ply")).exit_code, 0);
  ASSERT_EQ(run_cli("convert " + dir.file("a.ply") + " -o " + dir.file("a.ptl") + " -q").exit_code,
            0);
  const std::string base = "render " + dir.file("a.ptl") + " --size 200x150 --view 20,20 -q ";
  ASSERT_EQ(run_cli(base + "-o " + dir.file("small.png") + " --radius-scale 0.3 --stats " +
                    dir.file("small.json")).exit_code, 0);
  ASSERT_EQ(run_cli(base + "-o " + dir.file("one.png") + " --stats " + dir.file("one.json"))
                .exit_code, 0);
  // Smaller splats leave gaps between the samples: fewer covered pixels, same splat count.
  const int small = foreground(read_png_rgb8(dir.file("small.png")));
  const int one = foreground(read_png_rgb8(dir.file("one.png")));
  EXPECT_LT(small, one * 3 / 4);
  EXPECT_GT(small, 0);
  const auto splats = [](const std::string& json) {
    return json.substr(json.find("\"splats\""), json.find(',', json.find("\"splats\"")) -
                                                     json.find("\"splats\""));
  };
  std::ifstream a(dir.file("small.json")), b(dir.file("one.json"));
  const std::string ja{std::istreambuf_iterator<char>(a), {}}, jb{std::istreambuf_iterator<char>(b), {}};
  EXPECT_EQ(splats(ja), splats(jb));
}
