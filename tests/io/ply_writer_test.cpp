// PLY writer: golden bytes written out by hand for every encoding, round trips through the
// reader, and the atomic-write guarantees.
#include <gtest/gtest.h>

#include <filesystem>
#include <random>

#include "io_test_support.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/io/ply.hpp"
#include "testing/testing.hpp"

namespace pointillist {
namespace {

using testing::put;
using testing::read_file;
using testing::TempDir;

PointSet tiny_set() {
  PointSet p;
  p.positions = {{1, 2, 3}, {-0.5f, 0.25f, 0.001f}};
  p.normals = {{0, 0, 1}, {1, 0, 0}};
  p.colors = {{255, 0, 16}, {1, 2, 3}};
  p.radii = {0.5f, 2.0f};
  p.triangles = {{0, 1, 0}};
  p.comments = {"hello", "two\nlines"};
  return p;
}

std::string tiny_header(const char* format) {
  return std::string("ply\nformat ") + format +
         " 1.0\ncomment hello\ncomment two lines\nelement vertex 2\n"
         "property float x\nproperty float y\nproperty float z\n"
         "property float nx\nproperty float ny\nproperty float nz\n"
         "property uchar red\nproperty uchar green\nproperty uchar blue\n"
         "property float radius\n"
         "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
}

std::string tiny_binary(bool big) {
  std::string b = tiny_header(big ? "binary_big_endian" : "binary_little_endian");
  const PointSet p = tiny_set();
  for (int i = 0; i < 2; ++i) {
    for (int k = 0; k < 3; ++k) put(b, p.positions[i][k], big);
    for (int k = 0; k < 3; ++k) put(b, p.normals[i][k], big);
    put(b, p.colors[i].r, big);
    put(b, p.colors[i].g, big);
    put(b, p.colors[i].b, big);
    put(b, p.radii[i], big);
  }
  put(b, std::uint8_t(3), big);
  for (std::int32_t v : {0, 1, 0}) put(b, v, big);
  return b;
}

TEST(PlyWriter, WritesGoldenBinaryLittleEndian) {
  TempDir dir;
  const std::string path = dir.file("out.ply");
  write_ply(path, tiny_set());  // the default encoding
  EXPECT_EQ(read_file(path), tiny_binary(false));
}

TEST(PlyWriter, WritesGoldenBinaryBigEndian) {
  TempDir dir;
  const std::string path = dir.file("out.ply");
  write_ply(path, tiny_set(), {.encoding = PlyEncoding::BinaryBigEndian});
  EXPECT_EQ(read_file(path), tiny_binary(true));
}

TEST(PlyWriter, WritesGoldenAscii) {
  TempDir dir;
  const std::string path = dir.file("out.ply");
  write_ply(path, tiny_set(), {.encoding = PlyEncoding::Ascii});
  EXPECT_EQ(read_file(path), tiny_header("ascii") +
                                 "1 2 3 0 0 1 255 0 16 0.5\n"
                                 "-0.5 0.25 0.001 1 0 0 1 2 3 2\n"
                                 "3 0 1 0\n");
}

TEST(PlyWriter, WritesOnlyPresentAttributesAndFacesWhenAsked) {
  TempDir dir;
  const std::string path = dir.file("out.ply");
  PointSet p;
  p.positions = {{1, 2, 3}};
  p.triangles = {{0, 0, 0}};
  write_ply(path, p, {.encoding = PlyEncoding::Ascii, .write_faces = false});
  EXPECT_EQ(read_file(path),
            "ply\nformat ascii 1.0\nelement vertex 1\n"
            "property float x\nproperty float y\nproperty float z\nend_header\n1 2 3\n");
}

PointSet random_set(std::uint32_t seed, std::size_t n) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-100, 100);
  PointSet p;
  for (std::size_t i = 0; i < n; ++i) {
    p.positions.push_back({u(rng), u(rng) * 1e-6f, u(rng) * 1e6f});
    p.normals.push_back(normalized({u(rng), u(rng), u(rng)}));
    p.colors.push_back({std::uint8_t(rng()), std::uint8_t(rng()), std::uint8_t(rng())});
    p.radii.push_back(std::abs(u(rng)) * 1e-3f);
  }
  for (std::size_t t = 0; t + 2 < n; t += 2)
    p.triangles.push_back({std::uint32_t(t), std::uint32_t(rng() % n), std::uint32_t(t + 2)});
  p.comments = {"seeded"};
  return p;
}

TEST(PlyWriter, RoundTripsEveryEncoding) {
  TempDir dir;
  const PointSet original = random_set(42, 20000);
  for (PlyEncoding encoding :
       {PlyEncoding::BinaryLittleEndian, PlyEncoding::BinaryBigEndian, PlyEncoding::Ascii}) {
    SCOPED_TRACE(static_cast<int>(encoding));
    const std::string path = dir.file("round.ply");
    write_ply(path, original, {.encoding = encoding});
    const PointSet back = read_ply(path);
    EXPECT_EQ(back.positions, original.positions);  // ascii uses shortest round-trip text
    EXPECT_EQ(back.colors, original.colors);
    EXPECT_EQ(back.radii, original.radii);
    EXPECT_EQ(back.triangles, original.triangles);
    EXPECT_EQ(back.comments, original.comments);
    ASSERT_EQ(back.normals.size(), original.normals.size());
    for (std::size_t i = 0; i < back.normals.size(); ++i)
      ASSERT_LT(length(back.normals[i] - original.normals[i]), 1e-6f) << i;  // re-normalized
  }
}

TEST(PlyWriter, ReplacesExistingFileAndLeavesNoTemporaryFile) {
  TempDir dir;
  const std::string path = dir.file("out.ply");
  testing::write_file(path, "old contents");
  write_ply(path, tiny_set());
  EXPECT_EQ(read_file(path), tiny_binary(false));
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(dir.path()))
    names.push_back(entry.path().filename());
  EXPECT_EQ(names, std::vector<std::string>{"out.ply"});
}

TEST(PlyWriter, FailureLeavesNoFileBehind) {
  TempDir dir;
  // Rename onto a non-empty directory fails after the body is written: the temp file goes away.
  const std::string blocked = dir.file("blocked.ply");
  std::filesystem::create_directory(blocked);
  testing::write_file(blocked + "/keep", "x");
  try {
    write_ply(blocked, tiny_set());
    ADD_FAILURE() << "no exception";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find(blocked), std::string::npos) << e.what();
  }
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(dir.path()))
    names.push_back(entry.path().filename());
  EXPECT_EQ(names, std::vector<std::string>{"blocked.ply"});

  // A folder that does not exist.
  const std::string missing = dir.file("no/such/folder/out.ply");
  try {
    write_ply(missing, tiny_set());
    ADD_FAILURE() << "no exception";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find(missing), std::string::npos) << e.what();
  }

  // Attribute arrays of the wrong length are refused before anything is created.
  PointSet bad = tiny_set();
  bad.radii.pop_back();
  const std::string bad_path = dir.file("bad.ply");
  EXPECT_THROW(write_ply(bad_path, bad), Error);
  EXPECT_FALSE(std::filesystem::exists(bad_path));
}

// The batch writer: the header written out by hand, then each batch's records in order, and
// the reader gives the points back; a short or ill-fitting write leaves no file.
TEST(PlyPointWriter, WritesBatchesUnderOneHeaderThatTheReaderReadsBack) {
  TempDir dir;
  const std::string path = dir.file("batches.ply");
  PointSet layout;
  layout.positions.resize(1);
  layout.colors.resize(1);
  layout.comments = {"made in batches"};
  PlyPointWriter writer(path, layout, 5);
  PointSet a, b;
  a.positions = {{1, 2, 3}, {4, 5, 6}};
  a.colors = {{1, 2, 3}, {4, 5, 6}};
  b.positions = {{-1, -2, -3}, {0.5f, 0.25f, 0.125f}, {7, 8, 9}};
  b.colors = {{7, 8, 9}, {10, 11, 12}, {255, 254, 253}};
  writer.write(a);
  writer.write(b);
  EXPECT_FALSE(std::filesystem::exists(path));  // not before commit
  writer.commit();
  const std::string header =
      "ply\nformat binary_little_endian 1.0\ncomment made in batches\nelement vertex 5\n"
      "property float x\nproperty float y\nproperty float z\n"
      "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n";
  std::string body;
  for (const PointSet* s : {&a, &b}) {
    for (std::size_t i = 0; i < s->size(); ++i) {
      for (float v : {s->positions[i].x, s->positions[i].y, s->positions[i].z}) put(body, v);
      body += char(s->colors[i].r);
      body += char(s->colors[i].g);
      body += char(s->colors[i].b);
    }
  }
  EXPECT_EQ(read_file(path), header + body);
  const PointSet back = read_ply(path);
  ASSERT_EQ(back.size(), 5u);
  EXPECT_EQ(back.positions[3].y, 0.25f);
  EXPECT_EQ(back.colors[4].g, 254);
}

TEST(PlyPointWriter, RefusesBatchesThatDoNotFitAndACountNotReached) {
  TempDir dir;
  const std::string path = dir.file("short.ply");
  PointSet layout;
  layout.positions.resize(1);
  PointSet three;
  three.positions = {{1, 2, 3}, {4, 5, 6}, {7, 8, 9}};
  {
    PlyPointWriter writer(path, layout, 2);
    EXPECT_THROW(writer.write(three), Error);  // more than announced
    PointSet coloured = three;
    coloured.colors.assign(3, {1, 2, 3});
    EXPECT_THROW(writer.write(coloured), Error);  // other properties
    EXPECT_THROW(writer.commit(), Error);         // 0 of 2 written
  }
  EXPECT_FALSE(std::filesystem::exists(path));
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

}  // namespace
}  // namespace pointillist
