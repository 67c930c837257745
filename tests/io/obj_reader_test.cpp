// OBJ reader: hand-written files; expected positions, triangles, normals and error lines are
// worked out here.
#include <gtest/gtest.h>

#include <cmath>

#include "io_test_support.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/io/obj.hpp"
#include "testing/testing.hpp"

namespace pointillist {
namespace {

using pointillist::testing::TempDir;
using pointillist::testing::write_file;
using Tri = std::array<std::uint32_t, 3>;

#define EXPECT_CONTAINS(text, part)                          \
  EXPECT_NE(std::string(text).find(part), std::string::npos) \
      << "message: " << (text) << "\nexpected it to contain: " << (part)

PointSet read_text(const TempDir& dir, const std::string& text, const ObjReadOptions& options = {}) {
  const std::string path = dir.file("mesh.obj");
  write_file(path, text);
  return read_obj(path, Progress::none(), options);
}

void expect_vec(Vec3f got, Vec3f want, float tolerance = 1e-6f) {
  EXPECT_NEAR(got.x, want.x, tolerance);
  EXPECT_NEAR(got.y, want.y, tolerance);
  EXPECT_NEAR(got.z, want.z, tolerance);
}

TEST(ObjReader, ReadsVerticesAndTriangles) {
  TempDir dir;
  const PointSet p = read_text(dir,
                               "# a triangle\n"
                               "v 0 0 0\n"
                               "v 1.5 0 -2\n"
                               "v 0 2.25 0 1.0\n"  // w is ignored
                               "f 1 2 3\n");
  ASSERT_EQ(p.size(), 3u);
  expect_vec(p.positions[1], {1.5f, 0, -2}, 0);
  expect_vec(p.positions[2], {0, 2.25f, 0}, 0);
  ASSERT_EQ(p.triangles.size(), 1u);
  EXPECT_EQ(p.triangles[0], (Tri{0, 1, 2}));
  EXPECT_FALSE(p.has_normals());
  EXPECT_FALSE(p.has_colors());
}

TEST(ObjReader, FanTriangulatesPolygons) {
  TempDir dir;
  const PointSet p = read_text(dir,
                               "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 1.5 0\n"
                               "f 1 2 3 5 4\n"
                               "f 1 2\n");  // fewer than 3 corners: skipped
  ASSERT_EQ(p.triangles.size(), 3u);
  EXPECT_EQ(p.triangles[0], (Tri{0, 1, 2}));
  EXPECT_EQ(p.triangles[1], (Tri{0, 2, 4}));
  EXPECT_EQ(p.triangles[2], (Tri{0, 4, 3}));
}

TEST(ObjReader, ReadsEveryCornerSpelling) {
  TempDir dir;
  const PointSet p = read_text(dir,
                               "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n"
                               "vt 0 0\nvt 1 0\nvt 0 1\n"
                               "vn 0 0 1\n"
                               "f 1 2/1 3//1\n"
                               "f 2/2/1 4/3/1 3/1/1\n");
  ASSERT_EQ(p.triangles.size(), 2u);
  EXPECT_EQ(p.triangles[0], (Tri{0, 1, 2}));
  EXPECT_EQ(p.triangles[1], (Tri{1, 3, 2}));
}

TEST(ObjReader, ResolvesNegativeIndices) {
  TempDir dir;
  const PointSet p = read_text(dir,
                               "v 0 0 0\nv 1 0 0\nv 0 1 0\n"
                               "f -3 -2 -1\n"
                               "v 1 1 0\n"
                               "f -3 -1 -2\n");  // counts back from vertex 4
  ASSERT_EQ(p.triangles.size(), 2u);
  EXPECT_EQ(p.triangles[0], (Tri{0, 1, 2}));
  EXPECT_EQ(p.triangles[1], (Tri{1, 3, 2}));
}

TEST(ObjReader, AcceptsFacesBeforeTheirVertices) {
  TempDir dir;
  const PointSet p = read_text(dir, "f 1//1 2//1 3//1\nvn 0 0 -1\nv 0 0 0\nv 1 0 0\nv 0 1 0\n");
  ASSERT_EQ(p.triangles.size(), 1u);
  EXPECT_EQ(p.triangles[0], (Tri{0, 1, 2}));
  ASSERT_TRUE(p.has_normals());
  for (const Vec3f n : p.normals) expect_vec(n, {0, 0, -1});
}

TEST(ObjReader, AssignsConsistentNormalsFromCorners) {
  TempDir dir;
  const PointSet p = read_text(dir,
                               "v 0 0 0\nv 1 0 0\nv 0 1 0\n"
                               "vn 0 0 2\nvn 0 3 0\nvn 4 0 0\n"  // normalized on reading
                               "f 1//3 2//2 3//1\n");
  ASSERT_TRUE(p.has_normals());
  expect_vec(p.normals[0], {1, 0, 0});
  expect_vec(p.normals[1], {0, 1, 0});
  expect_vec(p.normals[2], {0, 0, 1});
}

TEST(ObjReader, AveragesDifferingNormalsOfAVertex) {
  TempDir dir;
  // Vertex 1 is a corner of both faces, once with +X and once with +Y: it gets their average.
  const PointSet p = read_text(dir,
                               "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
                               "vn 1 0 0\nvn 0 1 0\n"
                               "f 1//1 2//1 3//1\n"
                               "f 1//2 3//2 4//2\n");
  ASSERT_TRUE(p.has_normals());
  const float h = std::sqrt(0.5f);
  expect_vec(p.normals[0], {h, h, 0});
  expect_vec(p.normals[1], {1, 0, 0});
  expect_vec(p.normals[2], {h, h, 0});
  expect_vec(p.normals[3], {0, 1, 0});
}

TEST(ObjReader, VerticesWithoutNormalReferenceTakeTheirFaceNormal) {
  TempDir dir;
  // Face 2 has no vn: its own vertex 4 takes the face's normal (counter-clockwise in the
  // z = 0 plane: +Z); vertex 5 is on no face at all: (0, 0, 1) as well, by convention.
  const PointSet p = read_text(dir,
                               "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 5 5 5\n"
                               "vn 0 -1 0\n"
                               "f 1//1 2//1 3//1\n"
                               "f 2 4 3\n");
  ASSERT_TRUE(p.has_normals());
  expect_vec(p.normals[0], {0, -1, 0});
  expect_vec(p.normals[3], {0, 0, 1});
  expect_vec(p.normals[4], {0, 0, 1});

  // Clockwise: -Z.
  const PointSet q = read_text(dir,
                               "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n"
                               "vn 0 -1 0\n"
                               "f 1//1 2//1 3//1\n"
                               "f 2 3 4\n");
  expect_vec(q.normals[3], {0, 0, -1});
}

TEST(ObjReader, ReadsVertexColors) {
  TempDir dir;
  const PointSet p = read_text(dir, "v 0 0 0 1 0 0.5\nv 1 0 0 0.2 0.4 1.0\n");
  ASSERT_TRUE(p.has_colors());
  EXPECT_EQ(p.colors[0], (Rgb8{255, 0, 128}));
  EXPECT_EQ(p.colors[1], (Rgb8{51, 102, 255}));

  const PointSet bytes = read_text(dir, "v 0 0 0 255 0 128\n");
  ASSERT_TRUE(bytes.has_colors());
  EXPECT_EQ(bytes.colors[0], (Rgb8{255, 0, 128}));

  const PointSet off = read_text(dir, "v 0 0 0 1 0 0.5\n", {.read_colors = false});
  EXPECT_FALSE(off.has_colors());
}

TEST(ObjReader, DropsColorsUnlessEveryVertexHasOne) {
  TempDir dir;
  const PointSet p = read_text(dir, "v 0 0 0\nv 1 0 0 1 0 0\nv 2 0 0\n");
  EXPECT_FALSE(p.has_colors());
  ASSERT_EQ(p.comments.size(), 1u);
  EXPECT_EQ(p.comments[0], "vertex colors ignored: only 1 of 3 vertices have them");
}

TEST(ObjReader, IgnoresOtherStatements) {
  TempDir dir;
  const PointSet p = read_text(dir,
                               "mtllib scene.mtl\r\n"
                               "o cube\r\n"
                               "g side\r\n"
                               "v 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\n"
                               "vt 0.5 0.5\r\n"
                               "vp 0.1 0.2\r\n"
                               "usemtl red\r\n"
                               "s off\r\n"
                               "l 1 2\r\n"
                               "p 3\r\n"
                               "  # indented comment\r\n"
                               "\r\n"
                               "f 1 2 3\r\n");
  EXPECT_EQ(p.size(), 3u);
  ASSERT_EQ(p.triangles.size(), 1u);
}

TEST(ObjReader, ShiftsLargeCoordinates) {
  TempDir dir;
  const PointSet p = read_text(dir, "v 700123.5 100 4000000.25\nv 700124 101 4000001\n");
  EXPECT_EQ(p.origin, (std::array<double, 3>{700000, 0, 4000000}));
  expect_vec(p.positions[0], {123.5f, 100, 0.25f}, 0);
  expect_vec(p.positions[1], {124, 101, 1}, 0);
}

TEST(ObjReader, ReadsGzip) {
  TempDir dir;
  const std::string path = dir.file("mesh.obj.gz");
  write_file(path, pointillist::testing::gzip("v 1 2 3\n"));
  EXPECT_EQ(read_obj(path).size(), 1u);
}

// Errors -----------------------------------------------------------------------------------

void expect_error(const std::string& text, const std::string& place, const std::string& what) {
  TempDir dir;
  const std::string path = dir.file("bad.obj");
  write_file(path, text);
  std::string message = "no exception";
  try {
    read_obj(path);
  } catch (const FormatError& e) {
    message = e.what();
  } catch (const std::exception& e) {
    message = std::string("wrong exception type: ") + e.what();
  }
  EXPECT_CONTAINS(message, path + ": " + place + ": ");
  EXPECT_CONTAINS(message, what);
}

const std::string kTriangle = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";  // lines 1 to 3

TEST(ObjReader, RejectsBadNumbers) {
  expect_error("v 0 0 0\nv 1 x 0\n", "line 2", "v: value 2: expected a number, found 'x'");
  expect_error("v 0 0 nan\n", "line 1", "v: coordinate 3 is not a finite number");
  expect_error(kTriangle + "vn 0 0\n", "line 4",
               "vn: value 3: expected a number, found end of line");
  expect_error(kTriangle + "vn 0 0 1 1\n", "line 4", "vn: extra value '1'");
}

TEST(ObjReader, RejectsWrongVertexValueCounts) {
  expect_error("v 1 2\n", "line 1", "v: expected 3, 4 or 6 numbers");
  expect_error("v 1 2 3 4 5\n", "line 1", "found 5");
  expect_error("v 1 2 3 4 5 6 7 8 9\n", "line 1", "found 8 or more");
}

TEST(ObjReader, RejectsBadCorners) {
  expect_error(kTriangle + "f 1 2 x\n", "line 4",
               "f: corner 3: expected v, v/vt, v//vn or v/vt/vn with integer indices, found 'x'");
  expect_error(kTriangle + "f 1 2 3/a\n", "line 4", "found '3/a'");
  expect_error(kTriangle + "f 1 2 3.0\n", "line 4", "found '3.0'");
}

TEST(ObjReader, RejectsIndexZero) {
  expect_error(kTriangle + "\nf 1 2 0\n", "line 5", "f: vertex index 0 (OBJ indices start at 1");
}

TEST(ObjReader, RejectsIndicesOutOfRange) {
  expect_error(kTriangle + "f 1 2 4\n", "line 4",
               "f: vertex index 4 out of range (the file has 3 vertices)");
  expect_error(kTriangle + "f 1 2 -4\n", "line 4",
               "f: relative vertex index -4 points before the first vertex (3 defined so far)");
  expect_error(kTriangle + "vn 0 0 1\nf 1//1 2//1 3//2\n", "line 5",
               "f: normal index 2 out of range (the file has 1 vn lines)");
  expect_error(kTriangle + "f 1//-1 2 3\n", "line 4", "relative normal index -1 points before");
  // Of several bad forward references, the largest is reported.
  expect_error("f 1 2 9\nf 1 2 12\n" + kTriangle, "line 2", "vertex index 12 out of range");
}

TEST(ObjReader, RejectsFilesWithoutVertices) {
  expect_error("# nothing\ng empty\n", "line 3", "no vertices");
  expect_error("", "line 1", "no vertices");
}

}  // namespace
}  // namespace pointillist

TEST(ObjReader, RejectsAStrayVertexNoFloatCanHold) {
  // Found by fuzzing: the first vertex (y = 1e39) sets the origin; the second lies 1e39 from it.
  pointillist::expect_error("v 1 1e39 1\nv 1 1 1\n", "line 2",
               "v: coordinate 2 is too far from the other vertices for a float");
}
