// The sharp-features section of .ptl version 2: what is read back is what was written (the
// oracle: the TreeFeatures the test computed), files without it still load, and a damaged
// section fails with the file, the byte and what is wrong.
#include <gtest/gtest.h>

#include <bit>
#include <filesystem>
#include <fstream>
#include <map>
#include <tuple>

#include "pointillist/core/error.hpp"
#include "pointillist/format/ptl_v2.hpp"
#include "pointillist/format/ptl_v2_pages.hpp"
#include "pointillist/lod/pages.hpp"
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

// The cube written in small pages, and the features of the leaves as that file decodes them
// (as convert --features computes them), stored in a second file at `path` (the tree
// re-quantized once more, with the same node order).
struct Stored {
  SphereTree decoded;  // the first file's tree
  TreeFeatures features;
};
Stored write_cube_with_features(const std::string& path, ThreadPool& pool) {
  write_ptl_v2(path, cube_tree(pool), "", {.page_bytes = 1024});
  Stored out;
  out.decoded = PtlV2File::open(path)->decode_all();
  out.features = compute_tree_features(out.decoded.view(), pool);
  write_ptl_v2(path, out.decoded, "", {.page_bytes = 1024, .features = &out.features});
  return out;
}

// The size of the features section (header bytes 240..247; the section ends the file).
std::uint64_t section_size(const std::string& file) {
  std::uint64_t size = 0;
  for (int i = 0; i < 8; ++i) size |= std::uint64_t(std::uint8_t(file[240 + i])) << (8 * i);
  return size;
}

// The message of the FormatError `f` throws; fails the test when it throws none.
template <class F>
std::string format_error(F&& f, const char* what) {
  try {
    f();
  } catch (const FormatError& e) {
    return e.what();
  }
  ADD_FAILURE() << what;
  return {};
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
  // The per-node form built from it equals the one written, and so does the one decode_all
  // gathers from the pages' blocks (inner nodes' ids included).
  const TreeFeatures back = tree_features(file->decode_all().nodes, *read);
  EXPECT_EQ(back.surface, f.surface);
  EXPECT_EQ(back.clip_offset, f.clip_offset);
  TreeFeatures paged;
  (void)file->decode_all(&paged);
  EXPECT_EQ(paged.surface, f.surface);
  EXPECT_EQ(paged.clip_offset, f.clip_offset);
  EXPECT_EQ(paged.clip_mode, f.clip_mode);
  EXPECT_EQ(paged.surface_count, f.surface_count);
  ASSERT_EQ(paged.clip_planes.size(), f.clip_planes.size());
  for (std::size_t p = 0; p < f.clip_planes.size(); ++p) {
    EXPECT_EQ(paged.clip_planes[p].n, f.clip_planes[p].n);
    EXPECT_EQ(paged.clip_planes[p].h, f.clip_planes[p].h);
  }
}

TEST(PtlV2Features, EveryPageCarriesItsNodesFeatures) {
  // Small pages, so the cube spreads over many: each page's block, loaded with the page, holds
  // the features of exactly the nodes the page holds (matched by decoding the page's nodes
  // against the tree's: page records in page order are tree nodes, found by their spheres).
  ThreadPool pool(2);
  pointillist::testing::TempDir dir;
  const std::string path = dir.file("cube.ptl");
  const auto [decoded, f] = write_cube_with_features(path, pool);
  const auto file = PtlV2File::open(path);
  ASSERT_TRUE(file->page_features_stored());
  ASSERT_GT(file->page_count(), 8u);
  // Tree node by its decoded sphere and normal; the few that two nodes share (an only child
  // decodes as its parent) are left out.
  using Key = std::tuple<float, float, float, float, float, float, float>;
  const auto key = [](const SphereNode& n) {
    return Key{n.center.x, n.center.y, n.center.z, n.radius, n.normal.x, n.normal.y, n.normal.z};
  };
  // (Node k of the file is node k of `decoded`, quantized once more.)
  const SphereTree stored = file->decode_all();
  ASSERT_EQ(stored.nodes.size(), decoded.nodes.size());
  std::map<Key, std::size_t> by_sphere;
  std::map<Key, int> uses;
  for (std::size_t k = 0; k < stored.nodes.size(); ++k) {
    by_sphere[key(stored.nodes[k])] = k;
    ++uses[key(stored.nodes[k])];
  }
  ASSERT_GT(by_sphere.size(), decoded.nodes.size() * 99 / 100);
  std::size_t matched = 0;
  const auto source = ptl_v2_page_source(*file);
  ASSERT_NE(source->features(), nullptr);
  EXPECT_EQ(source->features()->surface_count, f.surface_count);
  std::size_t clipped = 0;
  for (std::uint32_t p = 0; p < file->page_count(); ++p) {
    PtlV2Page page;
    file->decode_page(p, page);
    HierarchyPage loaded;
    source->load(p, loaded);
    ASSERT_EQ(loaded.features.surface.size(), page.nodes.size()) << "page " << p;
    for (std::uint32_t r = 0; r < page.nodes.size(); ++r) {
      const SphereNode& n = page.nodes[r];
      if (uses.at(key(n)) != 1) continue;
      const std::size_t k = by_sphere.at(key(n));
      ++matched;
      EXPECT_EQ(loaded.features.surface[r], f.surface[k]) << "page " << p << " record " << r;
      ClipMode mode;
      const auto got = loaded.features.planes_of(r, mode);
      ASSERT_EQ(got.size(), f.planes(k).size()) << "page " << p << " record " << r;
      EXPECT_EQ(mode, f.clip_mode[k]);
      clipped += !got.empty();
    }
    EXPECT_GE(loaded.memory_bytes(), source->page_memory_bytes(p) / 4);
    EXPECT_LE(loaded.memory_bytes(), source->page_memory_bytes(p));
  }
  EXPECT_GT(matched, decoded.nodes.size() * 98 / 100);
  EXPECT_GT(clipped, f.stats.clipped * 9 / 10);
  // Without features wanted, pages carry none.
  HierarchyPage plain;
  ptl_v2_page_source(*file, false)->load(0, plain);
  EXPECT_TRUE(plain.features.empty());
}

TEST(PtlV2Features, APagesFirstLevelsCarryTheFeaturesOfTheirNodes) {
  // A page loaded in part (PagePrefix) carries the features of the nodes it holds: those of the
  // whole page's load (checked against the tree above) cut to its records.
  ThreadPool pool(2);
  pointillist::testing::TempDir dir;
  const std::string path = dir.file("cube.ptl");
  write_cube_with_features(path, pool);
  const auto file = PtlV2File::open(path);
  const auto source = ptl_v2_page_source(*file);
  std::size_t partial = 0, clipped = 0;
  for (std::uint32_t p = 1; p < file->page_count(); ++p) {
    HierarchyPage whole;
    source->load(p, whole);
    for (std::uint32_t extra = 0; extra + 1 < file->page_info(p).level_count; ++extra) {
      HierarchyPage part;
      source->load(p, part, {.node = 0, .extra_levels = extra});
      const std::uint32_t n = part.node_count();
      ASSERT_LT(n, whole.node_count());
      ++partial;
      ASSERT_EQ(part.features.surface.size(), n);
      for (std::uint32_t r = 0; r < n; ++r) {
        EXPECT_EQ(part.features.surface[r], whole.features.surface[r]);
        ClipMode mode_part, mode_whole;
        const auto a = part.features.planes_of(r, mode_part);
        const auto b = whole.features.planes_of(r, mode_whole);
        ASSERT_EQ(a.size(), b.size()) << "page " << p << " record " << r;
        EXPECT_EQ(mode_part, mode_whole);
        for (std::size_t k = 0; k < a.size(); ++k) {
          EXPECT_EQ(a[k].n, b[k].n);
          EXPECT_EQ(a[k].h, b[k].h);
        }
        clipped += !a.empty();
      }
      EXPECT_LE(part.memory_bytes(), whole.memory_bytes());
    }
  }
  EXPECT_GT(partial, 4u);
  EXPECT_GT(clipped, 0u);
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

// The section as Pointillist wrote it before page blocks (version 1, docs/ptl-format.md): the
// fixed fields, then the leaves' surface ids as runs and the clipped leaves, in node order.
std::string version1_section(const SphereTree& tree, const TreeFeatures& f) {
  std::string out;
  const auto u8 = [&](unsigned v) { out.push_back(static_cast<char>(v)); };
  const auto u32 = [&](std::uint32_t v) {
    for (int i = 0; i < 4; ++i) u8((v >> (8 * i)) & 0xff);
  };
  const auto u64 = [&](std::uint64_t v) {
    for (int i = 0; i < 8; ++i) u8((v >> (8 * i)) & 0xff);
  };
  const auto f32 = [&](float v) { u32(std::bit_cast<std::uint32_t>(v)); };
  out = "PTLF";
  u32(1);
  f32(f.options.sharp_threshold);
  f32(f.options.radius_scale);
  u8(static_cast<unsigned>(f.options.edge_test));
  u8(static_cast<unsigned>(f.options.clip_rule));
  u8(0), u8(0);
  u32(f.surface_count);
  u64(tree.leaf_count);
  const FeatureStats& st = f.stats;
  for (std::uint64_t v : {st.splats, st.edges, st.sharp_edges, st.crossing_edges,
                          st.antiparallel_edges, st.candidates, st.clipped, st.pass_through,
                          st.undefined_4_15, st.nearest_rule, st.capped, st.segments,
                          st.large_segments}) {
    u64(v);
  }
  for (int k = 1; k <= kMaxClipPlanes; ++k) u64(st.plane_histogram[k]);
  std::vector<std::pair<std::uint32_t, std::uint32_t>> runs;
  std::vector<std::size_t> clipped;
  std::uint32_t leaf = 0;
  for (std::size_t k = 0; k < tree.nodes.size(); ++k) {
    if (tree.nodes[k].child_count != 0) continue;
    if (!runs.empty() && runs.back().first == f.surface[k]) {
      ++runs.back().second;
    } else {
      runs.push_back({f.surface[k], 1});
    }
    if (!f.planes(k).empty()) clipped.push_back(k);
    ++leaf;
  }
  u64(runs.size());
  for (const auto& [id, n] : runs) u32(id), u32(n);
  u64(clipped.size());
  leaf = 0;
  for (std::size_t k = 0; k < tree.nodes.size(); ++k) {
    if (tree.nodes[k].child_count != 0) continue;
    if (!f.planes(k).empty()) {
      u32(leaf);
      u8(static_cast<unsigned>(f.planes(k).size()) | static_cast<unsigned>(f.clip_mode[k]) << 5);
      for (const ClipPlane& p : f.planes(k)) f32(p.n.x), f32(p.n.y), f32(p.n.z), f32(p.h);
    }
    ++leaf;
  }
  return out;
}

TEST(PtlV2Features, FilesOfTheFirstSectionVersionStillLoad) {
  ThreadPool pool(2);
  pointillist::testing::TempDir dir;
  const std::string path = dir.file("cube.ptl");
  const TreeFeatures f = write_cube_with_features(path, pool).features;
  // Swap the section (the file's last bytes) for a version 1 one, and its size in the header.
  std::string bytes = read_all(path);
  const std::uint64_t size = section_size(bytes);
  const SphereTree stored = PtlV2File::open(path)->decode_all();
  const std::string old = version1_section(stored, f);
  bytes = bytes.substr(0, bytes.size() - size) + old;
  for (int i = 0; i < 8; ++i) bytes[240 + i] = static_cast<char>((old.size() >> (8 * i)) & 0xff);
  write_all(path, bytes);

  const auto file = PtlV2File::open(path);
  ASSERT_TRUE(file->has_features());
  EXPECT_FALSE(file->page_features_stored());
  TreeFeatures back;
  (void)file->decode_all(&back);
  EXPECT_EQ(back.surface, f.surface);
  EXPECT_EQ(back.clip_offset, f.clip_offset);
  EXPECT_EQ(back.clip_mode, f.clip_mode);
  EXPECT_EQ(file->features()->surface_id.size(), stored.leaf_count);
  // Their pages carry none (the renderer then draws the paged model without them).
  const auto source = ptl_v2_page_source(*file);
  EXPECT_EQ(source->features(), nullptr);
  HierarchyPage page;
  source->load(0, page);
  EXPECT_TRUE(page.features.empty());
}

TEST(PtlV2Features, ADamagedSectionNamesTheByte) {
  ThreadPool pool(1);
  const SphereTree tree = cube_tree(pool);
  const TreeFeatures f = compute_tree_features(tree.view(), pool);
  pointillist::testing::TempDir dir;
  const std::string path = dir.file("cube.ptl");
  write_ptl_v2(path, tree, "", {.features = &f});
  const std::string good = read_all(path);
  const std::uint32_t pages = PtlV2File::open(path)->page_count();
  // Page 0's block follows the fixed fields (264 bytes), the page count and the block table
  // (16 bytes a page, and one more);
  // its first run's surface id (after the run count) set past the surface count.
  const std::size_t section = good.size() - section_size(good);
  const std::size_t first_id = section + 264 + 8 + 16 * (pages + 1) + 4;
  std::string bad = good;
  bad[first_id + 3] = '\x7f';
  write_all(path, bad);
  const std::string m = format_error([&] { (void)PtlV2File::open(path)->features(); },
                                     "a damaged features section was read");
  EXPECT_NE(m.find(path + ": byte " + std::to_string(first_id)), std::string::npos) << m;
  EXPECT_NE(m.find("surface id"), std::string::npos) << m;
  // The same damage found when the page is loaded for paged rendering.
  {
    const auto file = PtlV2File::open(path);
    const auto source = ptl_v2_page_source(*file);
    HierarchyPage page;
    const std::string loaded =
        format_error([&] { source->load(0, page); }, "a damaged page block was loaded");
    EXPECT_NE(loaded.find("byte " + std::to_string(first_id)), std::string::npos) << loaded;
  }
  // A block table entry out of order is refused with the byte of the entry.
  bad = good;
  const std::size_t entry1 = section + 264 + 8 + 16;
  bad[entry1 + 7] = '\x01';
  write_all(path, bad);
  const std::string table = format_error([&] { (void)PtlV2File::open(path)->features(); },
                                         "a damaged block table was read");
  EXPECT_NE(table.find("byte " + std::to_string(entry1)), std::string::npos) << table;
  // A section that runs past the end of the file is refused on opening.
  write_all(path, good.substr(0, good.size() - 10));
  EXPECT_THROW(PtlV2File::open(path), FormatError);
}

}  // namespace
