// `pointillist view` in a real window under Xvfb (installed by scripts/setup.sh): a scripted
// input file drives it; each settled screenshot equals, bit for bit, the image of the `render`
// command it prints; a drag to the right turns the camera to the left of the model; a bad model
// and a missing display end it with a message and a non-zero exit. Skipped where xvfb-run is
// missing.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "cli/cli_run.hpp"
#include "pointillist/core/math.hpp"
#include "testing/testing.hpp"

using pointillist::Vec3f;
using pointillist::testing::CliResult;
using pointillist::testing::run_cli;
using pointillist::testing::run_shell;
using pointillist::testing::write_text_file;
using ::testing::HasSubstr;

namespace {

bool have_xvfb() { return std::system("command -v xvfb-run >/dev/null 2>&1") == 0; }

// The viewer under a fresh X server (leak checking off: the X libraries keep memory to exit).
std::string viewer(const std::string& args) {
  return "xvfb-run -a -s '-screen 0 1280x1024x24' env ASAN_OPTIONS=detect_leaks=0 " +
         std::string(POINTILLIST_CLI_PATH) + " view " + args;
}

std::string bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

// The render command printed under "screenshot: FILE".
std::string printed_command(const std::string& output, const std::string& file) {
  const std::string mark = "screenshot: " + file + "\n  ";
  const auto at = output.find(mark);
  if (at == std::string::npos) return "";
  const auto start = at + mark.size();
  return output.substr(start, output.find('\n', start) - start);
}

Vec3f option_vec3(const std::string& command, const std::string& option) {
  const auto at = command.find(option + " ");
  Vec3f v{0, 0, 0};
  if (at != std::string::npos) {
    std::sscanf(command.c_str() + at + option.size() + 1, "%f,%f,%f", &v.x, &v.y, &v.z);
  }
  return v;
}

}  // namespace

TEST(ViewCli, ScreenshotsEqualThePrintedRenderCommandAndDragsTurnTheModel) {
  if (!have_xvfb()) GTEST_SKIP() << "xvfb-run not installed (scripts/setup.sh installs it)";
  pointillist::testing::TempDir dir;
  auto r = run_cli("generate --scene demo --points 60000 --quiet -o " + dir.file("demo.ply"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = run_cli("convert " + dir.file("demo.ply") + " -o " + dir.file("demo.ptl") + " --quiet");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string a = dir.file("a.png"), b = dir.file("b.png"), c = dir.file("c.png"),
                    d = dir.file("d.png");
  write_text_file(dir.file("s.events"),
                  "settle\nkey h\nscreenshot " + a + "\nkey h\ndrag left 300 240 380 240 8\nsettle\n"
                  "screenshot " + b + "\nkey m\nkey k\nwheel 200 200 2\nsettle\nscreenshot " +
                      c + "\nkey o\nkey e\nkey t\nwheel 320 240 1\nsettle\nscreenshot " + d +
                      "\nquit\n");
  r = run_shell(viewer(dir.file("demo.ptl") + " --size 640x480 --events " + dir.file("s.events") +
                       " --log-frames " + dir.file("frames.csv")));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const std::string& shot : {a, b, c, d}) {
    std::string command = printed_command(r.output, shot);
    ASSERT_FALSE(command.empty()) << r.output;
    ASSERT_EQ(command.rfind("pointillist render ", 0), 0u) << command;
    command = std::string(POINTILLIST_CLI_PATH) + command.substr(std::string("pointillist").size());
    const CliResult rendered = run_shell(command + " --quiet");
    ASSERT_EQ(rendered.exit_code, 0) << command << "\n" << rendered.output;
    const std::string out = shot.substr(0, shot.size() - 4) + "-render.png";
    EXPECT_EQ(bytes(shot), bytes(out)) << shot << " differs from " << command;
  }
  EXPECT_THAT(printed_command(r.output, c), HasSubstr("--mode quality --splat ellipse"));
  EXPECT_THAT(printed_command(r.output, d), HasSubstr("--ortho "));
  EXPECT_THAT(printed_command(r.output, d),
              HasSubstr("--mode quality --splat ellipse --edl 1 --two-sided"));
  // Dragging right turns the model right: the eye moves to the camera's left.
  const std::string ca = printed_command(r.output, a), cb = printed_command(r.output, b);
  const Vec3f eye_a = option_vec3(ca, "--eye"), target = option_vec3(ca, "--target");
  const Vec3f right = cross(target - eye_a, option_vec3(ca, "--up"));
  EXPECT_LT(dot(option_vec3(cb, "--eye") - eye_a, right), -0.01f * length(right));
  EXPECT_GT(bytes(dir.file("frames.csv")).size(), 100u);
}

TEST(ViewCli, BadModelAndMissingDisplayEndWithAMessage) {
  pointillist::testing::TempDir dir;
  write_text_file(dir.file("bad.ptl"), "PTL2 this is not a model");
  auto r = run_shell("env -u DISPLAY -u WAYLAND_DISPLAY " + std::string(POINTILLIST_CLI_PATH) +
                     " view " + dir.file("bad.ptl") + " --quiet");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_THAT(r.output, HasSubstr("bad.ptl"));
  r = run_cli("generate --scene sphere --points 2000 --quiet -o " + dir.file("s.ply"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = run_shell("env -u DISPLAY -u WAYLAND_DISPLAY ASAN_OPTIONS=detect_leaks=0 " +
                std::string(POINTILLIST_CLI_PATH) + " view " + dir.file("s.ply") + " --quiet");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_THAT(r.output, HasSubstr("the viewer needs a display"));
  r = run_cli("render " + dir.file("s.ply") + " --ortho -2 -o " + dir.file("x.png"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("--ortho"));
  r = run_cli("render " + dir.file("s.ply") + " --ortho 2.5 --view 0,90 --edl -q -o " +
              dir.file("plan.png"));
  EXPECT_EQ(r.exit_code, 0) << r.output;
  r = run_cli("view " + dir.file("s.ply") + " --events " + dir.file("s.ply"));
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_THAT(r.output, HasSubstr("s.ply:1: unknown event"));
}

// The window lives in a library loaded by `view` only: a program copied away from it still
// converts, and its `view` says which library it looked for and where, instead of crashing.
TEST(ViewCli, AProgramWithoutItsWindowLibraryConvertsAndSaysWhyItCannotView) {
  pointillist::testing::TempDir dir;
  const std::string copy = dir.file("pointillist");
  auto r = run_shell("cp " + std::string(POINTILLIST_CLI_PATH) + " " + copy);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = run_shell(copy + " generate --scene sphere --points 2000 --quiet -o " + dir.file("s.ply"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = run_shell(copy + " convert " + dir.file("s.ply") + " -o " + dir.file("s.ptl") + " --quiet");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = run_shell("env DISPLAY=:99 ASAN_OPTIONS=detect_leaks=0 " + copy + " view " +
                dir.file("s.ptl") + " --quiet");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_THAT(r.output, HasSubstr("pointillist-sdl-window.so"));
  EXPECT_THAT(r.output, HasSubstr(dir.path().string()));
  EXPECT_THAT(r.output, HasSubstr("cmake --install"));
}
