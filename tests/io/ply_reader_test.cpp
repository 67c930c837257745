// PLY reader on valid input. Every file is written by hand here (text or packed bytes), so the
// expected values come from the test, not from our writer.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>

#include "io_test_support.hpp"
#include "pointillist/io/ply.hpp"
#include "testing/testing.hpp"

namespace pointillist {
namespace {

using testing::put;
using testing::TempDir;
using testing::write_file;

struct Spelling {
  const char* name;
  bool is_signed;
  bool is_float;
  int size;
};

constexpr Spelling kSpellings[] = {
    {"char", true, false, 1},    {"uchar", false, false, 1},  {"short", true, false, 2},
    {"ushort", false, false, 2}, {"int", true, false, 4},     {"uint", false, false, 4},
    {"float", true, true, 4},    {"double", true, true, 8},   {"int8", true, false, 1},
    {"uint8", false, false, 1},  {"int16", true, false, 2},   {"uint16", false, false, 2},
    {"int32", true, false, 4},   {"uint32", false, false, 4}, {"float32", true, true, 4},
    {"float64", true, true, 8}};

enum class Enc { Ascii, Little, Big };
constexpr Enc kEncodings[] = {Enc::Ascii, Enc::Little, Enc::Big};

const char* format_line(Enc enc) {
  return enc == Enc::Ascii    ? "format ascii 1.0\n"
         : enc == Enc::Little ? "format binary_little_endian 1.0\n"
                              : "format binary_big_endian 1.0\n";
}

// Appends `v` as a value of the spelled type: text (plus a space) or packed bytes.
void put_value(std::string& out, const Spelling& s, double v, Enc enc) {
  if (enc == Enc::Ascii) {
    char text[64];
    if (s.is_float)
      std::snprintf(text, sizeof text, "%.9g ", v);
    else
      std::snprintf(text, sizeof text, "%lld ", static_cast<long long>(v));
    out += text;
    return;
  }
  const bool big = enc == Enc::Big;
  if (s.is_float) {
    if (s.size == 4)
      put(out, static_cast<float>(v), big);
    else
      put(out, v, big);
  } else if (s.is_signed) {
    if (s.size == 1)
      put(out, static_cast<std::int8_t>(v), big);
    else if (s.size == 2)
      put(out, static_cast<std::int16_t>(v), big);
    else
      put(out, static_cast<std::int32_t>(v), big);
  } else {
    if (s.size == 1)
      put(out, static_cast<std::uint8_t>(v), big);
    else if (s.size == 2)
      put(out, static_cast<std::uint16_t>(v), big);
    else
      put(out, static_cast<std::uint32_t>(v), big);
  }
}

void end_line(std::string& out, Enc enc) {
  if (enc == Enc::Ascii) out += "\n";
}

PointSet read_text(const TempDir& dir, const std::string& text,
                   const PlyReadOptions& options = {}) {
  const std::string path = dir.file("input.ply");
  write_file(path, text);
  return read_ply(path, Progress::none(), options);
}

TEST(PlyReader, ReadsAsciiPositionsAndFaces) {
  TempDir dir;
  const PointSet points = read_text(dir,
                                    "ply\n"
                                    "format ascii 1.0\n"
                                    "element vertex 3\n"
                                    "property float x\nproperty float y\nproperty float z\n"
                                    "element face 1\n"
                                    "property list uchar int vertex_indices\n"
                                    "end_header\n"
                                    "0 0 0\n"
                                    "1.5 -2.25 3e2\n"
                                    "0.1 0.2 0.3\n"
                                    "3 2 1 0\n");
  ASSERT_EQ(points.size(), 3u);
  EXPECT_EQ(points.positions[1], (Vec3f{1.5f, -2.25f, 300.0f}));
  EXPECT_EQ(points.positions[2], (Vec3f{0.1f, 0.2f, 0.3f}));
  ASSERT_EQ(points.triangles.size(), 1u);
  EXPECT_EQ(points.triangles[0], (std::array<std::uint32_t, 3>{2, 1, 0}));
  EXPECT_FALSE(points.has_normals());
  EXPECT_FALSE(points.has_colors());
  EXPECT_FALSE(points.has_radii());
}

// Every type under both spellings, in every encoding, for positions and a skipped property.
TEST(PlyReader, ReadsEveryScalarTypeInEveryEncoding) {
  TempDir dir;
  for (Enc enc : kEncodings) {
    for (const Spelling& s : kSpellings) {
      SCOPED_TRACE(std::string(s.name) + " " + format_line(enc));
      std::string file = std::string("ply\n") + format_line(enc) + "element vertex 2\n";
      for (const char* name : {"x", "skipped", "y", "z"})
        file += std::string("property ") + s.name + " " + name + "\n";
      file += "end_header\n";
      const double second_x = s.is_float ? -1.5 : (s.is_signed ? -100 : 200);
      const double rows[2][4] = {{1, 9, 2, 3}, {second_x, 7, 100, 120}};
      for (const auto& row : rows) {
        for (double v : row) put_value(file, s, v, enc);
        end_line(file, enc);
      }
      const PointSet points = read_text(dir, file);
      ASSERT_EQ(points.size(), 2u);
      EXPECT_EQ(points.positions[0], (Vec3f{1, 2, 3}));
      EXPECT_EQ(points.positions[1], (Vec3f{static_cast<float>(second_x), 100, 120}));
    }
  }
}

// Every integer count type with every integer index type, in every encoding.
TEST(PlyReader, ReadsListsWithAnyCountAndIndexType) {
  TempDir dir;
  for (Enc enc : kEncodings) {
    for (const Spelling& count : kSpellings) {
      if (count.is_float) continue;
      for (const Spelling& index : kSpellings) {
        if (index.is_float) continue;
        SCOPED_TRACE(std::string(count.name) + " " + index.name + " " + format_line(enc));
        std::string file =
            std::string("ply\n") + format_line(enc) +
            "element vertex 5\nproperty uchar x\nproperty uchar y\nproperty uchar z\n"
            "element face 2\nproperty list " +
            count.name + " " + index.name + " vertex_indices\nproperty list " + count.name +
            " float texcoord\n"
            "end_header\n";
        const Spelling uchar = kSpellings[1];
        const Spelling float32 = kSpellings[6];
        for (int v = 0; v < 5; ++v) {
          for (int k = 0; k < 3; ++k) put_value(file, uchar, v * 10 + k, enc);
          end_line(file, enc);
        }
        put_value(file, count, 4, enc);  // a quad
        for (int i : {0, 1, 2, 3}) put_value(file, index, i, enc);
        put_value(file, count, 2, enc);
        for (double t : {0.25, 0.75}) put_value(file, float32, t, enc);
        end_line(file, enc);
        put_value(file, count, 3, enc);
        for (int i : {4, 3, 2}) put_value(file, index, i, enc);
        put_value(file, count, 0, enc);
        end_line(file, enc);

        const PointSet points = read_text(dir, file);
        ASSERT_EQ(points.size(), 5u);
        EXPECT_EQ(points.positions[4], (Vec3f{40, 41, 42}));
        ASSERT_EQ(points.triangles.size(), 3u);
        EXPECT_EQ(points.triangles[0], (std::array<std::uint32_t, 3>{0, 1, 2}));
        EXPECT_EQ(points.triangles[1], (std::array<std::uint32_t, 3>{0, 2, 3}));
        EXPECT_EQ(points.triangles[2], (std::array<std::uint32_t, 3>{4, 3, 2}));
      }
    }
  }
}

// Faces with only an index list take the binary fast path.
TEST(PlyReader, FanTriangulatesBinaryPolygons) {
  TempDir dir;
  for (Enc enc : {Enc::Little, Enc::Big}) {
    for (const char* types :
         {"uchar int", "uchar uint", "ushort int", "int uint", "uchar ushort"}) {
      SCOPED_TRACE(std::string(types) + format_line(enc));
      std::string file = std::string("ply\n") + format_line(enc) +
                         "element vertex 6\nproperty float x\nproperty float y\nproperty float z\n"
                         "element face 4\nproperty list " +
                         types + " vertex_indices\nend_header\n";
      const std::string count_type(types, std::strchr(types, ' '));
      const std::string index_type(std::strchr(types, ' ') + 1);
      const auto spelling = [](const std::string& name) {
        for (const Spelling& s : kSpellings)
          if (name == s.name) return s;
        return kSpellings[0];
      };
      for (int i = 0; i < 18; ++i) put_value(file, kSpellings[6], i, enc);
      for (const std::vector<int>& face :
           std::vector<std::vector<int>>{{0, 1, 2, 3, 4}, {5, 4}, {}, {5, 4, 3, 2}}) {
        put_value(file, spelling(count_type), static_cast<double>(face.size()), enc);
        for (int i : face) put_value(file, spelling(index_type), i, enc);
      }
      const PointSet points = read_text(dir, file);
      const std::vector<std::array<std::uint32_t, 3>> expected = {
          {0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {5, 4, 3}, {5, 3, 2}};
      EXPECT_EQ(points.triangles, expected);
    }
  }
}

TEST(PlyReader, FanTriangulatesPolygonsAndSkipsDegenerateOnes) {
  TempDir dir;
  const PointSet points = read_text(dir,
                                    "ply\nformat ascii 1.0\nelement vertex 6\n"
                                    "property float x\nproperty float y\nproperty float z\n"
                                    "element face 4\nproperty list uchar uint vertex_index\n"
                                    "end_header\n"
                                    "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 2 0\n5 5 5\n"
                                    "5 0 1 2 3 4\n"
                                    "2 0 1\n"
                                    "0\n"
                                    "3 5 4 3\n");
  const std::vector<std::array<std::uint32_t, 3>> expected = {
      {0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {5, 4, 3}};
  EXPECT_EQ(points.triangles, expected);
}

TEST(PlyReader, KeepsCommentsAndIgnoresObjInfo) {
  TempDir dir;
  const PointSet points = read_text(dir,
                                    "ply\nformat ascii 1.0\n"
                                    "comment made by hand\n"
                                    "obj_info scanner 7\n"
                                    "element vertex 1\n"
                                    "comment between  elements \n"
                                    "property float x\nproperty float y\nproperty float z\n"
                                    "comment\n"
                                    "end_header\n1 2 3\n");
  const std::vector<std::string> expected = {"made by hand", "between  elements", ""};
  EXPECT_EQ(points.comments, expected);
}

TEST(PlyReader, ReadsElementsInAnyOrderAndSkipsUnknownOnes) {
  TempDir dir;
  for (Enc enc : kEncodings) {
    SCOPED_TRACE(format_line(enc));
    std::string file =
        std::string("ply\n") + format_line(enc) +
        "element material 2\nproperty uchar shininess\nproperty list uchar float rgb\n"
        "element face 1\nproperty uchar flags\nproperty list uint short vertex_indices\n"
        "property float quality\n"
        "element edge 1\nproperty int vertex1\nproperty int vertex2\n"
        "element vertex 3\nproperty double x\nproperty double y\nproperty double z\n"
        "element empty 0\nproperty list uchar int things\n"
        "end_header\n";
    const Spelling uchar = kSpellings[1], float32 = kSpellings[6], uint32 = kSpellings[5];
    const Spelling int16 = kSpellings[2], int32 = kSpellings[4], float64 = kSpellings[7];
    // material: shininess, rgb list of 3 / of 1
    put_value(file, uchar, 7, enc);
    put_value(file, uchar, 3, enc);
    for (double v : {0.1, 0.2, 0.3}) put_value(file, float32, v, enc);
    end_line(file, enc);
    put_value(file, uchar, 8, enc);
    put_value(file, uchar, 1, enc);
    put_value(file, float32, 0.5, enc);
    end_line(file, enc);
    // face
    put_value(file, uchar, 1, enc);
    put_value(file, uint32, 3, enc);
    for (int i : {1, 2, 0}) put_value(file, int16, i, enc);
    put_value(file, float32, 0.9, enc);
    end_line(file, enc);
    // edge
    put_value(file, int32, 0, enc);
    put_value(file, int32, 1, enc);
    end_line(file, enc);
    // vertex
    const double xyz[3][3] = {{0.5, 1, 2}, {-3, 4.25, 5}, {6, 7, 8.125}};
    for (const auto& row : xyz) {
      for (double v : row) put_value(file, float64, v, enc);
      end_line(file, enc);
    }
    const PointSet points = read_text(dir, file);
    ASSERT_EQ(points.size(), 3u);
    EXPECT_EQ(points.positions[0], (Vec3f{0.5f, 1, 2}));
    EXPECT_EQ(points.positions[1], (Vec3f{-3, 4.25f, 5}));
    EXPECT_EQ(points.positions[2], (Vec3f{6, 7, 8.125f}));
    ASSERT_EQ(points.triangles.size(), 1u);
    EXPECT_EQ(points.triangles[0], (std::array<std::uint32_t, 3>{1, 2, 0}));
  }
}

// An element without properties occupies no line and no byte.
TEST(PlyReader, AcceptsElementsWithoutProperties) {
  TempDir dir;
  for (Enc enc : kEncodings) {
    SCOPED_TRACE(format_line(enc));
    std::string file = std::string("ply\n") + format_line(enc) +
                       "element nothing 5\nelement vertex 1\nproperty float x\nproperty float y\n"
                       "property float z\nelement void 1000000000000\nend_header\n";
    for (double v : {1.0, 2.0, 3.0}) put_value(file, kSpellings[6], v, enc);
    end_line(file, enc);
    EXPECT_EQ(read_text(dir, file).positions, (std::vector<Vec3f>{{1, 2, 3}}));
  }
}

TEST(PlyReader, ReadsUcharColorsAndIgnoresAlpha) {
  TempDir dir;
  const PointSet points =
      read_text(dir,
                "ply\nformat ascii 1.0\nelement vertex 2\n"
                "property float x\nproperty float y\nproperty float z\n"
                "property uchar red\nproperty uchar green\nproperty uchar blue\n"
                "property uchar alpha\nend_header\n"
                "0 0 0 255 128 0 7\n"
                "1 1 1 1 2 3 255\n");
  ASSERT_TRUE(points.has_colors());
  EXPECT_EQ(points.colors[0], (Rgb8{255, 128, 0}));
  EXPECT_EQ(points.colors[1], (Rgb8{1, 2, 3}));
}

TEST(PlyReader, ReadsFloatColorsAsZeroToOne) {
  TempDir dir;
  const PointSet points =
      read_text(dir,
                "ply\nformat ascii 1.0\nelement vertex 2\n"
                "property float x\nproperty float y\nproperty float z\n"
                "property float red\nproperty float green\nproperty double blue\n"
                "end_header\n"
                "0 0 0 1 0.5 0\n"
                "1 1 1 2 -1 0.1\n");
  ASSERT_TRUE(points.has_colors());
  // 0.5 * 255 = 127.5 rounds up; out-of-range values clamp; 0.1 * 255 = 25.5 rounds to 26.
  EXPECT_EQ(points.colors[0], (Rgb8{255, 128, 0}));
  EXPECT_EQ(points.colors[1], (Rgb8{255, 0, 26}));
}

TEST(PlyReader, ReadsDiffuseColorsAndWideIntegerColors) {
  TempDir dir;
  std::string file =
      "ply\nformat binary_big_endian 1.0\nelement vertex 2\n"
      "property float x\nproperty float y\nproperty float z\n"
      "property ushort diffuse_red\nproperty int diffuse_green\nproperty char diffuse_blue\n"
      "end_header\n";
  for (int v = 0; v < 2; ++v) {
    for (int k = 0; k < 3; ++k) put(file, static_cast<float>(v + k), true);
    put(file, static_cast<std::uint16_t>(v == 0 ? 65535 : 257 * 9), true);  // 0..65535 scale
    put(file, static_cast<std::int32_t>(v == 0 ? 1000 : 77), true);         // clamped to 255
    put(file, static_cast<std::int8_t>(v == 0 ? -5 : 100), true);           // clamped to 0
  }
  const PointSet points = read_text(dir, file);
  ASSERT_TRUE(points.has_colors());
  EXPECT_EQ(points.colors[0], (Rgb8{255, 255, 0}));
  EXPECT_EQ(points.colors[1], (Rgb8{9, 77, 100}));
}

TEST(PlyReader, IgnoresColorsWhenAskedOrIncomplete) {
  TempDir dir;
  const std::string file =
      "ply\nformat ascii 1.0\nelement vertex 1\n"
      "property float x\nproperty float y\nproperty float z\n"
      "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n"
      "0 0 0 1 2 3\n";
  EXPECT_FALSE(read_text(dir, file, {.read_colors = false}).has_colors());
  EXPECT_FALSE(read_text(dir,
                         "ply\nformat ascii 1.0\nelement vertex 1\n"
                         "property float x\nproperty float y\nproperty float z\n"
                         "property uchar red\nproperty uchar green\nend_header\n"
                         "0 0 0 1 2\n")
                   .has_colors());
}

TEST(PlyReader, ReadsRadiusOrScale) {
  TempDir dir;
  for (const char* name : {"radius", "scale"}) {
    SCOPED_TRACE(name);
    const PointSet points =
        read_text(dir, std::string("ply\nformat ascii 1.0\nelement vertex 2\n"
                                   "property float x\nproperty float y\nproperty float z\n"
                                   "property float ") +
                           name + "\nend_header\n0 0 0 0.25\n1 1 1 2\n");
    ASSERT_TRUE(points.has_radii());
    EXPECT_EQ(points.radii, (std::vector<float>{0.25f, 2.0f}));
  }
}

TEST(PlyReader, NormalizesNormals) {
  TempDir dir;
  const PointSet points =
      read_text(dir,
                "ply\nformat ascii 1.0\nelement vertex 3\n"
                "property float x\nproperty float y\nproperty float z\n"
                "property float nx\nproperty float ny\nproperty float nz\nend_header\n"
                "0 0 0 3 0 4\n"
                "1 1 1 0 -2 0\n"
                "2 2 2 0 0 0\n");
  ASSERT_TRUE(points.has_normals());
  EXPECT_NEAR(points.normals[0].x, 0.6f, 1e-6f);
  EXPECT_NEAR(points.normals[0].z, 0.8f, 1e-6f);
  EXPECT_EQ(points.normals[1], (Vec3f{0, -1, 0}));
  EXPECT_EQ(points.normals[2], (Vec3f{0, 0, 1}));  // documented fallback for a zero normal
}

TEST(PlyReader, DropsNormalsThatAreAllZero) {
  TempDir dir;
  const PointSet points =
      read_text(dir,
                "ply\nformat ascii 1.0\nelement vertex 2\n"
                "property float x\nproperty float y\nproperty float z\n"
                "property float nx\nproperty float ny\nproperty float nz\nend_header\n"
                "0 0 0 0 0 0\n1 1 1 0 0 -0\n");
  EXPECT_FALSE(points.has_normals());
}

TEST(PlyReader, ToleratesCrLfBlankLinesSignsAndOddSpacing) {
  TempDir dir;
  const PointSet points = read_text(dir,
                                    "ply\r\nformat ascii 1.0\r\nelement vertex 2\r\n"
                                    "property float x\r\nproperty float y\r\nproperty double z\r\n"
                                    "end_header\r\n"
                                    "\r\n"
                                    "  +1\t-2.5e+1   .5 \r\n"
                                    "\n"
                                    "1e-50 4. 1.00000000000000000000001\r\n"
                                    "\n  \n");
  ASSERT_EQ(points.size(), 2u);
  EXPECT_EQ(points.positions[0], (Vec3f{1, -25, 0.5f}));
  EXPECT_EQ(points.positions[1], (Vec3f{0, 4, 1}));
}

// The fast decimal path and the slow path must agree with std::strtof on many spellings.
TEST(PlyReader, ParsesAsciiFloatsLikeStrtof) {
  TempDir dir;
  const char* tokens[] = {"0.0503644",
                          "-0.0317978",
                          "123456.7",
                          "16777217",
                          "3.4028235e38",
                          "1.17549435e-38",
                          "0.1",
                          "0.3",
                          "-0",
                          "7e-10",
                          "9.999999e9",
                          "12345678901234567890",
                          "0.000000000000000000000000000000000000001",
                          "2.5e-45",
                          "1.5",
                          "8388608.5",
                          "0.33333334",
                          "4.2E3"};
  std::vector<std::string> all(std::begin(tokens), std::end(tokens));
  std::mt19937 rng(99);
  for (int i = 0; i < 3000; ++i) {
    char text[64];
    const float v = std::ldexp(static_cast<float>(rng() % 100000) - 50000.0f,
                               static_cast<int>(rng() % 40) - 30);
    std::snprintf(text, sizeof text, i % 2 ? "%.6g" : "%.8g", v);
    all.push_back(text);
  }
  std::string file = "ply\nformat ascii 1.0\nelement vertex " + std::to_string(all.size()) +
                     "\nproperty float x\nproperty float y\nproperty double z\nend_header\n";
  for (const std::string& t : all) file += t + " 0 " + t + "\n";
  const PointSet points = read_text(dir, file);
  for (std::size_t i = 0; i < all.size(); ++i) {
    ASSERT_EQ(points.positions[i].x, std::strtof(all[i].c_str(), nullptr)) << all[i];
    ASSERT_EQ(points.positions[i].z, static_cast<float>(std::strtod(all[i].c_str(), nullptr)))
        << all[i];
  }
}

TEST(PlyReader, ReadsGzipCompressedFiles) {
  TempDir dir;
  std::string body;
  for (int i = 0; i < 1000; ++i)
    body += std::to_string(i) + " " + std::to_string(2 * i) + " " + std::to_string(-i) + "\n";
  const std::string file =
      "ply\nformat ascii 1.0\ncomment zipped\nelement vertex 1000\n"
      "property float x\nproperty float y\nproperty float z\nend_header\n" +
      body;
  const std::string path = dir.file("points.ply.gz");
  write_file(path, testing::gzip(file));
  const PointSet points = read_ply(path);
  ASSERT_EQ(points.size(), 1000u);
  EXPECT_EQ(points.positions[999], (Vec3f{999, 1998, -999}));
  EXPECT_EQ(points.comments, std::vector<std::string>{"zipped"});

  // Detected by content, not by name; concatenated gzip members are one stream.
  const std::string other = dir.file("points_no_extension");
  write_file(other, testing::gzip(file.substr(0, 500), 1) + testing::gzip(file.substr(500), 9));
  const PointSet again = read_ply(other);
  EXPECT_EQ(again.positions, points.positions);
}

TEST(PlyReader, ReadsBinaryGzip) {
  TempDir dir;
  std::string file =
      "ply\nformat binary_little_endian 1.0\nelement vertex 2\n"
      "property float x\nproperty float y\nproperty float z\nend_header\n";
  for (float v : {1.f, 2.f, 3.f, 4.f, 5.f, 6.f}) put(file, v);
  const std::string path = dir.file("b.ply.gz");
  write_file(path, testing::gzip(file));
  const PointSet points = read_ply(path);
  ASSERT_EQ(points.size(), 2u);
  EXPECT_EQ(points.positions[1], (Vec3f{4, 5, 6}));
}

// A vertex element with a list property goes through the generic binary walker.
TEST(PlyReader, ReadsBinaryVerticesWithListsAndAllAttributes) {
  TempDir dir;
  for (bool big : {false, true}) {
    std::string file =
        std::string("ply\n") +
        (big ? "format binary_big_endian 1.0\n" : "format binary_little_endian 1.0\n") +
        "element vertex 2\nproperty list uchar int neighbours\nproperty float x\n"
        "property double y\nproperty float z\nproperty float nx\nproperty float ny\n"
        "property float nz\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n"
        "property float radius\nend_header\n";
    for (int v = 0; v < 2; ++v) {
      put(file, std::uint8_t(2), big);
      put(file, std::int32_t(1 - v), big);
      put(file, std::int32_t(7), big);
      put(file, float(v + 0.5f), big);
      put(file, double(-v), big);
      put(file, float(10 * v), big);
      put(file, 0.0f, big);
      put(file, 2.0f, big);
      put(file, 0.0f, big);
      put(file, std::uint8_t(10 + v), big);
      put(file, std::uint8_t(20 + v), big);
      put(file, std::uint8_t(30 + v), big);
      put(file, float(0.125f * (v + 1)), big);
    }
    const PointSet points = read_text(dir, file);
    ASSERT_EQ(points.size(), 2u);
    EXPECT_EQ(points.positions[1], (Vec3f{1.5f, -1, 10}));
    ASSERT_TRUE(points.has_normals());
    EXPECT_EQ(points.normals[1], (Vec3f{0, 1, 0}));
    ASSERT_TRUE(points.has_colors());
    EXPECT_EQ(points.colors[1], (Rgb8{11, 21, 31}));
    EXPECT_EQ(points.radii, (std::vector<float>{0.125f, 0.25f}));
  }
}

// Many vertices through the blocked binary path (block boundaries at 1024), both byte orders.
TEST(PlyReader, ReadsLargeFixedLayoutBinaryVertices) {
  TempDir dir;
  for (bool big : {false, true}) {
    const int n = 5000;
    std::string file =
        std::string("ply\n") +
        (big ? "format binary_big_endian 1.0\n" : "format binary_little_endian 1.0\n") +
        "element vertex " + std::to_string(n) +
        "\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\n"
        "property uchar green\nproperty uchar blue\nproperty short unused\nproperty float scale\n"
        "end_header\n";
    for (int i = 0; i < n; ++i) {
      put(file, float(i), big);
      put(file, float(-i) * 0.5f, big);
      put(file, float(i % 7), big);
      put(file, std::uint8_t(i % 256), big);
      put(file, std::uint8_t((i / 256) % 256), big);
      put(file, std::uint8_t(3), big);
      put(file, std::int16_t(-1), big);
      put(file, float(i) * 0.25f, big);
    }
    const PointSet points = read_text(dir, file);
    ASSERT_EQ(points.size(), static_cast<std::size_t>(n));
    for (int i = 0; i < n; i += 37) {
      EXPECT_EQ(points.positions[i], (Vec3f{float(i), float(-i) * 0.5f, float(i % 7)}));
      EXPECT_EQ(points.colors[i], (Rgb8{std::uint8_t(i % 256), std::uint8_t((i / 256) % 256), 3}));
      EXPECT_EQ(points.radii[i], float(i) * 0.25f);
    }
    EXPECT_EQ(points.positions[n - 1].x, float(n - 1));
  }
}

class CountingProgress : public Progress {
 public:
  void begin_phase(std::string_view name, std::uint64_t phase_total) override {
    phases += std::string(name) + ";";
    total = phase_total;
  }
  void advance(std::uint64_t units) override { done += units; }
  void end_phase() override { ++ended; }
  std::string phases;
  std::uint64_t total = 0, done = 0;
  int ended = 0;
};

TEST(PlyReader, ReportsProgressInFileBytes) {
  TempDir dir;
  std::string file =
      "ply\nformat ascii 1.0\nelement vertex 3\n"
      "property float x\nproperty float y\nproperty float z\nend_header\n"
      "1 2 3\n4 5 6\n7 8 9\n";
  for (bool zipped : {false, true}) {
    const std::string path = dir.file(zipped ? "p.ply.gz" : "p.ply");
    const std::string bytes = zipped ? testing::gzip(file) : file;
    write_file(path, bytes);
    CountingProgress progress;
    read_ply(path, progress);
    EXPECT_EQ(progress.phases, "read;");
    EXPECT_EQ(progress.total, bytes.size());
    EXPECT_EQ(progress.done, bytes.size());
    EXPECT_EQ(progress.ended, 1);
  }
}

}  // namespace
}  // namespace pointillist
