// The sharp-features section of .ptl version 2: what is read back is what was written (the
// oracle: the TreeFeatures the test computed), files without it still load, and a damaged
// section fails with the file, the byte and what is wrong.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "pointillist/core/error.hpp"
#include "pointillist/format/ptl_v2.hpp"
#include "pointillist/lod/tree_features.hpp"
#include "pointillist/prep/radii.hpp"
#include "pointillist/scene/csg.hpp"
#include "testing/testing.hpp"

using namespace pointillist;

namespace {

SphereTree cube_tree(ThreadPool& pool) {
  CsgScene cube = csg_scene("T1");
  cube.spacing = 0.1f;
  CsgSamples s = sample_csg(cube, SamplingMode::Jittered, 3);
  CloudRadiusOptions radius;
  radius.coverage = 1.0f;
  s.points.radii = cloud_radii(s.points.positions, pool, Progress::none(), radius);
  return build_sphere_tree(s.points, pool);
}

std::string read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}
void write_all(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

TEST(PtlV2Features, WhatIsReadIsWhatWasWritten) {
  ThreadPool pool(2);
  const SphereTree tree = cube_tree(pool);
  const TreeFeatures f = compute_tree_features(tree.view(), pool);
  ASSERT_GT(f.stats.clipped, 50u);
  pointillist::testing::TempDir dir;
  const std::string path = dir.file("cube.ptl");
  write_ptl_v2(path, tree, "", {.features = &f});
  const auto file = PtlV2File::open(path);
  ASSERT_TRUE(file->has_features());
  const std::optional<FeatureData> read = file->features();
  ASSERT_TRUE(read);
  // Per leaf, in node order.
  std::size_t leaf = 0;
  for (std::size_t k = 0; k < tree.nodes.size(); ++k) {
    if (tree.nodes[k].child_count != 0) continue;
    ASSERT_EQ(read->surface_id[leaf], f.surface[k]) << "leaf " << leaf;
    ASSERT_EQ(read->clip_mode[leaf], f.clip_mode[k]) << "leaf " << leaf;
    const auto want = f.planes(k), got = read->planes(leaf);
    ASSERT_EQ(got.size(), want.size()) << "leaf " << leaf;
    for (std::size_t p = 0; p < want.size(); ++p) {
      EXPECT_EQ(got[p].n, want[p].n);
      EXPECT_EQ(got[p].h, want[p].h);
    }
    ++leaf;
  }
  EXPECT_EQ(read->stats.clipped, f.stats.clipped);
  EXPECT_EQ(read->stats.segments, f.stats.segments);
  EXPECT_EQ(read->options.sharp_threshold, f.options.sharp_threshold);
  // The per-node form built from it equals the one written.
  const TreeFeatures back = tree_features(file->decode_all().nodes, *read);
  EXPECT_EQ(back.surface, f.surface);
  EXPECT_EQ(back.clip_offset, f.clip_offset);
}

TEST(PtlV2Features, FilesWithoutThemStillLoadAndKeepTheirBytes) {
  ThreadPool pool(1);
  const SphereTree tree = cube_tree(pool);
  pointillist::testing::TempDir dir;
  write_ptl_v2(dir.file("plain.ptl"), tree, "m");
  const auto file = PtlV2File::open(dir.file("plain.ptl"));
  EXPECT_FALSE(file->has_features());
  EXPECT_FALSE(file->features());
  // The section is appended: the file without it is a prefix, byte for byte, but for the header.
  const TreeFeatures f = compute_tree_features(tree.view(), pool);
  write_ptl_v2(dir.file("with.ptl"), tree, "m", {.features = &f});
  const std::string a = read_all(dir.file("plain.ptl")), b = read_all(dir.file("with.ptl"));
  ASSERT_GT(b.size(), a.size());
  EXPECT_EQ(b.substr(256, a.size() - 256), a.substr(256));
}

TEST(PtlV2Features, ADamagedSectionNamesTheByte) {
  ThreadPool pool(1);
  const SphereTree tree = cube_tree(pool);
  const TreeFeatures f = compute_tree_features(tree.view(), pool);
  pointillist::testing::TempDir dir;
  const std::string path = dir.file("cube.ptl");
  write_ptl_v2(path, tree, "", {.features = &f});
  const std::string good = read_all(path);
  // The first run's surface id (section byte 272) set past the surface count.
  const std::size_t section = good.size() - [&] {
    std::uint64_t size = 0;
    for (int i = 0; i < 8; ++i) size |= std::uint64_t(std::uint8_t(good[240 + i])) << (8 * i);
    return size;
  }();
  std::string bad = good;
  bad[section + 272 + 3] = '\x7f';
  write_all(path, bad);
  try {
    (void)PtlV2File::open(path)->features();
    FAIL() << "a damaged features section was read";
  } catch (const FormatError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find(path + ": byte " + std::to_string(section + 272)), std::string::npos) << m;
    EXPECT_NE(m.find("surface id"), std::string::npos) << m;
  }
  // A section that runs past the end of the file is refused on opening.
  write_all(path, good.substr(0, good.size() - 10));
  EXPECT_THROW(PtlV2File::open(path), FormatError);
}

}  // namespace
