// Text point cloud reader (XYZ/PTS/CSV/TXT): every file is written here by hand, so expected
// values, detected layouts and error places (line numbers) are the test's own.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "io_test_support.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/core/thread_pool.hpp"
#include "pointillist/io/xyz.hpp"
#include "testing/testing.hpp"

namespace pointillist {
namespace {

using pointillist::testing::TempDir;
using pointillist::testing::write_file;

#define EXPECT_CONTAINS(text, part)                          \
  EXPECT_NE(std::string(text).find(part), std::string::npos) \
      << "message: " << (text) << "\nexpected it to contain: " << (part)

PointSet read_text(const TempDir& dir, const std::string& text, const XyzReadOptions& options = {},
                   const std::string& name = "points.xyz") {
  const std::string path = dir.file(name);
  write_file(path, text);
  return read_xyz(path, Progress::none(), options);
}

void expect_vec(Vec3f got, Vec3f want, float tolerance = 0.0f) {
  EXPECT_NEAR(got.x, want.x, tolerance);
  EXPECT_NEAR(got.y, want.y, tolerance);
  EXPECT_NEAR(got.z, want.z, tolerance);
}

bool has_comment(const PointSet& points, const std::string& text) {
  for (const std::string& c : points.comments)
    if (c == text) return true;
  return false;
}

TEST(XyzReader, ReadsBlankSeparatedPositions) {
  TempDir dir;
  const PointSet p = read_text(dir, "0.5 -1.25 3\n1e2 2.5E-1 -0\n");
  ASSERT_EQ(p.size(), 2u);
  expect_vec(p.positions[0], {0.5f, -1.25f, 3.0f});
  expect_vec(p.positions[1], {100.0f, 0.25f, 0.0f});
  EXPECT_FALSE(p.has_normals());
  EXPECT_FALSE(p.has_colors());
  EXPECT_TRUE(has_comment(p, "columns: x y z (from the 3 values on line 1)"));
}

TEST(XyzReader, SkipsBlankAndCommentLinesAndAcceptsTabsAndCrlf) {
  TempDir dir;
  const PointSet p =
      read_text(dir, "# scan of a box\r\n\r\n1\t2\t3\r\n   \n// more\n  4  5\t 6  \r\n# end\n7 8 9");
  ASSERT_EQ(p.size(), 3u);
  expect_vec(p.positions[0], {1, 2, 3});
  expect_vec(p.positions[1], {4, 5, 6});
  expect_vec(p.positions[2], {7, 8, 9});  // no newline at the end
}

TEST(XyzReader, ParsesPrecisely) {
  TempDir dir;
  // Values that are not exact in binary: the result must be the correctly rounded float.
  const PointSet p = read_text(dir, "0.1 0.2 0.3\n123.456 -7.89e-3 3.14159265358979\n");
  ASSERT_EQ(p.size(), 2u);
  EXPECT_EQ(p.positions[0].x, 0.1f);
  EXPECT_EQ(p.positions[0].y, 0.2f);
  EXPECT_EQ(p.positions[0].z, 0.3f);
  EXPECT_EQ(p.positions[1].x, 123.456f);
  EXPECT_EQ(p.positions[1].y, -7.89e-3f);
  EXPECT_EQ(p.positions[1].z, 3.14159265358979f);
}

TEST(XyzReader, ReadsCsvWithHeaderAndByteColors) {
  TempDir dir;
  const PointSet p =
      read_text(dir, "x,y,z,red,green,blue\n1.5, 2, 3 ,255,0,128\n-1,-2,-3,10,20,30,\n", {},
                "points.csv");
  ASSERT_EQ(p.size(), 2u);
  expect_vec(p.positions[0], {1.5f, 2, 3});
  expect_vec(p.positions[1], {-1, -2, -3});
  ASSERT_TRUE(p.has_colors());
  EXPECT_EQ(p.colors[0], (Rgb8{255, 0, 128}));
  EXPECT_EQ(p.colors[1], (Rgb8{10, 20, 30}));
  EXPECT_TRUE(has_comment(p, "columns: x y z r g b (from the header on line 1)"));
}

TEST(XyzReader, ReadsSemicolonSeparatedValues) {
  TempDir dir;
  const PointSet p = read_text(dir, "1;2;3\n4 ; 5 ; 6\n", {}, "points.csv");
  ASSERT_EQ(p.size(), 2u);
  expect_vec(p.positions[1], {4, 5, 6});
}

TEST(XyzReader, HeaderOrderDecidesColumns) {
  TempDir dir;
  // CloudCompare style header, columns in an unusual order.
  const PointSet p = read_text(dir, "//Z,X,Y,B,G,R,Nx,Ny,Nz\n3,1,2,30,20,10,0,0,2\n");
  ASSERT_EQ(p.size(), 1u);
  expect_vec(p.positions[0], {1, 2, 3});
  ASSERT_TRUE(p.has_colors());
  EXPECT_EQ(p.colors[0], (Rgb8{10, 20, 30}));
  ASSERT_TRUE(p.has_normals());
  expect_vec(p.normals[0], {0, 0, 1});
}

TEST(XyzReader, DetectsNormalsInSixColumns) {
  TempDir dir;
  // A negative value marks normals; unnormalized ones are normalized.
  const PointSet p = read_text(dir, "0 0 0 0 0 2\n1 1 1 -3 4 0\n");
  ASSERT_EQ(p.size(), 2u);
  ASSERT_TRUE(p.has_normals());
  EXPECT_FALSE(p.has_colors());
  expect_vec(p.normals[0], {0, 0, 1}, 1e-6f);
  expect_vec(p.normals[1], {-0.6f, 0.8f, 0}, 1e-6f);
}

TEST(XyzReader, DetectsPositiveUnitNormals) {
  TempDir dir;
  // All rows of unit length with decimals: normals, even without a negative value.
  const PointSet p = read_text(dir, "0 0 0 0.6 0.8 0.0\n1 1 1 0.0 0.0 1.0\n");
  ASSERT_TRUE(p.has_normals());
  EXPECT_FALSE(p.has_colors());
  expect_vec(p.normals[0], {0.6f, 0.8f, 0}, 1e-6f);
}

TEST(XyzReader, DetectsUnitColorsInSixColumns) {
  TempDir dir;
  const PointSet p = read_text(dir, "0 0 0 0.5 1.0 0.0\n1 1 1 0.2 0.2 0.2\n");
  ASSERT_TRUE(p.has_colors());
  EXPECT_FALSE(p.has_normals());
  // 0.5 * 255 = 127.5 rounds to 128; 0.2 * 255 = 51.
  EXPECT_EQ(p.colors[0], (Rgb8{128, 255, 0}));
  EXPECT_EQ(p.colors[1], (Rgb8{51, 51, 51}));
}

TEST(XyzReader, UnitColorsWithOnlyZeroAndOneAreStillUnit) {
  TempDir dir;
  // The decimal point says 0..1 although no value has a fraction. (Without the header these
  // unit-length rows would be taken as normals.)
  const PointSet p = read_text(dir, "x y z r g b\n0 0 0 1.0 0.0 0.0\n1 1 1 0.0 0.0 1.0\n");
  ASSERT_TRUE(p.has_colors());
  EXPECT_EQ(p.colors[0], (Rgb8{255, 0, 0}));
  EXPECT_EQ(p.colors[1], (Rgb8{0, 0, 255}));
}

TEST(XyzReader, DetectsByteColorsInSixColumns) {
  TempDir dir;
  const PointSet p = read_text(dir, "0 0 0 1 1 0\n1 1 1 200 100 255\n");
  ASSERT_TRUE(p.has_colors());
  // Integers without a decimal point are 0..255, even the small ones.
  EXPECT_EQ(p.colors[0], (Rgb8{1, 1, 0}));
  EXPECT_EQ(p.colors[1], (Rgb8{200, 100, 255}));
}

TEST(XyzReader, DetectsSixteenBitColors) {
  TempDir dir;
  const PointSet p = read_text(dir, "0 0 0 65535 0 257\n");
  ASSERT_TRUE(p.has_colors());
  // 257 * 255 / 65535 = 1.
  EXPECT_EQ(p.colors[0], (Rgb8{255, 0, 1}));
}

TEST(XyzReader, ReadsPtsWithCountLineAndIntensity) {
  TempDir dir;
  // Leica PTS: a point count, then x y z intensity r g b.
  const PointSet p =
      read_text(dir, "2\n1.5 2.5 3.5 -1200 10 20 30\n4 5 6 300 40 50 60\n", {}, "scan.pts");
  ASSERT_EQ(p.size(), 2u);
  expect_vec(p.positions[0], {1.5f, 2.5f, 3.5f});
  ASSERT_TRUE(p.has_colors());
  EXPECT_EQ(p.colors[1], (Rgb8{40, 50, 60}));
  EXPECT_FALSE(p.has_normals());
  EXPECT_TRUE(has_comment(p, "columns: x y z skip r g b (from the 7 values on line 2)"));
}

TEST(XyzReader, PtsCountLineIsNotChecked) {
  TempDir dir;
  const PointSet p = read_text(dir, "5\n1 2 3\n", {}, "scan.pts");
  EXPECT_EQ(p.size(), 1u);
}

TEST(XyzReader, DetectsNormalsAndColorsInNineColumnsEitherOrder) {
  TempDir dir;
  const PointSet a = read_text(dir, "1 2 3 0 -1 0 10 20 30\n4 5 6 1 0 0 40 50 60\n");
  ASSERT_TRUE(a.has_normals());
  ASSERT_TRUE(a.has_colors());
  expect_vec(a.normals[0], {0, -1, 0});
  EXPECT_EQ(a.colors[1], (Rgb8{40, 50, 60}));

  const PointSet b = read_text(dir, "1 2 3 10 20 30 0 -1 0\n4 5 6 40 50 60 1 0 0\n");
  ASSERT_TRUE(b.has_normals());
  ASSERT_TRUE(b.has_colors());
  expect_vec(b.normals[0], {0, -1, 0});
  EXPECT_EQ(b.colors[1], (Rgb8{40, 50, 60}));
  EXPECT_TRUE(has_comment(b, "columns: x y z r g b nx ny nz (from the 9 values on line 1)"));
}

TEST(XyzReader, OtherColumnCountsReadPositionsOnly) {
  TempDir dir;
  const PointSet p = read_text(dir, "1 2 3 4 5\n6 7 8 9 10\n");
  ASSERT_EQ(p.size(), 2u);
  expect_vec(p.positions[1], {6, 7, 8});
  EXPECT_FALSE(p.has_colors());
  EXPECT_TRUE(has_comment(p, "columns: x y z skip skip (from the 5 values on line 1)"));
}

TEST(XyzReader, ColumnsOptionOverridesDetection) {
  TempDir dir;
  const std::string text = "1 2 3 99 10 20 30\n4 5 6 98 40 50 60\n";
  const PointSet p = read_text(dir, text, {.columns = "z,y,x,skip,b,g,r"});
  ASSERT_EQ(p.size(), 2u);
  expect_vec(p.positions[0], {3, 2, 1});
  EXPECT_EQ(p.colors[0], (Rgb8{30, 20, 10}));
  EXPECT_TRUE(has_comment(p, "columns: z y x skip b g r (from the columns option)"));

  // Fewer names than columns: the rest of each line is ignored.
  const PointSet q = read_text(dir, text, {.columns = "x y z"});
  EXPECT_FALSE(q.has_colors());
  expect_vec(q.positions[1], {4, 5, 6});

  // Normals named explicitly, blanks as separators in the option.
  const PointSet r = read_text(dir, "1 2 3 0 0 5\n", {.columns = "x y z nx ny nz"});
  ASSERT_TRUE(r.has_normals());
  expect_vec(r.normals[0], {0, 0, 1});
}

TEST(XyzReader, SkipColumnsMayHoldText) {
  TempDir dir;
  const PointSet p = read_text(dir, "1,ground,2,3\n4,roof,5,6\n", {.columns = "x,_,y,z"},
                               "labelled.csv");
  ASSERT_EQ(p.size(), 2u);
  expect_vec(p.positions[1], {4, 5, 6});
}

TEST(XyzReader, ReadColorsOffDropsColors) {
  TempDir dir;
  const PointSet p = read_text(dir, "1 2 3 10 20 30\n", {.read_colors = false});
  EXPECT_FALSE(p.has_colors());
  const PointSet q = read_text(dir, "x y z r g b\n1 2 3 10 20 30\n", {.read_colors = false});
  EXPECT_FALSE(q.has_colors());
  EXPECT_EQ(q.size(), 1u);
}

TEST(XyzReader, ShiftsLargeCoordinatesToAnOrigin) {
  TempDir dir;
  // UTM-like coordinates: x and y are shifted by the first point rounded down to 1000s.
  const PointSet p =
      read_text(dir, "512345.5 5403210.25 12.5\n512346.75 5403211.5 13\n-70000.5 0 0\n");
  ASSERT_EQ(p.size(), 3u);
  EXPECT_EQ(p.origin, (std::array<double, 3>{512000, 5403000, 0}));
  expect_vec(p.positions[0], {345.5f, 210.25f, 12.5f});
  expect_vec(p.positions[1], {346.75f, 211.5f, 13.0f});
  expect_vec(p.positions[2], {-582000.5f, -5403000.0f, 0.0f});
}

TEST(XyzReader, DoesNotShiftSmallCoordinates) {
  TempDir dir;
  const PointSet p = read_text(dir, "65535.5 -65535 1\n");
  EXPECT_EQ(p.origin, (std::array<double, 3>{}));
  expect_vec(p.positions[0], {65535.5f, -65535.0f, 1.0f});
}

TEST(XyzReader, ReadsGzip) {
  TempDir dir;
  const std::string path = dir.file("points.xyz.gz");
  write_file(path, pointillist::testing::gzip("1 2 3\n4 5 6\n"));
  const PointSet p = read_xyz(path);
  ASSERT_EQ(p.size(), 2u);
  expect_vec(p.positions[1], {4, 5, 6});
}

// A large file made of values exact in binary (multiples of 1/8 and integer colors).
std::string big_text(std::size_t count, std::vector<Vec3f>& positions, std::vector<Rgb8>& colors) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> coord(-80000, 80000), byte(0, 255);
  std::string text = "x y z r g b\n";
  char line[128];
  for (std::size_t i = 0; i < count; ++i) {
    const Vec3f v{coord(rng) / 8.0f, coord(rng) / 8.0f, coord(rng) / 8.0f};
    const Rgb8 c{static_cast<std::uint8_t>(byte(rng)), static_cast<std::uint8_t>(byte(rng)),
                 static_cast<std::uint8_t>(byte(rng))};
    positions.push_back(v);
    colors.push_back(c);
    std::snprintf(line, sizeof line, "%.3f\t%.3f %.3f %d %d %d\n", v.x, v.y, v.z, c.r, c.g, c.b);
    text += line;
    if (i % 1000 == 999) text += "# a comment between points\n";
  }
  return text;
}

TEST(XyzReader, ParallelPiecesGiveTheSamePoints) {
  TempDir dir;
  std::vector<Vec3f> positions;
  std::vector<Rgb8> colors;
  const std::string text = big_text(120000, positions, colors);  // about 4 MB: several pieces
  ASSERT_GT(text.size(), 3u << 20);
  const std::string path = dir.file("big.xyz");
  write_file(path, text);
  for (unsigned threads : {1u, 2u, 3u}) {
    ThreadPool pool(threads);
    const PointSet p = read_xyz(path, Progress::none(), {.pool = &pool});
    ASSERT_EQ(p.size(), positions.size()) << threads << " threads";
    ASSERT_TRUE(p.has_colors());
    for (std::size_t i = 0; i < positions.size(); ++i) {
      ASSERT_EQ(p.positions[i], positions[i]) << "point " << i << ", " << threads << " threads";
      ASSERT_EQ(p.colors[i], colors[i]) << "point " << i << ", " << threads << " threads";
    }
  }
}

// Errors -----------------------------------------------------------------------------------

std::string error_for(const TempDir& dir, const std::string& text, std::string* path_out,
                      const XyzReadOptions& options = {}) {
  const std::string path = dir.file("bad.xyz");
  write_file(path, text);
  if (path_out) *path_out = path;
  try {
    read_xyz(path, Progress::none(), options);
  } catch (const FormatError& e) {
    return e.what();
  } catch (const std::exception& e) {
    return std::string("wrong exception type: ") + e.what();
  }
  return "no exception";
}

void expect_error(const std::string& text, const std::string& place, const std::string& what,
                  const XyzReadOptions& options = {}) {
  TempDir dir;
  std::string path;
  const std::string message = error_for(dir, text, &path, options);
  EXPECT_CONTAINS(message, path + ": " + place + ": ");
  EXPECT_CONTAINS(message, what);
}

TEST(XyzReader, RejectsEmptyFile) { expect_error("", "line 1", "file is empty"); }

TEST(XyzReader, RejectsFileWithoutPoints) {
  expect_error("x y z\n# nothing\n\n", "line 3", "no point lines");
}

TEST(XyzReader, RejectsTooFewValuesOnFirstLine) {
  expect_error("# header\n1 2\n", "line 2",
               "a point line needs at least 3 values (x y z), found 2");
}

TEST(XyzReader, RejectsBadNumber) {
  expect_error("1 2 3\n4 five 6\n", "line 2", "column 2 (y): expected a number, found 'five'");
  expect_error("1 2 3\n4 5 6 7\n", "line 2", "extra value '7'");
  expect_error("1 2 3\n4 5 6x\n", "line 2", "column 3 (z): expected a number, found '6x'");
  expect_error("1 2 3 4 5 6\n1 2 3 4 5 abc\n", "line 2",
               "column 6: expected a number, found 'abc'");
}

TEST(XyzReader, RejectsShortLine) {
  expect_error("1 2 3\n\n4 5\n", "line 3",
               "line ends early: expected 3 values, found 2 (the first point line, line 1, has 3)");
  expect_error("x,y,z,r,g,b\n1,2,3,4,5,6\n1,2,3,4\n", "line 3", "line ends early");
}

TEST(XyzReader, RejectsNonFiniteCoordinates) {
  expect_error("1 2 3\n4 nan 6\n", "line 2", "column 2 (y) is not a finite number (found 'nan')");
  expect_error("1 2 3\n1e999 0 0\n", "line 2", "column 1 (x): expected a number");
}

TEST(XyzReader, RejectsEmptyCsvField) {
  expect_error("1,2,3\n4,,6\n", "line 2", "column 2 is empty");
}

TEST(XyzReader, RejectsMixedDelimiters) {
  expect_error("1,2,3\n4 5 6\n", "line 2", "expected ',' between values");
}

TEST(XyzReader, RejectsNonPointText) {
  std::string text;
  for (int i = 0; i < 1200; ++i) text += "lorem ipsum dolor\n";
  expect_error(text, "line 1001", "no point line in the first 1000 lines");
}

TEST(XyzReader, ReportsTheRightLineFromParallelPieces) {
  TempDir dir;
  std::vector<Vec3f> positions;
  std::vector<Rgb8> colors;
  std::string text = big_text(100000, positions, colors);
  // Break the line of point 90000: lines are the header, the points and one comment line per
  // 1000 points.
  const std::size_t line = 1 + 90000 + 90 + 1;
  std::size_t at = 0;
  for (std::size_t l = 1; l < line; ++l) at = text.find('\n', at) + 1;
  text.insert(at, "bad ");
  const std::string path = dir.file("big_bad.xyz");
  write_file(path, text);
  ThreadPool pool(3);
  try {
    read_xyz(path, Progress::none(), {.pool = &pool});
    FAIL() << "no exception";
  } catch (const FormatError& e) {
    EXPECT_CONTAINS(e.what(), path + ": line " + std::to_string(line) +
                                  ": column 1 (x): expected a number, found 'bad'");
  }
}

TEST(XyzReader, RejectsBadColumnsOption) {
  TempDir dir;
  const std::string path = dir.file("ok.xyz");
  write_file(path, "1 2 3\n");
  const auto message = [&](const std::string& columns) -> std::string {
    try {
      read_xyz(path, Progress::none(), {.columns = columns});
    } catch (const OptionError& e) {
      return e.what();
    } catch (const std::exception& e) {
      return std::string("wrong exception type: ") + e.what();
    }
    return "no exception";
  };
  EXPECT_CONTAINS(message("x,y,q"), "columns 'x,y,q': unknown column name 'q'");
  EXPECT_CONTAINS(message("x,y"), "x, y and z are all required");
  EXPECT_CONTAINS(message("x,y,z,x"), "column 'x' given twice");
  EXPECT_CONTAINS(message("x,y,z,nx,ny"), "normals (nx ny nz) need all three columns");
  EXPECT_CONTAINS(message("x,y,z,r"), "colors (r g b) need all three columns");
  // Naming more columns than a line has is a format error at that line.
  expect_error("1 2 3\n", "line 1", "line ends early: expected 4 or more values, found 3",
               {.columns = "x,y,z,skip"});
}

TEST(XyzReader, RejectsMissingFile) {
  TempDir dir;
  EXPECT_THROW(read_xyz(dir.file("missing.xyz")), IoError);
}

}  // namespace
}  // namespace pointillist

TEST(XyzReader, RejectsAStrayPointNoFloatCanHold) {
  // Found by fuzzing: the first point (y = 1e39) sets the origin; the second lies 1e39 from it,
  // beyond float's 3.4e38 (converting it was undefined behaviour).
  pointillist::expect_error("1 1e39 1\n1 1 1\n1 2 1\n", "line 2", "y = 1 is too far from the other points");
}
