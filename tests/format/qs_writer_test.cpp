#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "pointillist/core/error.hpp"
#include "pointillist/format/qs.hpp"
#include "pointillist/io/ply.hpp"
#include "testing/testing.hpp"

namespace pointillist {
namespace {

using Bytes = std::vector<std::uint8_t>;

Bytes read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_bytes(const std::string& path, const Bytes& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

std::string qsplat_file(const std::string& name) {
  return (pointillist::testing::shared_testdata_dir() / "qsplat" / name).string();
}

// Compares two byte strings; on a mismatch reports the count and the first differing offsets.
::testing::AssertionResult same_bytes(const std::vector<std::uint8_t>& got,
                                      const std::vector<std::uint8_t>& want) {
  std::size_t differing = 0;
  std::string first;
  for (std::size_t i = 0; i < std::min(got.size(), want.size()); ++i) {
    if (got[i] == want[i]) continue;
    if (++differing <= 8) {
      first += " " + std::to_string(i) + "(" + std::to_string(got[i]) + " vs " +
               std::to_string(want[i]) + ")";
    }
  }
  if (differing == 0 && got.size() == want.size()) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << "sizes " << got.size() << " vs " << want.size() << ", " << differing
         << " bytes differ; first at" << first;
}

TEST(QsWriter, ReproducesQsplatMakeByteForByte) {
  POINTILLIST_REQUIRE_SHARED_TESTDATA();
  pointillist::testing::TempDir dir;
  const PointSet mesh = read_ply(qsplat_file("dragon_vrip_res4.bbe.ply"));
  const std::string out = dir.file("dragon.qs");
  const QsWriteReport report = write_qs(out, mesh);
  EXPECT_EQ(report.input_points, 5205u);
  EXPECT_EQ(report.leaf_count, 5203u);  // two vertices are used by no face
  EXPECT_EQ(report.record_count, 7752u);
  EXPECT_EQ(report.depth, 9u);
  EXPECT_EQ(report.file_size, 34588u);
  const Bytes want = read_bytes(qsplat_file("dragon_vrip_res4.strict.qs"));
  ASSERT_EQ(want.size(), 34588u);
  EXPECT_TRUE(same_bytes(read_bytes(out), want));
}

TEST(QsWriter, ReproducesQsplatMakeWithColorsByteForByte) {
  POINTILLIST_REQUIRE_SHARED_TESTDATA();
  pointillist::testing::TempDir dir;
  const PointSet mesh = read_ply(qsplat_file("dragon_vrip_res4_color.bbe.ply"));
  ASSERT_TRUE(mesh.has_colors());
  const std::string out = dir.file("dragon_color.qs");
  write_qs(out, mesh);
  const Bytes want = read_bytes(qsplat_file("dragon_vrip_res4_color.strict.qs"));
  ASSERT_EQ(want.size(), 50124u);
  EXPECT_TRUE(same_bytes(read_bytes(out), want));
}

// The original makefile's build (-ffast-math) rounds the root sphere differently: only the 3
// header bytes of its low-order bits differ (README of the test data).
TEST(QsWriter, DiffersFromTheFastMathBuildOnlyInTheRootSphere) {
  POINTILLIST_REQUIRE_SHARED_TESTDATA();
  pointillist::testing::TempDir dir;
  const std::string out = dir.file("dragon.qs");
  write_qs(out, read_ply(qsplat_file("dragon_vrip_res4.bbe.ply")));
  const Bytes got = read_bytes(out), fast = read_bytes(qsplat_file("dragon_vrip_res4.qs"));
  ASSERT_EQ(got.size(), fast.size());
  std::vector<std::size_t> differing;
  for (std::size_t i = 0; i < got.size(); ++i) {
    if (got[i] != fast[i]) differing.push_back(i);
  }
  ASSERT_EQ(differing.size(), 3u);
  for (std::size_t at : differing) {
    EXPECT_GE(at, 44u + 20);  // root centre and radius: fragment bytes 20..35
    EXPECT_LT(at, 44u + 36);
  }
}

// ---- Round trips of a synthetic mesh ----

constexpr int kGrid = 30;

// A bumpy 30 x 30 height field over [0, 1]², two triangles per cell, plus one vertex that no
// face uses. Each vertex's colour encodes its index exactly in RGB 565 (r5 = i mod 32, g6 =
// i / 32), so decoded leaves can be matched to their vertex.
PointSet bumpy_grid() {
  PointSet m;
  for (int y = 0; y < kGrid; ++y) {
    for (int x = 0; x < kGrid; ++x) {
      const float u = float(x) / (kGrid - 1), v = float(y) / (kGrid - 1);
      m.positions.push_back({u, v, 0.1f * std::sin(5 * u) * std::cos(4 * v)});
      const int i = y * kGrid + x;
      m.colors.push_back({std::uint8_t((i % 32) << 3), std::uint8_t((i / 32) << 2), 0});
    }
  }
  m.positions.push_back({5, 5, 5});  // unused
  m.colors.push_back({255, 255, 255});
  for (int y = 0; y + 1 < kGrid; ++y) {
    for (int x = 0; x + 1 < kGrid; ++x) {
      const std::uint32_t a = y * kGrid + x, b = a + 1, c = a + kGrid, d = c + 1;
      m.triangles.push_back({a, b, d});
      m.triangles.push_back({a, d, c});
    }
  }
  m.comments = {"made by qs_writer_test", "second line"};
  return m;
}

// Area-weighted vertex normals, written out independently of the writer.
std::vector<Vec3f> vertex_normals(const PointSet& m) {
  std::vector<Vec3f> n(m.size());
  for (const auto& t : m.triangles) {
    const Vec3f p = m.positions[t[0]], q = m.positions[t[1]], r = m.positions[t[2]];
    const Vec3f e1 = q - p, e2 = r - p;
    const Vec3f f{e1.y * e2.z - e1.z * e2.y, e1.z * e2.x - e1.x * e2.z, e1.x * e2.y - e1.y * e2.x};
    for (std::uint32_t v : t) n[v] += f;
  }
  for (Vec3f& v : n) v = normalized(v);
  return n;
}

double angle_deg(Vec3f a, Vec3f b) {
  const double c = dot(a, b) / (double(length(a)) * length(b));
  return std::acos(std::clamp(c, -1.0, 1.0)) * 180.0 / 3.14159265358979323846;
}

TEST(QsWriter, RoundTripKeepsEveryVertexNormalAndColor) {
  POINTILLIST_REQUIRE_SHARED_TESTDATA();
  pointillist::testing::TempDir dir;
  const PointSet mesh = bumpy_grid();
  const std::string path = dir.file("grid.qs");
  const QsWriteReport report = write_qs(path, mesh);
  EXPECT_EQ(report.leaf_count, std::uint64_t(kGrid * kGrid));
  const QsModel m = read_qs(path);
  EXPECT_EQ(report.file_size, m.file_size);
  ASSERT_EQ(m.fragments.size(), 2u);
  EXPECT_EQ(m.comments, "made by qs_writer_test\nsecond line\n");
  EXPECT_EQ(m.fragments[0].length, 20u + 36u);  // 35 bytes of text + 1 of padding
  EXPECT_EQ(m.fragments[1].options, kQsOptionColor);
  EXPECT_EQ(m.fragments[1].length % 4, 0u);
  EXPECT_EQ(m.stats.record_count, report.record_count);
  EXPECT_EQ(m.tree.depth, report.depth);
  EXPECT_EQ(m.tree.leaf_count, std::uint64_t(kGrid * kGrid));
  EXPECT_LE(m.tree.nodes.size(), 1 + 1.5 * kGrid * kGrid + 1);  // 2-4 children per node

  const std::vector<Vec3f> normals = vertex_normals(mesh);
  std::vector<int> seen(kGrid * kGrid, 0);
  double worst_normal_deg = 0;
  for (const SphereNode& n : m.tree.nodes) {
    if (n.child_count != 0) continue;
    const int i = (n.color.r >> 3) + 32 * (n.color.g >> 2);
    ASSERT_LT(i, kGrid * kGrid);
    ++seen[i];
    // The decoded sphere is inscribed in a cube that holds the vertex: |c - p| <= √3·r.
    EXPECT_LE(distance(n.center, mesh.positions[i]), std::sqrt(3.0f) * n.radius * 1.0001f)
        << "vertex " << i;
    worst_normal_deg = std::max(worst_normal_deg, angle_deg(n.normal, normals[i]));
  }
  for (int i = 0; i < kGrid * kGrid; ++i) EXPECT_EQ(seen[i], 1) << "vertex " << i;
  // 52 cells per 90° (1.73°) plus a dither of up to half a cell per component.
  EXPECT_LT(worst_normal_deg, 5.0);
}

TEST(QsWriter, WritesFourByteRecordsWithoutColors) {
  POINTILLIST_REQUIRE_SHARED_TESTDATA();
  pointillist::testing::TempDir dir;
  const PointSet mesh = bumpy_grid();
  const std::string with = dir.file("with.qs"), without = dir.file("without.qs");
  const QsWriteReport a = write_qs(with, mesh);
  const QsWriteReport b = write_qs(without, mesh, {.write_colors = false, .write_comments = false});
  EXPECT_EQ(a.record_count, b.record_count);
  const QsModel m = read_qs(without);
  ASSERT_EQ(m.fragments.size(), 1u);  // no comment fragment
  EXPECT_EQ(m.fragments[0].options, 0u);
  EXPECT_FALSE(m.tree.has_colors);
  // Tree fragments: 40-byte header, records, one pointer per group with a pointer (the same in
  // both), then padding to a multiple of 4 (2 bytes when 6-byte records are odd in number).
  EXPECT_EQ(b.file_size % 4, 0u);
  const std::uint64_t tree_with = a.file_size - 56;  // minus the comment fragment
  EXPECT_EQ(tree_with - b.file_size, 2 * b.record_count + (b.record_count % 2 == 1 ? 2 : 0));
  // Same tree and same dither sequence: identical spheres and normals.
  const QsModel c = read_qs(with);
  ASSERT_EQ(c.tree.nodes.size(), m.tree.nodes.size());
  for (std::size_t i = 0; i < m.tree.nodes.size(); ++i) {
    ASSERT_EQ(c.tree.nodes[i].center, m.tree.nodes[i].center) << i;
    ASSERT_EQ(c.tree.nodes[i].normal, m.tree.nodes[i].normal) << i;
  }
}

TEST(QsWriter, DitherSpreadsTheNormalsOfAFlatPlane) {
  POINTILLIST_REQUIRE_SHARED_TESTDATA();
  pointillist::testing::TempDir dir;
  PointSet plane = bumpy_grid();
  for (Vec3f& p : plane.positions) p.z = 0;
  const std::string path = dir.file("plane.qs");
  // Without dither every normal (0, 0, 1) lands in cell (26, 26) of the +z face, whose centre is
  // (g, g, √(1 - 2g²)) with g = tan(π/208).
  write_qs(path, plane, {.dither_normals = false});
  const double g = std::tan(3.14159265358979323846 / 208);
  for (const SphereNode& n : read_qs(path).tree.nodes) {
    if (n.child_count != 0) continue;
    EXPECT_NEAR(n.normal.x, g, 1e-6);
    EXPECT_NEAR(n.normal.y, g, 1e-6);
  }
  write_qs(path, plane);
  std::size_t off_centre = 0;
  for (const SphereNode& n : read_qs(path).tree.nodes) {
    if (n.child_count == 0 && std::abs(n.normal.x - g) > 1e-3) ++off_centre;
  }
  EXPECT_GT(off_centre, 100u);  // dithered into the neighbouring cells
}

TEST(QsWriter, WritesPointSetsWithTheirOwnNormalsAndRadii) {
  POINTILLIST_REQUIRE_SHARED_TESTDATA();
  pointillist::testing::TempDir dir;
  PointSet cloud;
  for (int i = 0; i < 50; ++i) {
    cloud.positions.push_back({float(i % 10), float(i / 10), 0});
    cloud.normals.push_back({0, 0, 1});
    cloud.radii.push_back(i == 7 ? 0.0f : 0.6f);  // radius 0: dropped
  }
  const std::string path = dir.file("cloud.qs");
  EXPECT_EQ(write_qs(path, cloud).leaf_count, 49u);
  const QsModel m = read_qs(path);
  EXPECT_EQ(m.tree.leaf_count, 49u);
  for (const SphereNode& n : m.tree.nodes) {
    if (n.child_count == 0) {
      EXPECT_GE(n.radius, 0.6f * 0.99f);
    }
  }
  // Three points: the root's group has no grandchildren but still a pointer (the viewer reads
  // one unconditionally, spec §12.9): 40 + 4 + 3 x 4 bytes.
  cloud.positions.resize(3);
  cloud.normals.resize(3);
  cloud.radii = {0.5f, 0.5f, 0.5f};
  EXPECT_EQ(write_qs(path, cloud, {.write_comments = false}).file_size, 56u);
  const Bytes bytes = read_bytes(path);
  ASSERT_EQ(bytes.size(), 56u);
  EXPECT_EQ(bytes[43], 16);  // pointer 16: just past the root's group
  EXPECT_EQ(read_qs(path).tree.leaf_count, 3u);
  // One point cannot make a tree.
  cloud.positions.resize(1);
  cloud.normals.resize(1);
  cloud.radii.resize(1);
  EXPECT_THROW(write_qs(path, cloud), Error);
}

TEST(QsWriter, RejectsUnusableInputAndLeavesExistingFilesAlone) {
  POINTILLIST_REQUIRE_SHARED_TESTDATA();
  pointillist::testing::TempDir dir;
  const std::string path = dir.file("keep.qs");
  write_bytes(path, {1, 2, 3});
  PointSet degenerate;  // one triangle of three equal points: radius 0, nothing left
  degenerate.positions = {{1, 1, 1}, {1, 1, 1}, {1, 1, 1}};
  degenerate.triangles = {{0, 1, 2}};
  EXPECT_THROW(write_qs(path, degenerate), Error);
  PointSet bad_index = bumpy_grid();
  bad_index.triangles[5][1] = 100000;
  try {
    write_qs(path, bad_index);
    ADD_FAILURE() << "no error for a face index out of range";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("triangle 5"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
  PointSet cloud;
  cloud.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  try {
    write_qs(path, cloud);
    ADD_FAILURE() << "no error for a point set without normals";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("prepare_splats"), std::string::npos) << e.what();
  }
  PointSet nan_point = bumpy_grid();
  nan_point.positions[3].y = std::nanf("");
  EXPECT_THROW(write_qs(path, nan_point), Error);
  EXPECT_EQ(read_bytes(path), (Bytes{1, 2, 3}));
  EXPECT_THROW(write_qs(dir.file("no/such/folder/x.qs"), bumpy_grid()), IoError);
  // Only the untouched file remains: no temporary files left behind.
  std::size_t files = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir.path())) {
    files += e.is_regular_file();
  }
  EXPECT_EQ(files, 1u);
}

// The full Stanford dragon (when fetched): the structure spec §13 measured on QSplat 1.0's
// output for the same mesh.
TEST(QsWriter, MatchesQsplatMakeStatisticsOnTheFullDragon) {
  POINTILLIST_REQUIRE_SHARED_TESTDATA();
  const auto path = pointillist::testing::cached_model("dragon_vrip.ply.gz");
  if (path.empty()) GTEST_SKIP() << "dragon not fetched (run scripts/fetch-models.sh)";
  pointillist::testing::TempDir dir;
  const std::string out = dir.file("dragon.qs");
  const QsWriteReport r = write_qs(out, read_ply(path.string()));
  EXPECT_EQ(r.leaf_count, 437645u);
  EXPECT_EQ(r.record_count, 653581u);
  EXPECT_EQ(r.depth, 16u);
  const QsModel m = read_qs(out);
  EXPECT_EQ(m.stats.child_count_histogram,
            (std::array<std::uint64_t, 5>{437645, 0, 68690, 72787, 74459}));
  EXPECT_EQ(m.file_size, 2919888u);  // with the 44-byte comment fragment
}

}  // namespace
}  // namespace pointillist
