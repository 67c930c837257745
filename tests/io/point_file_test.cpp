// read_point_file: the reader follows the extension. Each file is tiny and hand-written; the
// point it holds says which reader produced it.
#include <gtest/gtest.h>

#include "io_test_support.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/core/thread_pool.hpp"
#include "pointillist/io/point_file.hpp"
#include "testing/testing.hpp"

namespace pointillist {
namespace {

using pointillist::testing::put;
using pointillist::testing::TempDir;
using pointillist::testing::write_file;

#define EXPECT_CONTAINS(text, part)                          \
  EXPECT_NE(std::string(text).find(part), std::string::npos) \
      << "message: " << (text) << "\nexpected it to contain: " << (part)

// A LAS 1.2 file, point format 2, holding the single point (X, Y, Z) * 0.5 with color (R, G, B).
std::string tiny_las(std::int32_t x, std::int32_t y, std::int32_t z, std::uint16_t rgb) {
  std::string h = "LASF";
  h.append(20, '\0');  // file source ID, global encoding, GUID
  put(h, std::uint8_t{1});
  put(h, std::uint8_t{2});
  h.append(68, '\0');  // system, software, day, year
  put(h, std::uint16_t{227});
  put(h, std::uint32_t{227});
  put(h, std::uint32_t{0});
  put(h, std::uint8_t{2});
  put(h, std::uint16_t{26});
  put(h, std::uint32_t{1});
  h.append(20, '\0');
  for (int i = 0; i < 3; ++i) put(h, 0.5);
  h.append(9 * 8, '\0');  // offsets, bounds
  put(h, x);
  put(h, y);
  put(h, z);
  h.append(8, '\0');
  for (int i = 0; i < 3; ++i) put(h, rgb);
  return h;
}

const std::string kPly =
    "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
    "property float z\nend_header\n1 2 3\n";

struct Case {
  std::string name;
  std::string bytes;
  Vec3f expected;
};

TEST(PointFile, DispatchesByExtension) {
  const std::vector<Case> cases = {
      {"a.ply", kPly, {1, 2, 3}},
      {"a.ply.gz", pointillist::testing::gzip(kPly), {1, 2, 3}},
      {"b.xyz", "4 5 6\n", {4, 5, 6}},
      {"b.pts", "1\n4 5 7 0 1 2 3\n", {4, 5, 7}},
      {"b.csv", "x,y,z\n4,5,8\n", {4, 5, 8}},
      {"b.txt", "4;5;9\n", {4, 5, 9}},
      {"b.xyz.gz", pointillist::testing::gzip("4 5 10\n"), {4, 5, 10}},
      {"c.obj", "v 7 8 9\n", {7, 8, 9}},
      {"d.las", tiny_las(2, 4, 6, 255), {1, 2, 3}},
      {"UPPER.LAS", tiny_las(2, 4, 8, 255), {1, 2, 4}},
      {"Mixed.Xyz", "1 1 1\n", {1, 1, 1}},
  };
  TempDir dir;
  ThreadPool pool(2);
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string path = dir.file(c.name);
    write_file(path, c.bytes);
    EXPECT_TRUE(is_point_file_extension(path));
    const PointSet p = read_point_file(path, Progress::none(), {.pool = &pool});
    ASSERT_EQ(p.size(), 1u);
    EXPECT_EQ(p.positions[0], c.expected);
  }
}

TEST(PointFile, PassesOptionsThrough) {
  TempDir dir;
  const std::string xyz = dir.file("c.xyz");
  write_file(xyz, "1 2 3 40 50 60\n");
  const PointSet swapped = read_point_file(xyz, Progress::none(), {.columns = "z,y,x,b,g,r"});
  EXPECT_EQ(swapped.positions[0], (Vec3f{3, 2, 1}));
  EXPECT_EQ(swapped.colors[0], (Rgb8{60, 50, 40}));
  EXPECT_FALSE(read_point_file(xyz, Progress::none(), {.read_colors = false}).has_colors());

  const std::string las = dir.file("c.las");
  write_file(las, tiny_las(0, 0, 0, 200));
  EXPECT_TRUE(read_point_file(las).has_colors());
  EXPECT_FALSE(read_point_file(las, Progress::none(), {.read_colors = false}).has_colors());

  const std::string obj = dir.file("c.obj");
  write_file(obj, "v 0 0 0 1 0 0\n");
  EXPECT_TRUE(read_point_file(obj).has_colors());
  EXPECT_FALSE(read_point_file(obj, Progress::none(), {.read_colors = false}).has_colors());
}

std::string error_of(const std::string& path) {
  try {
    read_point_file(path);
  } catch (const FormatError& e) {
    return e.what();
  } catch (const std::exception& e) {
    return std::string("wrong exception type: ") + e.what();
  }
  return "no exception";
}

TEST(PointFile, RefusesLazWithAdvice) {
  TempDir dir;
  const std::string path = dir.file("tile.laz");
  write_file(path, "LASF");
  const std::string message = error_of(path);
  EXPECT_CONTAINS(message, path + ": compressed LAS (LAZ) is not supported yet");
  EXPECT_CONTAINS(message, "decompress it with laszip or pdal first");
  EXPECT_FALSE(is_point_file_extension(path));
}

TEST(PointFile, RejectsUnknownExtensionsListingTheSupportedOnes) {
  TempDir dir;
  for (const std::string name : {"model.stl", "model", "ply", "scan.ply.zip", "points.gz"}) {
    const std::string path = dir.file(name);
    write_file(path, "1 2 3\n");
    const std::string message = error_of(path);
    EXPECT_CONTAINS(message, path + ": unknown point file type");
    EXPECT_CONTAINS(message, ".ply, .ply.gz, .xyz, .pts, .csv, .txt");
    EXPECT_CONTAINS(message, ".obj");
    EXPECT_CONTAINS(message, ".las");
    EXPECT_FALSE(is_point_file_extension(path)) << name;
  }
}

TEST(PointFile, ExtensionIsTakenFromTheFileNameOnly) {
  EXPECT_FALSE(is_point_file_extension("scans.ply/readme"));
  EXPECT_TRUE(is_point_file_extension("scans.d/scan.PLY"));
  EXPECT_FALSE(is_point_file_extension(".ply"));  // a hidden file without a name part
  EXPECT_TRUE(is_point_file_extension("x.obj.gz"));
  EXPECT_TRUE(is_point_file_extension("x.las.gz"));
  EXPECT_FALSE(is_point_file_extension("x.laz"));
}

TEST(PointFile, ReadsTheOriginComment) {
  PointSet p;
  EXPECT_FALSE(point_set_origin(p).has_value());
  p.comments = {"columns: x y z", "origin: 512000 5403000.5 -12"};
  const auto origin = point_set_origin(p);
  ASSERT_TRUE(origin.has_value());
  EXPECT_EQ((*origin)[0], 512000.0);
  EXPECT_EQ((*origin)[1], 5403000.5);
  EXPECT_EQ((*origin)[2], -12.0);

  // Written by a reader: the same numbers come back.
  TempDir dir;
  const std::string path = dir.file("far.xyz");
  write_file(path, "700123.5 100 4000000.25\n");
  const auto read = point_set_origin(read_point_file(path));
  ASSERT_TRUE(read.has_value());
  EXPECT_EQ((*read)[0], 700000.0);
  EXPECT_EQ((*read)[1], 0.0);
  EXPECT_EQ((*read)[2], 4000000.0);
}

}  // namespace
}  // namespace pointillist
