// The hybrid point/polygon mode from the command line: a mesh converted to .ptl keeps its faces
// and renders hybrid; --no-faces and point clouds are refused with a message naming the file.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "cli/cli_run.hpp"
#include "testing/testing.hpp"

using pointillist::testing::run_cli;
using ::testing::HasSubstr;

namespace {

// An ASCII PLY of a wavy n × n grid mesh.
std::string grid_ply(int n) {
  std::ostringstream s;
  s << "ply\nformat ascii 1.0\nelement vertex " << n * n
    << "\nproperty float x\nproperty float y\nproperty float z\nelement face "
    << 2 * (n - 1) * (n - 1) << "\nproperty list uchar int vertex_indices\nend_header\n";
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      s << x * 0.05f << " " << y * 0.05f << " " << 0.1f * std::sin(0.4f * x) * std::cos(0.3f * y)
        << "\n";
    }
  }
  for (int y = 0; y + 1 < n; ++y) {
    for (int x = 0; x + 1 < n; ++x) {
      const int i = y * n + x;
      s << "3 " << i << " " << i + 1 << " " << i + n + 1 << "\n";
      s << "3 " << i << " " << i + n + 1 << " " << i + n << "\n";
    }
  }
  return s.str();
}

}  // namespace

TEST(HybridCli, ConvertedMeshKeepsItsFacesAndRendersHybrid) {
  pointillist::testing::TempDir dir;
  const auto ply = dir.file("grid.ply"), ptl = dir.file("grid.ptl"), bare = dir.file("bare.ptl");
  std::ofstream(ply) << grid_ply(40);
  ASSERT_EQ(run_cli("convert " + ply + " -o " + ptl).exit_code, 0);
  const auto info = run_cli("info " + ptl);
  EXPECT_THAT(info.output, HasSubstr("3042 triangles"));
  EXPECT_THAT(info.output, HasSubstr("with the mesh's faces"));
  const auto stats = dir.file("stats.json"), png = dir.file("h.png");
  const auto r = run_cli("render " + ptl + " --lod spt --hybrid --distance 0.5 --size 160x120 -o " +
                         png + " --stats " + stats);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream in(stats);
  const std::string json((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_THAT(json, HasSubstr("\"hybrid\": true"));
  EXPECT_THAT(json, ::testing::Not(HasSubstr("\"triangles\": 0,")));

  ASSERT_EQ(run_cli("convert " + ply + " -o " + bare + " --no-faces").exit_code, 0);
  const auto refused = run_cli("render " + bare + " --lod spt --hybrid -o " + png);
  EXPECT_NE(refused.exit_code, 0);
  EXPECT_THAT(refused.output, HasSubstr("bare.ptl"));
  EXPECT_THAT(refused.output, HasSubstr("--hybrid"));
}

TEST(HybridCli, NeedsTheSequentialPointTree) {
  pointillist::testing::TempDir dir;
  const auto ply = dir.file("grid.ply");
  std::ofstream(ply) << grid_ply(10);
  const auto r = run_cli("render " + ply + " --hybrid -o " + dir.file("x.png"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_THAT(r.output, HasSubstr("--lod spt"));
}
