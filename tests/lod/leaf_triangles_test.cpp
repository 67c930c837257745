// Faces renumbered onto a hierarchy's leaves (leaf_triangles), checked by position: each corner
// of a renumbered face must be the leaf at the point the input face names.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <string>

#include "lod/sphere_points.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/lod/sphere_tree.hpp"

namespace pointillist {
namespace {

// `count` faces of random corners among `points` points (leaf_triangles needs no real mesh).
std::vector<std::array<std::uint32_t, 3>> random_faces(std::size_t count, std::uint32_t points) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<std::uint32_t> corner(0, points - 1);
  std::vector<std::array<std::uint32_t, 3>> faces(count);
  for (auto& f : faces) f = {corner(rng), corner(rng), corner(rng)};
  return faces;
}

// True when the leaves of `tree` lie at more than one depth, so that their node (breadth-first)
// order differs from their depth-first order.
bool leaves_at_several_depths(const SphereTree& tree) {
  std::vector<std::uint32_t> depth(tree.nodes.size(), 0);
  std::uint32_t shallowest = ~0u, deepest = 0;
  for (std::size_t i = 0; i < tree.nodes.size(); ++i) {
    const SphereNode& node = tree.nodes[i];
    for (std::uint32_t c = 0; c < node.child_count; ++c) depth[node.first_child + c] = depth[i] + 1;
    if (node.child_count != 0) continue;
    shallowest = std::min(shallowest, depth[i]);
    deepest = std::max(deepest, depth[i]);
  }
  return shallowest < deepest;
}

// Leaves at two depths (150,000 points give them), so that the depth-first order of the split
// differs from the leaves' node order; the tree built on one thread and on two.
TEST(LeafTriangles, EveryCornerIsTheLeafOfItsPoint) {
  const PointSet points = testing::sphere_points(150000, 3);
  const auto faces = random_faces(200000, 150000);
  for (const unsigned threads : {1u, 2u}) {
    ThreadPool pool(threads);
    std::vector<std::uint32_t> order;
    const SphereTree tree = build_sphere_tree(points, pool, Progress::none(), {}, &order);
    ASSERT_TRUE(leaves_at_several_depths(tree));
    const auto leaf_faces = leaf_triangles(tree.view(), order, faces);
    const PointSet leaves = sphere_tree_leaves(tree.view());
    ASSERT_EQ(leaf_faces.size(), faces.size());
    for (std::size_t t = 0; t < faces.size(); ++t) {
      for (int k = 0; k < 3; ++k) {
        ASSERT_LT(leaf_faces[t][k], leaves.size());
        ASSERT_EQ(leaves.positions[leaf_faces[t][k]], points.positions[faces[t][k]])
            << "face " << t << " corner " << k << ", " << threads << " threads";
      }
    }
  }
}

TEST(LeafTriangles, TheFirstFaceBeyondThePointsIsNamed) {
  const PointSet points = testing::sphere_points(2000, 4);
  auto faces = random_faces(200000, 2000);
  faces[150000][1] = 2000;
  faces[90000][2] = 2500;  // the first of the two
  ThreadPool pool(2);
  std::vector<std::uint32_t> order;
  const SphereTree tree = build_sphere_tree(points, pool, Progress::none(), {}, &order);
  try {
    leaf_triangles(tree.view(), order, faces);
    FAIL() << "no error for faces beyond the points";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("face 90000 refers to point 2500 of 2000"),
              std::string::npos)
        << e.what();
  }
  // A split order that does not match the tree's leaves.
  order.pop_back();
  EXPECT_THROW(leaf_triangles(tree.view(), order, faces), Error);
}

}  // namespace
}  // namespace pointillist
