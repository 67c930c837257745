// QSplat 1.0's out-of-table sphere code (spec ../shared/specs/qsplat-qs-format.md §4.3): a child
// that sticks out of its decoded parent can land in a cube the sphere table lacks, and the
// original then writes code 8191. Two leaves of the twice-subdivided Stanford dragon do; here a
// five-point set builds the same configuration, and the expected bytes come from the spec's
// rules, restated below without the library's encoder.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "pointillist/core/error.hpp"
#include "format_test_support.hpp"
#include "pointillist/format/qs.hpp"
#include "testing/testing.hpp"

namespace pointillist {
namespace {

using format_test::Bytes;
using format_test::read_bytes;
using format_test::write_bytes;

constexpr int kOutOfTable = 8191;

std::uint32_t be32(const Bytes& b, std::size_t at) {
  return std::uint32_t{b[at]} << 24 | std::uint32_t{b[at + 1]} << 16 |
         std::uint32_t{b[at + 2]} << 8 | b[at + 3];
}
std::uint32_t be16(const Bytes& b, std::size_t at) { return std::uint32_t{b[at]} << 8 | b[at + 1]; }
float be_float(const Bytes& b, std::size_t at) { return std::bit_cast<float>(be32(b, at)); }

// Spec §4.1: candidates in code order (m, then x, y, z), skipping cubes whose circumscribed
// sphere misses the unit ball; float32 with 1/13 as a float32 constant.
struct SpecSphereTable {
  std::vector<std::array<float, 4>> candidates;  // X, Y, Z, R by code
  std::map<std::array<int, 4>, int> codes;       // (m, x, y, z) -> code, kept cubes only
};

SpecSphereTable spec_sphere_table() {
  SpecSphereTable t;
  const float c = 1.0f / 13.0f;
  for (int m = 1; m <= 13; ++m) {
    for (int x = 0; x <= 13 - m; ++x) {
      for (int y = 0; y <= 13 - m; ++y) {
        for (int z = 0; z <= 13 - m; ++z) {
          const float X = float(m + 2 * x) * c - 1.0f, Y = float(m + 2 * y) * c - 1.0f,
                      Z = float(m + 2 * z) * c - 1.0f, R = float(m) * c;
          const double reach = 1.0 + std::sqrt(3.0) * R;
          if (double(X) * X + double(Y) * Y + double(Z) * Z > reach * reach) continue;
          t.codes[{m, x, y, z}] = int(t.candidates.size());
          t.candidates.push_back({X, Y, Z, R});
        }
      }
    }
  }
  return t;
}

// Spec §4.3: the code of child sphere (c, r) against decoded parent (p, rho); a cube not in the
// table gives 8191.
int spec_sphere_code(const SpecSphereTable& table, Vec3f p, float rho, Vec3f c, float r) {
  const float s = r / rho;
  std::array<int, 3> lo{}, hi{};
  int m = 0;
  for (int a = 0; a < 3; ++a) {
    const float t = 0.5f * ((c[a] - p[a]) / rho + 1.0f);
    lo[a] = std::clamp(int(std::floor((t - s / 2) * 13)), 0, 12);
    hi[a] = std::clamp(int(std::ceil((t + s / 2) * 13)), 1, 13);
    m = std::max(m, hi[a] - lo[a]);
  }
  for (int a = 0; a < 3; ++a) {
    if (hi[a] - lo[a] < m) {
      if (lo[a] > 0) {
        --lo[a];
      } else {
        ++hi[a];
      }
    }
  }
  const auto it = table.codes.find({m, lo[0], lo[1], lo[2]});
  return it == table.codes.end() ? kOutOfTable : it->second;
}

// A far point A and a cluster of four: the root's children are A and node B over the cluster
// (spec §8.3). B fits inside one of the root's 13³ cells, so it decodes to that whole cell
// (code m = 1), centred off B's own centre; the first cluster point, tiny and out towards the
// cell's (+x, +y, +z) corner, then lies in cell (11, 11, 11) of B's grid, outside B's decoded
// sphere, and that one-cell cube is skipped by the table (|(X, Y, Z)| = 1.33 > 1 + √3/13).
PointSet corner_cluster() {
  PointSet points;
  points.positions = {{-1.0f, -0.045f, -0.045f},
                      {1.005f, 0.06f, 0.06f},
                      {0.988f, 0.037f, 0.04f},
                      {0.985f, 0.043f, 0.037f},
                      {0.982f, 0.04f, 0.043f}};
  points.normals.assign(5, Vec3f{0, 0, 1});
  points.radii.assign(5, 0.001f);
  return points;
}

TEST(QsOutOfTableCode, LeafInACubeTheTableSkipsIsWrittenAs8191) {
  pointillist::testing::TempDir dir;
  const PointSet points = corner_cluster();
  const std::string path = dir.file("corner.qs");
  write_qs(path, points, {.write_comments = false});
  const Bytes b = read_bytes(path);
  // 40-byte header; root group: pointer, A, B; B's group: its four leaves, no pointer.
  ASSERT_EQ(b.size(), 40u + 4 + 2 * 4 + 4 * 4);
  ASSERT_EQ(be32(b, 36), 2u);  // root children
  const std::uint32_t a_word = be16(b, 44), b_word = be16(b, 48);
  ASSERT_EQ(a_word & 7u, 0u);  // A: leaf
  ASSERT_EQ(b_word & 7u, 3u);  // B: 4 children, no grandchild

  const SpecSphereTable table = spec_sphere_table();
  ASSERT_EQ(table.candidates.size(), 7621u);
  // B's sphere (spec §8.4: mean centre, max of distance plus child radius) and its code against
  // the header's root sphere.
  const Vec3f root_center{be_float(b, 20), be_float(b, 24), be_float(b, 28)};
  const float root_radius = be_float(b, 32);
  const std::span<const Vec3f> cluster = std::span(points.positions).subspan(1);
  const Vec3f b_center = (((cluster[0] + cluster[1]) + cluster[2]) + cluster[3]) / 4.0f;
  float b_radius = 0;
  for (const Vec3f& p : cluster) b_radius = std::max(b_radius, length(b_center - p) + 0.001f);
  const int b_code = spec_sphere_code(table, root_center, root_radius, b_center, b_radius);
  ASSERT_LT(b_code, 1617);  // one cell of the root's grid
  EXPECT_EQ(b_word >> 3, std::uint32_t(b_code));

  // Spec §4.2: B decoded against the root, then its leaves coded against decoded B.
  const auto& [bx, by, bz, br] = table.candidates[std::size_t(b_word >> 3)];
  const Vec3f decoded_b{root_center.x + root_radius * bx, root_center.y + root_radius * by,
                        root_center.z + root_radius * bz};
  const float decoded_b_radius = root_radius * br;
  for (std::size_t i = 0; i < 4; ++i) {
    const int code = spec_sphere_code(table, decoded_b, decoded_b_radius, cluster[i], 0.001f);
    // The first leaf is the case under test; the others are ordinary codes.
    if (i == 0) {
      ASSERT_EQ(code, kOutOfTable);
    } else {
      ASSERT_LT(code, 7621);
    }
    // Word 0 of a leaf: sphere code << 3, grandchild bit 0, child-count code 0.
    EXPECT_EQ(be16(b, 52 + 4 * i), std::uint32_t(code) << 3) << "leaf " << i;
  }
  EXPECT_EQ(b[52], 0xff);
  EXPECT_EQ(b[53], 0xf8);
}

TEST(QsOutOfTableCode, ReaderDecodesItAsTheParentCentreWithRadiusZero) {
  pointillist::testing::TempDir dir;
  const std::string path = dir.file("corner.qs");
  write_qs(path, corner_cluster(), {.write_comments = false});
  const QsModel m = read_qs(path);
  EXPECT_EQ(m.tree.leaf_count, 5u);
  // Nodes: root, A, B, then B's leaves; the first is the one with code 8191, decoded as QSplat
  // 1.0's viewer does (table memory past the end is zero).
  ASSERT_EQ(m.tree.nodes.size(), 7u);
  const SphereNode& b_node = m.tree.nodes[2];
  ASSERT_EQ(b_node.child_count, 4u);
  const SphereNode& leaf = m.tree.nodes[b_node.first_child];
  EXPECT_EQ(leaf.radius, 0.0f);
  EXPECT_EQ(leaf.center, b_node.center);
  EXPECT_NE(m.metadata().find("1 with the out-of-table sphere code"), std::string::npos)
      << m.metadata();

  // Only 8191 is QSplat's marker: the codes between the table's end and it are still corrupt.
  Bytes b = read_bytes(path);
  b[52] = std::uint8_t(8190 >> 5);
  b[53] = std::uint8_t((8190 & 31) << 3);
  write_bytes(path, b);
  try {
    read_qs(path);
    ADD_FAILURE() << "no error for sphere code 8190";
  } catch (const FormatError& e) {
    EXPECT_NE(std::string(e.what()).find(path + ": byte 52: sphere code 8190 is outside the table"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace pointillist
