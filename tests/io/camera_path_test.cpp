// Camera path files: the text is written here by hand, so the expected frames, the golden bytes
// of the writer and the error places (line numbers) are the test's own.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "io_test_support.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/io/camera_path.hpp"
#include "testing/testing.hpp"

namespace pointillist {
namespace {

using pointillist::testing::TempDir;
using pointillist::testing::write_file;

void expect_vec(Vec3f got, Vec3f want) {
  EXPECT_EQ(got.x, want.x);
  EXPECT_EQ(got.y, want.y);
  EXPECT_EQ(got.z, want.z);
}

std::string error_of(const std::string& text) {
  try {
    parse_camera_path(text, "p.path");
  } catch (const FormatError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(CameraPath, ReadsFramesCommentsBlankLinesAndTheFovLine) {
  const CameraPath p = parse_camera_path(
      "# a path\n"
      "\n"
      "fov 45   # degrees\n"
      "0 2 30  0 2 0\n"
      "  \t\r\n"
      "1.5 -2e1 +3   4 5 6   0 0 1  # with an up vector\r\n"
      "7 8 9 10 11 12",  // no newline at the end
      "p.path");
  ASSERT_TRUE(p.fov_deg);
  EXPECT_EQ(*p.fov_deg, 45.0f);
  ASSERT_EQ(p.frames.size(), 3u);
  expect_vec(p.frames[0].eye, {0, 2, 30});
  expect_vec(p.frames[0].target, {0, 2, 0});
  EXPECT_FALSE(p.frames[0].up);
  EXPECT_EQ(p.frames[0].line, 4u);
  expect_vec(p.frames[1].eye, {1.5f, -20, 3});
  expect_vec(p.frames[1].target, {4, 5, 6});
  ASSERT_TRUE(p.frames[1].up);
  expect_vec(*p.frames[1].up, {0, 0, 1});
  EXPECT_EQ(p.frames[1].line, 6u);
  expect_vec(p.frames[2].target, {10, 11, 12});
  EXPECT_FALSE(parse_camera_path("1 1 1 0 0 0\n", "p.path").fov_deg);
}

TEST(CameraPath, WriterGivesTheGoldenTextAndReadsBackTheSameFloats) {
  CameraPath p;
  p.fov_deg = 60.0f;
  p.frames.push_back({{96, 1.7f, 2}, {96.1f, 1.7f, 3}, std::nullopt, 0});
  p.frames.push_back({{0.1f, -2.5f, 1e-7f}, {1, 2, 3}, Vec3f{0, 0, 1}, 0});
  const std::string text = format_camera_path(p, "two frames\nsecond line");
  EXPECT_EQ(text,
            "# two frames\n"
            "# second line\n"
            "fov 60\n"
            "96 1.7 2  96.1 1.7 3\n"
            "0.1 -2.5 1e-07  1 2 3  0 0 1\n");
  TempDir dir;
  write_camera_path(dir.file("a.path"), p, "two frames");
  const CameraPath back = read_camera_path(dir.file("a.path"));
  ASSERT_EQ(back.frames.size(), 2u);
  EXPECT_EQ(*back.fov_deg, 60.0f);
  for (std::size_t i = 0; i < 2; ++i) {
    expect_vec(back.frames[i].eye, p.frames[i].eye);
    expect_vec(back.frames[i].target, p.frames[i].target);
    EXPECT_EQ(back.frames[i].up.has_value(), p.frames[i].up.has_value());
  }
  // Odd floats survive too (shortest form, read back exactly).
  CameraPath odd;
  odd.frames.push_back({{1.0f / 3, 123456.789f, -7.0e-30f}, {3.4e38f, 0, 0}, std::nullopt, 0});
  const CameraPath odd_back = parse_camera_path(format_camera_path(odd), "odd");
  expect_vec(odd_back.frames[0].eye, odd.frames[0].eye);
  expect_vec(odd_back.frames[0].target, odd.frames[0].target);
}

TEST(CameraPath, ErrorsNameTheFileTheLineAndWhatWasExpected) {
  struct Case {
    std::string text, expect;
  };
  const Case cases[] = {
      {"0 0 1 0 0 0\n# c\n1 2 3 4 5\n", "p.path: line 3: expected 6 numbers"},
      {"0 0 1 0 0 0 0 1\n", "p.path: line 1: expected 6 numbers"},
      {"0 0 1 0 0 0 0 1 0 1 2 3 4\n", "found 10 or more values"},
      {"0 0 1 0 zero 0\n", "p.path: line 1: value 5 'zero' is not a number"},
      {"0 0 1 0 0 0x1\n", "value 6 '0x1' is not a number"},
      {"\n0 0 nan 0 0 0\n", "p.path: line 2: value 3 'nan' is not a finite number"},
      {"0 0 1e39 0 0 0\n", "value 3 '1e39' is not a finite number"},
      {"0 0 inf 0 0 0\n", "is not a finite number"},
      {"1 2 3 1 2 3\n", "p.path: line 1: the eye and the target are the same point"},
      {"0 0 5 0 0 0 0 0 1\n", "p.path: line 1: the up vector (0 0 1) is zero or parallel"},
      {"0 0 5 0 0 0 0 0 0\n", "is zero or parallel"},
      {"fov\n0 0 1 0 0 0\n", "p.path: line 1: expected 'fov DEGREES'"},
      {"fov 180\n0 0 1 0 0 0\n", "between 0 and 180"},
      {"fov 30 40\n0 0 1 0 0 0\n", "expected 'fov DEGREES'"},
      {"0 0 1 0 0 0\nfov 30\n", "p.path: line 2: the fov line comes after a frame"},
      {"fov 30\nfov 40\n0 0 1 0 0 0\n", "p.path: line 2: a second fov line"},
      {"", "p.path: no frames"},
      {"# only a comment\nfov 30\n", "p.path: no frames"},
  };
  for (const Case& c : cases) {
    EXPECT_NE(error_of(c.text).find(c.expect), std::string::npos)
        << "text: " << c.text << "\nmessage: " << error_of(c.text);
  }
}

TEST(CameraPath, StopsAtTheFrameCap) {
  std::string text;
  text.reserve(12 * (kMaxCameraPathFrames + 1));
  for (std::size_t i = 0; i <= kMaxCameraPathFrames; ++i) text += "0 0 1 0 0 0\n";
  EXPECT_NE(error_of(text).find("line 1000001: more than 1000000 frames"), std::string::npos)
      << error_of(text);
  text.resize(12 * kMaxCameraPathFrames);
  EXPECT_EQ(parse_camera_path(text, "p.path").frames.size(), kMaxCameraPathFrames);
}

TEST(CameraPath, MissingFileIsAnIoErrorNamingIt) {
  TempDir dir;
  try {
    read_camera_path(dir.file("none.path"));
    FAIL() << "no error";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("none.path"), std::string::npos) << e.what();
  }
}

TEST(CameraPath, CamerasTakeTheFovTheSizeAndTheDefaultUp) {
  const CameraPath p = parse_camera_path("0 0 5 0 0 0\n\n1 0 0 0 0 0 0 0 1\n", "p.path");
  const std::vector<Camera> c = path_cameras(p, "p.path", 40.0f, 64, 48, {1, 0, 0});
  ASSERT_EQ(c.size(), 2u);
  expect_vec(c[0].up, {1, 0, 0});
  expect_vec(c[1].up, {0, 0, 1});
  EXPECT_EQ(c[1].fov_deg, 40.0f);
  EXPECT_EQ(c[1].width, 64);
  EXPECT_EQ(c[1].height, 48);
  // The default up along the second frame's view direction: named by its line.
  try {
    path_cameras(parse_camera_path("0 0 5 0 0 0\n\n1 0 0 0 0 0\n", "p.path"), "p.path", 40.0f, 64,
                 48, {1, 0, 0});
    FAIL() << "no error";
  } catch (const FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("p.path: line 3: the up vector (1 0 0) is parallel"),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW(path_cameras(p, "p.path", 180.0f, 64, 48), OptionError);
}

}  // namespace
}  // namespace pointillist
