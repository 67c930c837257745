// The mesh faces' section of .ptl version 2: faces written over the leaves come back as the same
// faces of the same points, files without it still load, and damage is reported, never read.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <set>

#include "format_test_support.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/format/ptl_v2.hpp"
#include "pointillist/prep/prepare.hpp"
#include "testing/testing.hpp"

using namespace pointillist;
using namespace pointillist::format_test;

namespace {

// A wavy grid mesh of n × n vertices.
PointSet grid_mesh(int n) {
  PointSet m;
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      m.positions.push_back({x * 0.1f, y * 0.1f, 0.05f * std::sin(0.7f * x + 0.3f * y)});
    }
  }
  for (int y = 0; y + 1 < n; ++y) {
    for (int x = 0; x + 1 < n; ++x) {
      const auto i = static_cast<std::uint32_t>(y * n + x), w = static_cast<std::uint32_t>(n);
      m.triangles.push_back({i, i + 1, i + w + 1});
      m.triangles.push_back({i, i + w + 1, i + w});
    }
  }
  return m;
}

struct Written {
  PointSet mesh;
  SphereTree tree;
  std::vector<std::array<std::uint32_t, 3>> faces;  // over the leaves
};

Written write_mesh(const std::string& path, int n, std::uint32_t page_bytes,
                   unsigned threads = 2) {
  ThreadPool pool(threads);
  Written w;
  w.mesh = grid_mesh(n);
  prepare_splats(w.mesh, pool, Progress::none());
  std::vector<std::uint32_t> order;
  w.tree = build_sphere_tree(w.mesh, pool, Progress::none(), {}, &order);
  w.faces = leaf_triangles(w.tree.view(), order, w.mesh.triangles);
  write_ptl_v2(path, w.tree, "mesh", {.page_bytes = page_bytes, .triangles = w.faces}, pool);
  return w;
}

// A face as the positions of its corners, rotated so the smallest corner comes first (winding
// kept), for comparing faces over differently numbered points.
using Corners = std::array<std::array<float, 3>, 3>;
Corners corners(const std::vector<Vec3f>& p, const std::array<std::uint32_t, 3>& t) {
  Corners c;
  for (int k = 0; k < 3; ++k) c[k] = {p[t[k]].x, p[t[k]].y, p[t[k]].z};
  const auto first = std::min_element(c.begin(), c.end()) - c.begin();
  std::rotate(c.begin(), c.begin() + first, c.end());
  return c;
}

}  // namespace

TEST(PtlV2Mesh, FacesComeBackOnTheSamePointsOverManyPages) {
  pointillist::testing::TempDir dir;
  const std::string path = dir.file("grid.ptl");
  const Written w = write_mesh(path, 60, 1024);
  const auto file = PtlV2File::open(path);
  ASSERT_TRUE(file->has_triangles());
  ASSERT_GT(file->page_count(), 10u);
  const auto faces = file->triangles();
  ASSERT_EQ(faces.size(), w.mesh.triangles.size());
  // The decoded leaves are quantized; compare against the written tree's leaves (same order).
  const PointSet leaves = sphere_tree_leaves(w.tree.view());
  std::multiset<Corners> want, got;
  for (const auto& t : w.mesh.triangles) want.insert(corners(w.mesh.positions, t));
  for (const auto& t : faces) got.insert(corners(leaves.positions, t));
  EXPECT_EQ(got, want);
}

TEST(PtlV2Mesh, TheFileIsTheSameForAnyThreadCount) {
  // The pages' face blocks are encoded in parallel.
  pointillist::testing::TempDir dir;
  write_mesh(dir.file("one.ptl"), 60, 1024, 1);
  write_mesh(dir.file("two.ptl"), 60, 1024, 2);
  const auto bytes = [](const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  };
  const std::string one = bytes(dir.file("one.ptl"));
  ASSERT_GT(one.size(), 1000u);
  EXPECT_TRUE(one == bytes(dir.file("two.ptl")));
}

TEST(PtlV2Mesh, FilesWithoutFacesHaveNone) {
  pointillist::testing::TempDir dir;
  ThreadPool pool(2);
  PointSet mesh = grid_mesh(10);
  prepare_splats(mesh, pool, Progress::none());
  write_ptl_v2(dir.file("plain.ptl"), build_sphere_tree(mesh, pool), "plain");
  const auto file = PtlV2File::open(dir.file("plain.ptl"));
  EXPECT_FALSE(file->has_triangles());
  EXPECT_TRUE(file->triangles().empty());
}

TEST(PtlV2Mesh, DamageIsReportedWithItsByte) {
  pointillist::testing::TempDir dir;
  const std::string path = dir.file("grid.ptl");
  write_mesh(path, 30, 1024);
  const Bytes good = read_bytes(path);
  const std::uint64_t at = get_u64(good, 248);
  ASSERT_GT(at, 256u);
  const auto expect_error = [&](const Bytes& b, const char* what) {
    write_bytes(path, b);
    try {
      const auto f = PtlV2File::open(path);
      (void)f->triangles();
      ADD_FAILURE() << what << ": read without an error";
    } catch (const FormatError& e) {
      EXPECT_NE(std::string(e.what()).find("byte"), std::string::npos) << e.what();
    }
  };
  {  // Truncated inside the section.
    Bytes b(good.begin(), good.begin() + static_cast<std::ptrdiff_t>(at + 60));
    expect_error(b, "truncated");
  }
  {  // A triangle count larger than the bytes can hold.
    Bytes b = good;
    put_u32(b, at + 16, 0x7fffffff);
    expect_error(b, "count");
  }
  {  // Every byte of the blocks set to 0x7f: corners far beyond the leaves.
    Bytes b = good;
    const std::uint64_t pages = get_u64(good, at + 24);
    for (std::uint64_t k = at + 40 + 16 * (pages + 1); k < good.size(); ++k) b[k] = 0x7f;
    expect_error(b, "corners");
  }
  {  // The signature gone.
    Bytes b = good;
    b[at] = 'X';
    expect_error(b, "signature");
  }
}
