#include "pointillist/format/ptl.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>

#include "lod/sphere_points.hpp"
#include "pointillist/core/error.hpp"
#include "testing/testing.hpp"

namespace pointillist {
namespace {

namespace fs = std::filesystem;
using testing::TempDir;

// Node field offsets in the file (docs/ptl-format.md), written out rather than taken from the
// struct so a layout change fails the tests.
constexpr std::size_t kNodesAt = 256;
constexpr std::size_t kNodeBytes = 40;
constexpr std::size_t kRadiusField = 12;
constexpr std::size_t kFirstChildField = 32;
constexpr std::size_t kChildCountField = 36;

std::vector<std::uint8_t> read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_bytes(const std::string& path, const std::vector<std::uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

void patch_u32(std::vector<std::uint8_t>& b, std::size_t at, std::uint32_t v) {
  if (at + 4 > b.size()) {
    ADD_FAILURE() << "patch at byte " << at << " beyond the file (" << b.size() << " bytes)";
    return;
  }
  for (std::size_t i = 0; i < 4; ++i) b[at + i] = std::uint8_t(v >> (8 * i));
}

// Root over two leaves, values with simple float bit patterns.
SphereTree tiny_tree() {
  SphereTree t;
  SphereNode root;
  root.center = {0, 0, 0};
  root.radius = 2;
  root.normal = {0, 0, 1};
  root.cone_sin = 0.5f;
  root.first_child = 1;
  root.child_count = 2;
  root.color = {10, 20, 30};
  SphereNode a;
  a.center = {-1, 0, 0};
  a.radius = 1;
  a.normal = {0, 0, 1};
  a.color = {1, 2, 3};
  SphereNode b = a;
  b.center = {1, 0, 0};
  t.nodes = {root, a, b};
  t.has_colors = true;
  t.leaf_count = 2;
  t.depth = 1;
  t.bounds = {{-1, 0, 0}, {1, 0, 0}};
  t.view_sphere = {{0, 0, 0}, 1};
  return t;
}

// Message of the error `open` throws for the file `bytes`, written to `path`.
template <typename E = FormatError>
std::string open_error(const std::string& path, const std::vector<std::uint8_t>& bytes) {
  write_bytes(path, bytes);
  try {
    PtlFile::open(path);
  } catch (const E& e) {
    return e.what();
  }
  ADD_FAILURE() << "no error for " << path;
  return "";
}

using pointillist::testing::expect_names;

TEST(PtlFile, RoundTripKeepsEveryNodeAndHeaderField) {
  TempDir dir;
  ThreadPool pool(2);
  const SphereTree tree = build_sphere_tree(testing::sphere_points(3000, 21, true), pool);
  const std::string path = dir.file("sphere.ptl");
  const std::string metadata = "source: sphere\nconverted by: test\n";
  write_ptl(path, tree, metadata);
  const auto file = PtlFile::open(path);
  const SphereTreeView& v = file->tree();
  ASSERT_EQ(v.nodes.size(), tree.nodes.size());
  EXPECT_EQ(std::memcmp(v.nodes.data(), tree.nodes.data(), tree.nodes.size() * sizeof(SphereNode)),
            0);
  EXPECT_TRUE(v.has_colors);
  EXPECT_EQ(v.leaf_count, tree.leaf_count);
  EXPECT_EQ(v.depth, tree.depth);
  EXPECT_EQ(v.bounds.lo, tree.bounds.lo);
  EXPECT_EQ(v.bounds.hi, tree.bounds.hi);
  EXPECT_EQ(v.view_sphere.center, tree.view_sphere.center);
  EXPECT_EQ(v.view_sphere.radius, tree.view_sphere.radius);
  EXPECT_EQ(file->metadata(), metadata);
  EXPECT_EQ(file->version(), 1u);
  EXPECT_EQ(file->file_size(), kNodesAt + tree.nodes.size() * kNodeBytes + metadata.size());
  EXPECT_EQ(fs::file_size(path), file->file_size());

  // Without colors, and with empty metadata.
  SphereTree plain = tree;
  plain.has_colors = false;
  write_ptl(path, plain, "");
  const auto plain_file = PtlFile::open(path);
  EXPECT_FALSE(plain_file->tree().has_colors);
  EXPECT_EQ(plain_file->metadata(), "");
}

TEST(PtlFile, GoldenBytes) {
  TempDir dir;
  const std::string path = dir.file("tiny.ptl");
  write_ptl(path, tiny_tree(), "hi\n");
  const std::vector<std::uint8_t> bytes = read_bytes(path);
  ASSERT_EQ(bytes.size(), 256u + 3 * 40 + 3);
  std::vector<std::uint8_t> header(256, 0);
  const std::uint8_t expected_start[] = {
      'P', 'T', 'L', 'S', 'P', 'L', 'A', 'T',  // magic
      1, 0, 0, 0,                              // version 1
      0, 1, 0, 0,                              // header size 256
      1, 0, 0, 0,                              // flags: has colors
      40, 0, 0, 0,                             // node size
      3, 0, 0, 0, 0, 0, 0, 0,                  // node count
      2, 0, 0, 0, 0, 0, 0, 0,                  // leaf count
      1, 0, 0, 0,                              // depth
      0, 0, 0, 0,                              // compatible flags
      0, 0, 0x80, 0xbf, 0, 0, 0, 0, 0, 0, 0, 0,     // bounds lo (-1, 0, 0)
      0, 0, 0x80, 0x3f, 0, 0, 0, 0, 0, 0, 0, 0,     // bounds hi (1, 0, 0)
      0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0,           // view centre
      0, 0, 0x80, 0x3f,                             // view radius 1
      0, 1, 0, 0, 0, 0, 0, 0,                       // nodes at 256
      0x78, 0x01, 0, 0, 0, 0, 0, 0,                 // metadata at 376
      3, 0, 0, 0, 0, 0, 0, 0,                       // metadata size 3
  };
  static_assert(sizeof expected_start == 112);
  std::copy(std::begin(expected_start), std::end(expected_start), header.begin());
  EXPECT_EQ(std::vector<std::uint8_t>(bytes.begin(), bytes.begin() + 256), header);
  const std::vector<std::uint8_t> root = {
      0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0,  // centre (0, 0, 0)
      0, 0, 0, 0x40,                       // radius 2
      0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0x80, 0x3f,  // normal (0, 0, 1)
      0, 0, 0, 0x3f,                       // cone sine 0.5
      1, 0, 0, 0,                          // first child 1
      2,                                   // child count
      10, 20, 30,                          // color
  };
  EXPECT_EQ(std::vector<std::uint8_t>(bytes.begin() + 256, bytes.begin() + 296), root);
  EXPECT_EQ(std::string(bytes.end() - 3, bytes.end()), "hi\n");
}

TEST(PtlFile, RejectsWrongMagic) {
  TempDir dir;
  const std::string path = dir.file("scan.ptl");
  std::vector<std::uint8_t> ply(300, ' ');
  std::memcpy(ply.data(), "ply\nformat", 10);
  const std::string m = open_error(path, ply);
  expect_names(m, path, 0, "not a Pointillist model file");
  EXPECT_NE(m.find("ply\\x0aform"), std::string::npos) << m;
  expect_names(open_error(path, {}), path, 0, "not a Pointillist model file");
  EXPECT_FALSE(is_ptl_file(path));
}

TEST(PtlFile, RejectsNewerVersion) {
  TempDir dir;
  const std::string path = dir.file("future.ptl");
  write_ptl(path, tiny_tree(), "");
  std::vector<std::uint8_t> bytes = read_bytes(path);
  patch_u32(bytes, 8, 3);
  const std::string m = open_error(path, bytes);
  expect_names(m, path, 8, "version 3");
  EXPECT_NE(m.find("reads (versions 1 and 2)"), std::string::npos) << m;
  EXPECT_NE(m.find("upgrade"), std::string::npos) << m;
}

TEST(PtlFile, RejectsUnknownFlagsButIgnoresUnknownCompatibleFlags) {
  TempDir dir;
  const std::string path = dir.file("flags.ptl");
  write_ptl(path, tiny_tree(), "");
  std::vector<std::uint8_t> bytes = read_bytes(path);
  std::vector<std::uint8_t> compat = bytes;
  patch_u32(bytes, 16, 0x11);
  expect_names(open_error(path, bytes), path, 16, "flags 0x11");
  patch_u32(compat, 44, 0x20);
  std::uint8_t reserved_before = compat[200];
  compat[200] = 0x7f;  // reserved bytes are ignored too
  write_bytes(path, compat);
  EXPECT_NO_THROW(PtlFile::open(path));
  EXPECT_EQ(reserved_before, 0);
}

TEST(PtlFile, RejectsTruncatedFile) {
  TempDir dir;
  const std::string path = dir.file("cut.ptl");
  ThreadPool pool(1);
  write_ptl(path, build_sphere_tree(testing::sphere_points(200, 22), pool), "meta");
  const std::vector<std::uint8_t> bytes = read_bytes(path);
  for (std::size_t size : {std::size_t{100}, std::size_t{256 + 40 * 17 + 7}, bytes.size() - 1}) {
    const std::vector<std::uint8_t> cut(bytes.begin(), bytes.begin() + std::ptrdiff_t(size));
    expect_names(open_error(path, cut), path, size, "file ends early");
  }
}

TEST(PtlFile, RejectsChildOutOfRange) {
  TempDir dir;
  const std::string path = dir.file("range.ptl");
  write_ptl(path, tiny_tree(), "");
  std::vector<std::uint8_t> bytes = read_bytes(path);
  patch_u32(bytes, kNodesAt + kFirstChildField, 2);  // children 2 and 3 of 3 nodes
  const std::string m = open_error(path, bytes);
  expect_names(m, path, kNodesAt + kFirstChildField, "node 0 of 3");
  EXPECT_NE(m.find("out of range"), std::string::npos) << m;
}

TEST(PtlFile, RejectsChildIndexNotAfterParent) {
  TempDir dir;
  const std::string path = dir.file("loop.ptl");
  ThreadPool pool(1);
  const SphereTree tree = build_sphere_tree(testing::sphere_points(100, 23), pool);
  write_ptl(path, tree, "");
  std::uint32_t interior = 1;
  while (tree.nodes[interior].child_count == 0) ++interior;
  for (std::uint32_t target : {interior, interior - 1, 0u}) {
    std::vector<std::uint8_t> bytes = read_bytes(path);
    patch_u32(bytes, kNodesAt + interior * kNodeBytes + kFirstChildField, target);
    const std::string m = open_error(path, bytes);
    expect_names(m, path, kNodesAt + interior * kNodeBytes + kFirstChildField,
                 "node " + std::to_string(interior) + " of");
    EXPECT_NE(m.find("does not come after"), std::string::npos) << m;
  }
}

TEST(PtlFile, RejectsNodesWithTwoParentsAndBadChildCounts) {
  TempDir dir;
  const std::string path = dir.file("shape.ptl");
  // Root -> 1, 2; node 1 -> 3, 4; node 2 claims 3, 4 as well.
  SphereTree t = tiny_tree();
  t.nodes.resize(5, t.nodes[1]);
  t.nodes[1].first_child = 3;
  t.nodes[1].child_count = 2;
  t.leaf_count = 3;
  t.depth = 2;
  write_ptl(path, t, "");
  EXPECT_NO_THROW(PtlFile::open(path));
  std::vector<std::uint8_t> bytes = read_bytes(path);
  std::vector<std::uint8_t> two_parents = bytes;
  patch_u32(two_parents, kNodesAt + 2 * kNodeBytes + kFirstChildField, 3);
  two_parents[kNodesAt + 2 * kNodeBytes + kChildCountField] = 2;
  expect_names(open_error(path, two_parents), path, kNodesAt + 2 * kNodeBytes + kFirstChildField,
               "expected 5");
  std::vector<std::uint8_t> one_child = bytes;
  one_child[kNodesAt + kNodeBytes + kChildCountField] = 1;
  expect_names(open_error(path, one_child), path, kNodesAt + kNodeBytes + kChildCountField,
               "child count 1");
  std::vector<std::uint8_t> nan_radius = bytes;
  patch_u32(nan_radius, kNodesAt + 4 * kNodeBytes + kRadiusField, 0x7fc00000);
  expect_names(open_error(path, nan_radius), path, kNodesAt + 4 * kNodeBytes + kRadiusField,
               "node 4 of 5: radius");
  std::vector<std::uint8_t> wrong_leaves = bytes;
  patch_u32(wrong_leaves, 32, 4);
  expect_names(open_error(path, wrong_leaves), path, 32, "header says 4 leaves");
  std::vector<std::uint8_t> wrong_depth = bytes;
  patch_u32(wrong_depth, 40, 1);
  expect_names(open_error(path, wrong_depth), path, 40, "depth 1");
}

TEST(PtlFile, MissingFileIsAnIoError) {
  TempDir dir;
  const std::string path = dir.file("absent.ptl");
  try {
    PtlFile::open(path);
    ADD_FAILURE();
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
  EXPECT_FALSE(is_ptl_file(path));
}

// Files in `dir` (to check no temporary file is left behind).
std::vector<std::string> entries(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  return names;
}

TEST(PtlFile, AtomicWriteLeavesNoTemporaryFile) {
  TempDir dir;
  // Folder does not exist: nothing can be created.
  const std::string missing = dir.file("no-such-folder/model.ptl");
  try {
    write_ptl(missing, tiny_tree(), "");
    ADD_FAILURE();
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find(missing), std::string::npos) << e.what();
  }
  EXPECT_TRUE(entries(dir.path()).empty());
  // Destination is a folder: the temporary file is written, the rename fails, and the
  // temporary file is removed.
  fs::create_directory(dir.path() / "taken.ptl");
  fs::create_directory(dir.path() / "taken.ptl" / "inside");
  const std::string taken = dir.file("taken.ptl");
  try {
    write_ptl(taken, tiny_tree(), "");
    ADD_FAILURE();
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find(taken), std::string::npos) << e.what();
  }
  EXPECT_EQ(entries(dir.path()), std::vector<std::string>{"taken.ptl"});
  // Overwriting an existing model replaces it whole.
  const std::string model = dir.file("model.ptl");
  write_bytes(model, std::vector<std::uint8_t>(5000, 'x'));
  write_ptl(model, tiny_tree(), "new");
  EXPECT_EQ(fs::file_size(model), 256u + 120 + 3);
  EXPECT_TRUE(is_ptl_file(model));
  EXPECT_EQ(entries(dir.path()).size(), 2u);
}

}  // namespace
}  // namespace pointillist
