// The cut of a sphere tree at one node size (what QSplat draws under a view-independent
// threshold): every leaf is stood for by exactly one node of the cut, every node of the cut is
// at most the cut's size or a leaf under a larger parent (checked by walking the tree from the
// root independently), and the size is chosen for the count asked for.
#include <gtest/gtest.h>

#include <map>

#include "pointillist/lod/sphere_tree.hpp"
#include "sphere_points.hpp"

using namespace pointillist;

TEST(SphereTreeCut, StandsForEveryLeafOnceAtOneSize) {
  PointSet pts = pointillist::testing::sphere_points(20000, 9, true);
  ThreadPool pool(2);
  const SphereTree tree = build_sphere_tree(pts, pool);
  for (std::size_t target : {1u, 50u, 1000u, 7000u, 20000u}) {
    const PointSet cut = sphere_tree_cut(tree, target);
    SCOPED_TRACE(target);
    ASSERT_EQ(cut.radii.size(), cut.size());
    ASSERT_EQ(cut.colors.size(), cut.size());
    EXPECT_NEAR(double(cut.size()), double(target), 0.02 * double(target) + 4);
    // The cut's size: the largest radius among its interior nodes, or any leaf's; every node
    // of the tree is in the cut, above it (radius > size, not a leaf) or below one node of it.
    float size = 0;
    std::map<std::tuple<float, float, float, float>, int> in_cut;
    for (std::size_t i = 0; i < cut.size(); ++i) {
      ++in_cut[{cut.positions[i].x, cut.positions[i].y, cut.positions[i].z, cut.radii[i]}];
    }
    std::size_t leaves_covered = 0;
    std::vector<std::pair<std::uint32_t, bool>> stack = {{0, false}};  // (node, under the cut)
    while (!stack.empty()) {
      const auto [i, under] = stack.back();
      stack.pop_back();
      const SphereNode& n = tree.nodes[i];
      // Each output is consumed by the first node it matches from the root down (an interior
      // node with one point below it has that point's own sphere).
      auto found = in_cut.find({n.center.x, n.center.y, n.center.z, n.radius});
      const bool here = !under && found != in_cut.end() && found->second > 0;
      if (here) --found->second;
      if (!under && !here) {
        EXPECT_GT(n.child_count, 0) << "a leaf with no node of the cut above";
      }
      if (here && n.child_count > 0) size = std::max(size, n.radius);
      if (n.child_count == 0 && (under || here)) ++leaves_covered;
      for (std::uint32_t c = 0; c < n.child_count; ++c) stack.push_back({n.first_child + c, under || here});
    }
    EXPECT_EQ(leaves_covered, 20000u);
    for (const auto& [key, left] : in_cut) EXPECT_EQ(left, 0) << "a node of the cut under another";
    // Above the cut, every node is larger than every interior node in it.
    for (std::size_t i = 0; i < cut.size(); ++i) {
      ++in_cut[{cut.positions[i].x, cut.positions[i].y, cut.positions[i].z, cut.radii[i]}];
    }
    stack = {{0, false}};
    while (!stack.empty()) {
      const auto [i, unused] = stack.back();
      stack.pop_back();
      const SphereNode& n = tree.nodes[i];
      if (in_cut[{n.center.x, n.center.y, n.center.z, n.radius}] > 0) continue;
      EXPECT_GT(n.radius, size);
      for (std::uint32_t c = 0; c < n.child_count; ++c) stack.push_back({n.first_child + c, false});
    }
  }
}
