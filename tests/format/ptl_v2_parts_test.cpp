// .ptl version 2 written in parts (PtlV2PartWriter): subtrees built apart below a common top.
// Oracles: the input splats (every one must be held by a decoded leaf), the format's nesting
// rule, the structure a reader checks, and the same splats written whole (rendered images).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <vector>

#include "format/format_test_support.hpp"
#include "lod/sphere_points.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/format/ptl_v2.hpp"
#include "testing/testing.hpp"

namespace pointillist {
namespace {

using testing::TempDir;

double dist(Vec3f a, Vec3f b) {
  const double dx = double(a.x) - b.x, dy = double(a.y) - b.y, dz = double(a.z) - b.z;
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

bool holds(const SphereNode& outer, Vec3f c, float r) {
  return dist(outer.center, c) + double(r) <= double(outer.radius) * (1 + 1e-6);
}

// The points of `all` whose octant around the origin is `octant` (bits: x, y, z positive).
PointSet octant_points(const PointSet& all, int octant) {
  PointSet part;
  for (std::size_t i = 0; i < all.size(); ++i) {
    const Vec3f p = all.positions[i];
    const int o = (p.x > 0) | (p.y > 0) << 1 | (p.z > 0) << 2;
    if (o != octant) continue;
    part.positions.push_back(p);
    part.normals.push_back(all.normals[i]);
    part.radii.push_back(all.radii[i]);
    if (all.has_colors()) part.colors.push_back(all.colors[i]);
  }
  return part;
}

struct Written {
  std::string path;
  std::vector<PointSet> parts;
  PtlV2WriteReport report;
};

// Writes `points` cut into octants (in octant order, so the top groups neighbours), plus one
// subtree of a single point, through a PtlV2PartWriter, to `name` in `dir`. With `joined`, as
// an MPI job does: a second writer joins the first's temporary file and writes the odd subtrees
// and the single point's, and the first adopts what it needs of them.
Written write_in_parts(const TempDir& dir, const PointSet& points, const PtlV2WriteOptions& o,
                       bool joined = false, const std::string& name = "parts.ptl") {
  ThreadPool pool(2);
  Written w{dir.file(name), {}, {}};
  for (int octant = 0; octant < 8; ++octant) w.parts.push_back(octant_points(points, octant));
  PointSet lone;
  lone.positions = {{3, 3, 3}};
  lone.normals = {{0, 0, 1}};
  lone.radii = {0.05f};
  if (points.has_colors()) lone.colors = {{10, 20, 30}};
  w.parts.push_back(lone);
  std::vector<SphereTree> trees;
  std::vector<PtlV2SubtreeSummary> summaries;
  for (const PointSet& part : w.parts) {
    trees.push_back(build_sphere_tree(part, pool));
    summaries.push_back(summarize_ptl_v2_subtree(trees.back(), o));
  }
  PtlV2PartWriter writer(w.path, summaries, points.has_colors(), o);
  const auto joiners = [&](std::size_t k) { return joined && (k % 2 == 1 || k == 8); };
  if (joined) {
    PtlV2PartWriter joiner(w.path, summaries, points.has_colors(), o, writer.temp_path());
    for (std::size_t k = 0; k < trees.size(); ++k) {
      if (joiners(k)) joiner.write_subtree(k, trees[k], pool);
    }
    joiner.sync();
    EXPECT_THROW(joiner.written_part(0), Error);  // not written there
    EXPECT_THROW(joiner.finish({}, {}, {}, {0, 1, 0}, ""), Error);  // the owner's to finish
    for (std::size_t k = 0; k < trees.size(); ++k) {
      if (joiners(k)) writer.adopt_part(k, joiner.written_part(k));
    }
    EXPECT_THROW(writer.adopt_part(0, std::vector<char>(3)), Error);  // wrong size
  }
  // Any order.
  for (std::size_t k = trees.size(); k-- > 0;) {
    if (!joiners(k)) writer.write_subtree(k, trees[k], pool);
  }
  Aabb box = bounding_box(points.positions);
  box.lo = min(box.lo, Vec3f{3, 3, 3});
  box.hi = max(box.hi, Vec3f{3, 3, 3});
  w.report =
      writer.finish(box, {box.center(), length(box.hi - box.center())}, {}, {0, 1, 0}, "parts\n");
  return w;
}

TEST(PtlV2Parts, DecodesWithEverySplatHeldAndEveryChildInsideItsParent) {
  TempDir dir;
  const PointSet points = testing::sphere_points(3000, 7, true);
  const Written w = write_in_parts(dir, points, {.page_bytes = 1024});
  const auto file = PtlV2File::open(w.path);  // checks header, schema and page table
  EXPECT_GT(file->page_count(), 9u);           // small pages: every subtree takes several
  const SphereTree decoded = file->decode_all();  // checks the pages against each other
  EXPECT_EQ(decoded.leaf_count, 3001u);
  EXPECT_EQ(file->metadata(), "parts\n");
  std::vector<SphereNode> leaves;
  std::size_t outside_parent = 0;
  for (const SphereNode& n : decoded.nodes) {
    if (n.child_count == 0) leaves.push_back(n);
    for (std::uint32_t k = 0; k < n.child_count; ++k) {
      const SphereNode& c = decoded.nodes[n.first_child + k];
      if (!holds(n, c.center, c.radius)) ++outside_parent;
    }
  }
  EXPECT_EQ(outside_parent, 0u);
  // Every input splat is held by a decoded leaf (brute force over the 3001 leaves).
  std::size_t unheld = 0;
  for (const PointSet& part : w.parts) {
    for (std::size_t i = 0; i < part.size(); ++i) {
      const bool held = std::any_of(leaves.begin(), leaves.end(), [&](const SphereNode& l) {
        return holds(l, part.positions[i], part.radii[i]);
      });
      if (!held) ++unheld;
    }
  }
  EXPECT_EQ(unheld, 0u);
}

// The subtree of `tree` under node `root`, breadth-first from it.
SphereTree subtree(const SphereTree& tree, std::uint32_t root) {
  SphereTree t;
  t.has_colors = tree.has_colors;
  std::vector<std::uint32_t> queue{root};
  for (std::size_t i = 0; i < queue.size(); ++i) {
    SphereNode n = tree.nodes[queue[i]];
    const std::uint32_t first = n.first_child;
    if (n.child_count > 0) n.first_child = static_cast<std::uint32_t>(queue.size());
    for (std::uint32_t k = 0; k < n.child_count; ++k) queue.push_back(first + k);
    t.nodes.push_back(n);
  }
  return t;
}

// The nodes `levels` levels below the root, left to right.
std::vector<std::uint32_t> level_nodes(const SphereTree& tree, int levels) {
  std::vector<std::uint32_t> level{0};
  for (int l = 0; l < levels; ++l) {
    std::vector<std::uint32_t> next;
    for (const std::uint32_t v : level) {
      for (std::uint32_t k = 0; k < tree.nodes[v].child_count; ++k)
        next.push_back(tree.nodes[v].first_child + k);
    }
    level = next;
  }
  return level;
}

// A hierarchy cut below its top levels and written in parts decodes to the hierarchy written
// whole, node for node and bit for bit (what makes a chunked conversion equal to one in one
// piece).
TEST(PtlV2Parts, SubtreesOfAHierarchyWrittenInPartsDecodeToTheWholeHierarchy) {
  TempDir dir;
  ThreadPool pool(2);
  EXPECT_NE(sphere_tree_root_halves(20000), sphere_tree_root_halves(33000));  // both kinds
  for (const std::size_t count : {20000u, 33000u}) {
    const SphereTree tree = format_test::scene_tree(count, 5, true);
    const std::string whole = dir.file("whole.ptl");
    write_ptl_v2(whole, tree, "m\n", {.page_bytes = 2048});
    const SphereTree expected = PtlV2File::open(whole)->decode_all();
    for (const int levels : {1, 2}) {
      std::vector<SphereTree> parts;
      std::vector<PtlV2SubtreeSummary> summaries;
      for (const std::uint32_t r : level_nodes(tree, levels)) {
        parts.push_back(subtree(tree, r));
        summaries.push_back(summarize_ptl_v2_subtree(parts.back(), {.page_bytes = 2048}));
      }
      const std::string path = dir.file("parts.ptl");
      PtlV2PartWriter writer(path, summaries, true, {.page_bytes = 2048});
      for (std::size_t k = 0; k < parts.size(); ++k) writer.write_subtree(k, parts[k], pool);
      writer.finish(tree.bounds, tree.view_sphere, {}, {0, 1, 0}, "m\n");
      const SphereTree got = PtlV2File::open(path)->decode_all();
      ASSERT_EQ(got.nodes.size(), expected.nodes.size()) << count << " points, " << levels;
      EXPECT_EQ(std::memcmp(got.nodes.data(), expected.nodes.data(),
                            got.nodes.size() * sizeof(SphereNode)),
                0)
          << count << " points, cut " << levels << " levels down";
      EXPECT_EQ(got.depth, expected.depth);
    }
  }
}

TEST(PtlV2Parts, RefusesAWrongSubtreeAndAnUnfinishedFile) {
  TempDir dir;
  ThreadPool pool(1);
  const PointSet a = testing::sphere_points(500, 1), b = testing::sphere_points(600, 2);
  const SphereTree ta = build_sphere_tree(a, pool), tb = build_sphere_tree(b, pool);
  const std::string path = dir.file("x.ptl");
  {
    PtlV2PartWriter writer(path, {summarize_ptl_v2_subtree(ta, {}),
                                  summarize_ptl_v2_subtree(tb, {})}, false);
    EXPECT_THROW(writer.write_subtree(0, tb, pool), Error);
    writer.write_subtree(0, ta, pool);
    EXPECT_THROW(writer.finish({}, {}, {}, {0, 1, 0}, ""), Error);
  }
  EXPECT_FALSE(std::filesystem::exists(path));  // nothing left behind
  for (const auto& entry : std::filesystem::directory_iterator(dir.path())) {
    ADD_FAILURE() << "left behind: " << entry.path();
  }
}

// What an MPI job does (write_in_parts, joined): the file and the report of a single writer.
TEST(PtlV2Parts, AJoiningWriterWritesSubtreesIntoTheOwnersFile) {
  TempDir dir;
  const PointSet points = testing::sphere_points(6000, 4);
  const PtlV2WriteOptions o{.page_bytes = 2048};
  const Written one = write_in_parts(dir, points, o);
  const Written two = write_in_parts(dir, points, o, true, "joined.ptl");
  EXPECT_TRUE(format_test::read_bytes(one.path) == format_test::read_bytes(two.path))
      << "the joined file differs from the one a single writer makes";
  // The statistics travel with the subtrees (written_part, adopt_part).
  EXPECT_EQ(two.report.parent_fallbacks, one.report.parent_fallbacks);
  EXPECT_EQ(two.report.mean_leaf_radius_ratio, one.report.mean_leaf_radius_ratio);
  for (int c = 0; c < 4; ++c) EXPECT_EQ(two.report.cone_codes[c], one.report.cone_codes[c]) << c;
  EXPECT_GT(two.report.mean_leaf_radius_ratio, 1.0);
}

}  // namespace
}  // namespace pointillist
