// The writer's checks of a hierarchy before it encodes anything (check_tree): a tree of a
// quarter of a million nodes with faults placed by hand, where the first fault in node order must
// be the one named, whatever else is wrong after it.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "pointillist/core/error.hpp"
#include "pointillist/core/thread_pool.hpp"
#include "pointillist/format/ptl_v2.hpp"
#include "testing/testing.hpp"

namespace pointillist {
namespace {

using testing::TempDir;

// A complete binary tree of 2^18 - 1 nodes in breadth-first order: node i's children are
// 2i + 1 and 2i + 2, the last level's 2^17 nodes are leaves (depth 17). Leaves lie on a line,
// each parent's sphere holds its children's.
constexpr std::uint32_t kLevels = 18;
constexpr std::uint32_t kNodes = (1u << kLevels) - 1;
constexpr std::uint32_t kFirstLeaf = (1u << (kLevels - 1)) - 1;

SphereTree binary_tree() {
  SphereTree t;
  t.nodes.resize(kNodes);
  for (std::uint32_t i = kNodes; i-- > 0;) {
    SphereNode& n = t.nodes[i];
    n.normal = {0, 0, 1};
    if (i >= kFirstLeaf) {
      n.center = {float(i - kFirstLeaf), 0, 0};
      n.radius = 0.5f;
      continue;
    }
    n.first_child = 2 * i + 1;
    n.child_count = 2;
    const SphereNode& a = t.nodes[2 * i + 1];
    const SphereNode& b = t.nodes[2 * i + 2];
    n.center = (a.center + b.center) * 0.5f;
    n.radius = (b.center.x - a.center.x) * 0.5f + a.radius + 1;
  }
  t.leaf_count = kNodes - kFirstLeaf;
  t.depth = kLevels - 1;
  t.bounds = {{0, 0, 0}, {float(kNodes - kFirstLeaf - 1), 0, 0}};
  t.view_sphere = {t.nodes[0].center, t.nodes[0].radius};
  return t;
}

// The message of writing `tree` on two threads ("" when it is written).
std::string write_error(const SphereTree& tree) {
  TempDir dir;
  ThreadPool pool(2);
  try {
    write_ptl_v2(dir.file("t.ptl"), tree, "", {}, pool);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(PtlV2TreeChecks, AValidTreeOfManyBlocksIsWrittenWithItsLeavesAndDepth) {
  TempDir dir;
  ThreadPool pool(2);
  const PtlV2WriteReport r = write_ptl_v2(dir.file("t.ptl"), binary_tree(), "", {}, pool);
  EXPECT_EQ(r.node_count, kNodes);
  EXPECT_EQ(r.leaf_count, kNodes - kFirstLeaf);
  const auto file = PtlV2File::open(dir.file("t.ptl"));
  EXPECT_EQ(file->depth(), kLevels - 1);
}

TEST(PtlV2TreeChecks, TheFirstBadLinkBeforeABadValueIsNamed) {
  SphereTree t = binary_tree();
  t.nodes[150000].radius = std::numeric_limits<float>::quiet_NaN();  // a later block's leaf
  t.nodes[100000].first_child = 5;                                   // should be 200001
  const std::string m = write_error(t);
  EXPECT_NE(m.find("node 100000 of 262143: first child 5, expected 200001 (children stored "
                   "breadth-first, in range)"),
            std::string::npos)
      << m;
}

TEST(PtlV2TreeChecks, TheFirstBadValueBeforeABadLinkIsNamed) {
  SphereTree t = binary_tree();
  t.nodes[120000].first_child = 7;
  t.nodes[70000].child_count = 5;
  t.nodes[140000].normal.y = std::numeric_limits<float>::infinity();
  EXPECT_NE(write_error(t).find("node 70000 of 262143: child count 5 (must be 0, 2, 3 or 4)"),
            std::string::npos)
      << write_error(t);
  t.nodes[70000].child_count = 2;
  t.nodes[120000].first_child = 2 * 120000 + 1;
  EXPECT_NE(write_error(t).find("node 140000 of 262143: a centre, radius, normal or cone that "
                                "is negative or not finite"),
            std::string::npos)
      << write_error(t);
}

TEST(PtlV2TreeChecks, ChildrenThatNoNodeNamesAreNamed) {
  // The last interior node made a leaf: its two children, the last two nodes, have no parent.
  SphereTree t = binary_tree();
  t.nodes[kFirstLeaf - 1].child_count = 0;
  t.nodes[kFirstLeaf - 1].first_child = 0;
  EXPECT_NE(write_error(t).find("node 262141 is nobody's child"), std::string::npos)
      << write_error(t);
}

}  // namespace
}  // namespace pointillist
