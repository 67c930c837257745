#include "pointillist/lod/sphere_tree.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <map>
#include <numeric>
#include <span>
#include <string>
#include <string_view>
#include <tuple>

#include "lod/sphere_points.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/core/morton.hpp"

namespace pointillist {
namespace {

using testing::box_points;
using testing::sphere_points;

SphereTree build(const PointSet& points, unsigned threads = 2, SphereTreeOptions options = {}) {
  ThreadPool pool(threads);
  return build_sphere_tree(points, pool, Progress::none(), options);
}

// Leaves (node indices) of the subtree under `node`, by explicit traversal.
std::vector<std::uint32_t> subtree_leaves(const SphereTree& t, std::uint32_t node) {
  std::vector<std::uint32_t> out, stack{node};
  while (!stack.empty()) {
    const std::uint32_t i = stack.back();
    stack.pop_back();
    const SphereNode& nd = t.nodes[i];
    if (nd.child_count == 0) out.push_back(i);
    for (std::uint32_t k = 0; k < nd.child_count; ++k) stack.push_back(nd.first_child + k);
  }
  return out;
}

double dist(Vec3f a, Vec3f b) {
  const double dx = double(a.x) - b.x, dy = double(a.y) - b.y, dz = double(a.z) - b.z;
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

double angle_between(Vec3f a, Vec3f b) {
  const double d = (double(a.x) * b.x + double(a.y) * b.y + double(a.z) * b.z) /
                   (dist(a, {}) * dist(b, {}));
  return std::acos(std::clamp(d, -1.0, 1.0));
}

// Map from exact position to input index (random inputs have distinct positions).
std::map<std::tuple<float, float, float>, std::uint32_t> index_by_position(const PointSet& p) {
  std::map<std::tuple<float, float, float>, std::uint32_t> m;
  for (std::uint32_t i = 0; i < p.size(); ++i) {
    m.emplace(std::tuple{p.positions[i].x, p.positions[i].y, p.positions[i].z}, i);
  }
  EXPECT_EQ(m.size(), p.size()) << "test input has duplicate positions";
  return m;
}

std::uint32_t input_index(const std::map<std::tuple<float, float, float>, std::uint32_t>& m,
                          Vec3f p) {
  const auto it = m.find({p.x, p.y, p.z});
  EXPECT_NE(it, m.end());
  return it == m.end() ? ~0u : it->second;
}

TEST(SphereTree, ChildSpheresInsideParents) {
  const PointSet pts = sphere_points(3000, 1);
  const SphereTree t = build(pts);
  for (std::uint32_t i = 0; i < t.nodes.size(); ++i) {
    const SphereNode& p = t.nodes[i];
    for (std::uint32_t k = 0; k < p.child_count; ++k) {
      const SphereNode& c = t.nodes[p.first_child + k];
      EXPECT_LE(dist(p.center, c.center) + c.radius, p.radius * (1 + 1e-6))
          << "node " << i << " child " << k;
    }
  }
  // Direct check (not only parent by parent): every splat inside every ancestor.
  for (std::uint32_t i = 0; i < t.nodes.size(); i += 7) {
    for (std::uint32_t leaf : subtree_leaves(t, i)) {
      const SphereNode& l = t.nodes[leaf];
      EXPECT_LE(dist(t.nodes[i].center, l.center) + l.radius, t.nodes[i].radius * (1 + 1e-6));
    }
  }
}

// Oracle for the smallest sphere enclosing a few spheres: Badoiu–Clarkson iterations (step
// 1/(t+1) towards the farthest point), keeping the best radius seen. Every value is the radius of
// a true enclosing sphere, so it is an upper bound on the optimum that approaches it.
double enclosing_radius_oracle(std::span<const SphereNode> balls) {
  double c[3] = {balls[0].center.x, balls[0].center.y, balls[0].center.z};
  double best = INFINITY;
  for (int t = 1; t <= 8000; ++t) {
    double far_r = -1, far_d[3] = {0, 0, 0}, far_len = 0;
    for (const SphereNode& b : balls) {
      const double d[3] = {b.center.x - c[0], b.center.y - c[1], b.center.z - c[2]};
      const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
      if (len + b.radius > far_r) {
        far_r = len + b.radius;
        far_len = len;
        std::copy(d, d + 3, far_d);
      }
    }
    best = std::min(best, far_r);
    const double s = far_len > 0 ? far_r / far_len : 0;
    for (int a = 0; a < 3; ++a) c[a] += far_d[a] * s / (t + 1);
  }
  return best;
}

TEST(SphereTree, InteriorSpheresAreMinimal) {
  for (const PointSet& pts : {sphere_points(250, 2, false, 1.0f, 0.01f, {3, -2, 5}),
                              box_points(250, 2, {1, 2, 3})}) {
    const SphereTree t = build(pts);
    for (std::uint32_t i = 0; i < t.nodes.size(); ++i) {
      const SphereNode& p = t.nodes[i];
      if (p.child_count == 0) continue;
      const double oracle = enclosing_radius_oracle({&t.nodes[p.first_child], p.child_count});
      EXPECT_LE(p.radius, oracle * (1 + 1e-5)) << "node " << i;
    }
  }
}

TEST(SphereTree, ChildNormalsInsideParentCones) {
  const PointSet pts = sphere_points(4000, 3);
  const SphereTree t = build(pts);
  const double tol = 1e-5;
  std::size_t bounded = 0, interior = 0;
  for (std::uint32_t i = 0; i < t.nodes.size(); ++i) {
    const SphereNode& p = t.nodes[i];
    if (p.child_count == 0) {
      EXPECT_EQ(p.cone_sin, 0.0f);
      continue;
    }
    ++interior;
    EXPECT_NEAR(dist(p.normal, {}), 1.0, 1e-5) << "node " << i;
    if (p.cone_sin >= 1) continue;
    ++bounded;
    const double theta = std::asin(double(p.cone_sin));
    for (std::uint32_t k = 0; k < p.child_count; ++k) {
      const SphereNode& c = t.nodes[p.first_child + k];
      ASSERT_LT(c.cone_sin, 1.0f) << "a bounded cone cannot hold an unbounded one";
      const double theta_c = std::asin(double(c.cone_sin));
      EXPECT_LE(angle_between(p.normal, c.normal), theta - theta_c + tol)
          << "node " << i << " child " << k;
    }
    for (std::uint32_t leaf : subtree_leaves(t, i)) {
      EXPECT_LE(angle_between(p.normal, t.nodes[leaf].normal), theta + tol);
    }
  }
  // On a smooth sphere the small subtrees have narrow cones; the root cannot have one.
  EXPECT_GT(bounded, interior * 9 / 10);
  EXPECT_GE(t.nodes[0].cone_sin, 1.0f);
}

TEST(SphereTree, OppositeNormalsGiveNoConeBound) {
  PointSet pts;
  pts.positions = {{0, 0, 0}, {1, 0, 0}};
  pts.normals = {{0, 1, 0}, {0, -1, 0}};
  pts.radii = {0.1f, 0.1f};
  const SphereTree t = build(pts);
  ASSERT_EQ(t.nodes.size(), 3u);
  EXPECT_GE(t.nodes[0].cone_sin, 1.0f);
  EXPECT_NEAR(dist(t.nodes[0].normal, {}), 1.0, 1e-6);
  // Two splats 1 apart with radius 0.1: the enclosing sphere is centred between them, radius 0.6.
  EXPECT_NEAR(t.nodes[0].radius, 0.6, 1e-6);
  EXPECT_NEAR(dist(t.nodes[0].center, {0.5f, 0, 0}), 0.0, 1e-6);
}

TEST(SphereTree, InteriorNodesHaveTwoToFourChildren) {
  for (std::size_t n : {2u, 3u, 4u, 5u, 6u, 7u, 11u, 1000u, 4097u}) {
    const SphereTree t = build(sphere_points(n, 4 + n));
    for (const SphereNode& nd : t.nodes) {
      EXPECT_TRUE(nd.child_count == 0 || (nd.child_count >= 2 && nd.child_count <= 4))
          << int(nd.child_count) << " children, n = " << n;
    }
  }
  // A node over 2 points has 2 leaf children, over 3 points 3, over 4 or more 4.
  EXPECT_EQ(build(sphere_points(2, 9)).nodes[0].child_count, 2);
  EXPECT_EQ(build(sphere_points(3, 9)).nodes[0].child_count, 3);
  EXPECT_EQ(build(sphere_points(4, 9)).nodes[0].child_count, 4);
  EXPECT_EQ(build(sphere_points(4, 9)).nodes.size(), 5u);
}

TEST(SphereTree, NodesPerLeafRatio) {
  // Includes sizes just above a power of two, where collapsing binary levels from the root
  // alone would give about 1.67.
  for (std::size_t n : {10000u, 12345u, 16384u, 16385u, 24576u, 40000u}) {
    const SphereTree t = build(sphere_points(n, 5));
    std::size_t leaves = 0;
    for (const SphereNode& nd : t.nodes) leaves += nd.child_count == 0;
    EXPECT_EQ(leaves, n);
    EXPECT_EQ(t.leaf_count, n);
    const double ratio = double(t.nodes.size()) / double(leaves);
    EXPECT_GE(ratio, 1.3) << "n = " << n;
    EXPECT_LE(ratio, 1.5 + 1e-9) << "n = " << n;
  }
}

TEST(SphereTree, BreadthFirstLayout) {
  for (std::size_t n : {1u, 2u, 3u, 17u, 2500u}) {
    const SphereTree t = build(sphere_points(n, 6));
    const std::size_t count = t.nodes.size();
    std::vector<int> parents(count, 0);
    std::vector<std::uint32_t> level(count, 0);
    std::uint32_t expected_first = 1;
    for (std::uint32_t i = 0; i < count; ++i) {
      const SphereNode& nd = t.nodes[i];
      if (nd.child_count == 0) {
        EXPECT_EQ(nd.first_child, 0u);
        continue;
      }
      // Children follow their parent, in parent order, right after the previous node's children.
      EXPECT_GT(nd.first_child, i);
      EXPECT_EQ(nd.first_child, expected_first) << "node " << i;
      expected_first = nd.first_child + nd.child_count;
      for (std::uint32_t k = 0; k < nd.child_count; ++k) {
        ASSERT_LT(nd.first_child + k, count);
        ++parents[nd.first_child + k];
        level[nd.first_child + k] = level[i] + 1;
      }
    }
    EXPECT_EQ(expected_first, count) << "every node but the root is somebody's child";
    EXPECT_EQ(parents[0], 0);
    for (std::size_t i = 1; i < count; ++i) EXPECT_EQ(parents[i], 1) << "node " << i;
    // All nodes of level d come before level d + 1.
    for (std::size_t i = 1; i < count; ++i) EXPECT_LE(level[i - 1], level[i]);
    EXPECT_EQ(t.depth, level.back());
    // Ranges shrink by 2 per binary level and the 4-way collapse halves the level count.
    const std::uint32_t binary_depth = static_cast<std::uint32_t>(std::ceil(std::log2(double(n))));
    EXPECT_GE(t.depth, (binary_depth + 1) / 2) << "n = " << n;
    EXPECT_LE(t.depth, (binary_depth + 2) / 2) << "n = " << n;
  }
}

TEST(SphereTree, EveryPointIsExactlyOneLeaf) {
  const PointSet pts = box_points(5000, 7, {1, 2, 3});
  const SphereTree t = build(pts);
  const auto by_pos = index_by_position(pts);
  std::vector<int> seen(pts.size(), 0);
  for (const SphereNode& nd : t.nodes) {
    if (nd.child_count != 0) continue;
    const std::uint32_t i = input_index(by_pos, nd.center);
    ASSERT_LT(i, pts.size());
    ++seen[i];
    EXPECT_EQ(nd.radius, pts.radii[i]);
    EXPECT_EQ(nd.normal, pts.normals[i]);
  }
  for (std::size_t i = 0; i < seen.size(); ++i) EXPECT_EQ(seen[i], 1) << "point " << i;
}

TEST(SphereTree, SinglePointIsALeafRoot) {
  PointSet pts;
  pts.positions = {{1, 2, 3}};
  pts.normals = {{0, 1, 0}};
  pts.radii = {0.5f};
  pts.colors = {{10, 20, 30}};
  const SphereTree t = build(pts);
  ASSERT_EQ(t.nodes.size(), 1u);
  EXPECT_EQ(t.nodes[0].child_count, 0);
  EXPECT_EQ(t.nodes[0].center, (Vec3f{1, 2, 3}));
  EXPECT_EQ(t.nodes[0].radius, 0.5f);
  EXPECT_EQ(t.nodes[0].color, (Rgb8{10, 20, 30}));
  EXPECT_EQ(t.leaf_count, 1u);
  EXPECT_EQ(t.depth, 0u);
  EXPECT_TRUE(t.has_colors);
  EXPECT_EQ(t.view_sphere.radius, 0.0f);
}

// Brute force: the leaves below the root's first two children (the first half of the binary
// split) are the n/2 smallest points by (coordinate on the longest axis of the box, index), and
// likewise for the quarters inside each half.
void expect_median_split(const PointSet& pts, const SphereTree& t,
                         const std::vector<std::uint32_t>& ids, std::uint32_t first_node,
                         std::uint32_t node_count_a, std::uint32_t node_count_b) {
  Aabb box;
  for (std::uint32_t i : ids) box.extend(pts.positions[i]);
  const Vec3f e = box.hi - box.lo;
  const int axis = (e.x >= e.y && e.x >= e.z) ? 0 : (e.y >= e.z ? 1 : 2);
  std::vector<std::uint32_t> sorted = ids;
  std::sort(sorted.begin(), sorted.end(), [&](std::uint32_t a, std::uint32_t b) {
    const float ka = pts.positions[a][axis], kb = pts.positions[b][axis];
    return ka < kb || (ka == kb && a < b);
  });
  const auto by_pos = index_by_position(pts);
  std::vector<std::uint32_t> lower;
  for (std::uint32_t k = 0; k < node_count_a; ++k) {
    for (std::uint32_t leaf : subtree_leaves(t, first_node + k)) {
      lower.push_back(input_index(by_pos, t.nodes[leaf].center));
    }
  }
  std::vector<std::uint32_t> upper;
  for (std::uint32_t k = 0; k < node_count_b; ++k) {
    for (std::uint32_t leaf : subtree_leaves(t, first_node + node_count_a + k)) {
      upper.push_back(input_index(by_pos, t.nodes[leaf].center));
    }
  }
  std::vector<std::uint32_t> expect_lower(sorted.begin(), sorted.begin() + ids.size() / 2);
  std::vector<std::uint32_t> expect_upper(sorted.begin() + ids.size() / 2, sorted.end());
  std::sort(lower.begin(), lower.end());
  std::sort(upper.begin(), upper.end());
  std::sort(expect_lower.begin(), expect_lower.end());
  std::sort(expect_upper.begin(), expect_upper.end());
  EXPECT_EQ(lower, expect_lower) << "axis " << axis;
  EXPECT_EQ(upper, expect_upper) << "axis " << axis;
}

// Checks the binary split of `ids` (input indices) under `node` and, one level down, of each half.
// The halves are the node's children when it has 2, else children 0–1 and 2–3.
void expect_median_splits_below(const PointSet& pts, const SphereTree& t, std::uint32_t node,
                                const std::vector<std::uint32_t>& ids) {
  const SphereNode& nd = t.nodes[node];
  ASSERT_TRUE(nd.child_count == 2 || nd.child_count == 4);
  const std::uint32_t per_half = nd.child_count / 2;
  expect_median_split(pts, t, ids, nd.first_child, per_half, per_half);
  const auto by_pos = index_by_position(pts);
  for (std::uint32_t h = 0; h < 2; ++h) {
    std::vector<std::uint32_t> half;
    for (std::uint32_t k = 0; k < per_half; ++k) {
      for (std::uint32_t leaf : subtree_leaves(t, nd.first_child + per_half * h + k)) {
        half.push_back(input_index(by_pos, t.nodes[leaf].center));
      }
    }
    if (per_half == 2) {
      expect_median_split(pts, t, half, nd.first_child + 2 * h, 1, 1);
    } else {
      expect_median_split(pts, t, half, t.nodes[nd.first_child + h].first_child, 2, 2);
    }
  }
}

TEST(SphereTree, RootSplitsAtTheMedianOfTheLongestAxis) {
  // 203 points: root with 4 children; 130: with 2 (fewer nodes that way). Longest axes differ.
  for (std::size_t n : {203u, 130u}) {
    for (const Vec3f size : {Vec3f{1, 2, 3}, Vec3f{5, 1, 2}, Vec3f{1, 4, 2}}) {
      const PointSet pts = box_points(n, 8, size);
      const SphereTree t = build(pts);
      std::vector<std::uint32_t> all(pts.size());
      std::iota(all.begin(), all.end(), 0u);
      expect_median_splits_below(pts, t, 0, all);
    }
  }
}

// Brute-force leaf order: sort the range by (coordinate on the longest axis of its box, index),
// recurse into the first n/2 and the rest.
void expected_leaf_order(const PointSet& pts, std::vector<std::uint32_t> ids,
                         std::vector<std::uint32_t>& out) {
  if (ids.size() <= 1) {
    out.insert(out.end(), ids.begin(), ids.end());
    return;
  }
  Aabb box;
  for (std::uint32_t i : ids) box.extend(pts.positions[i]);
  const Vec3f e = box.hi - box.lo;
  const int axis = (e.x >= e.y && e.x >= e.z) ? 0 : (e.y >= e.z ? 1 : 2);
  std::sort(ids.begin(), ids.end(), [&](std::uint32_t a, std::uint32_t b) {
    const float ka = pts.positions[a][axis], kb = pts.positions[b][axis];
    return ka < kb || (ka == kb && a < b);
  });
  const auto mid = ids.begin() + std::ptrdiff_t(ids.size() / 2);
  expected_leaf_order(pts, {ids.begin(), mid}, out);
  expected_leaf_order(pts, {mid, ids.end()}, out);
}

void leaves_depth_first(const SphereTree& t, std::uint32_t node, std::vector<std::uint32_t>& out) {
  const SphereNode& nd = t.nodes[node];
  if (nd.child_count == 0) out.push_back(node);
  for (std::uint32_t k = 0; k < nd.child_count; ++k) leaves_depth_first(t, nd.first_child + k, out);
}

TEST(SphereTree, EverySplitIsAMedianSplit) {
  // Children are laid out in range order, so the depth-first leaf sequence is the order the
  // recursive median splits leave the points in, at every level down to ranges of 2 and 3.
  // Points named by input index and (as from 8 M points) by Morton rank.
  for (std::size_t labels_from : {std::size_t{1} << 23, std::size_t{0}}) {
    for (std::size_t n : {2u, 3u, 5u, 64u, 130u, 333u, 1000u}) {
      const PointSet pts = box_points(n, 14, {1, 1.5f, 0.7f});
      const SphereTree t =
          build(pts, 2, {.parallel_grain_points = 16, .morton_labels_from = labels_from});
      const auto by_pos = index_by_position(pts);
      std::vector<std::uint32_t> leaves, got, expected;
      leaves_depth_first(t, 0, leaves);
      for (std::uint32_t leaf : leaves) got.push_back(input_index(by_pos, t.nodes[leaf].center));
      std::vector<std::uint32_t> all(n);
      std::iota(all.begin(), all.end(), 0u);
      expected_leaf_order(pts, all, expected);
      EXPECT_EQ(got, expected) << "n = " << n << ", Morton labels from " << labels_from;
    }
  }
}

TEST(SphereTree, MedianTiesGoToTheLowerIndex) {
  // x takes only 3 values (many ties) and is the longest axis; y, z are distinct and small.
  PointSet pts = box_points(100, 9, {0, 0.5f, 0.5f});
  for (std::size_t i = 0; i < pts.size(); ++i) pts.positions[i].x = float((i * 7) % 3);
  for (std::size_t labels_from : {std::size_t{1} << 23, std::size_t{0}}) {
    const SphereTree t = build(pts, 2, {.morton_labels_from = labels_from});
    std::vector<std::uint32_t> all(pts.size());
    std::iota(all.begin(), all.end(), 0u);
    expect_median_splits_below(pts, t, 0, all);
  }
}

// `count` points (prime to 7919) on an a × b × c grid of unit steps, in a scrambled order (with
// copies when count > a b c), so that coordinates tie at every level of the splits.
PointSet tied_grid(std::size_t count, std::size_t a, std::size_t b, std::size_t c,
                   std::uint64_t seed) {
  PointSet pts = box_points(count, seed, {1, 1, 1});
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const std::size_t j = (i * 7919) % pts.size();
    pts.positions[i] = {float(j % a), float(j / a % b), float(j / (a * b) % c)};
  }
  return pts;
}

// The brute-force median splits' order of all the points.
std::vector<std::uint32_t> expected_split_order(const PointSet& pts) {
  std::vector<std::uint32_t> all(pts.size()), expected;
  std::iota(all.begin(), all.end(), 0u);
  expected_leaf_order(pts, all, expected);
  return expected;
}

TEST(SphereTree, TiesInEveryRangeGoToTheLowerIndexWithMortonLabels) {
  // Coordinates on a coarse grid tie at every level, down to the three-point ranges, whose
  // split compares input indices; the Morton ranks would order the tied points otherwise.
  const PointSet pts = tied_grid(1000, 4, 5, 3, 21);
  const std::vector<std::uint32_t> expected = expected_split_order(pts);
  for (unsigned threads : {1u, 2u}) {
    ThreadPool pool(threads);
    std::vector<std::uint32_t> split_order;
    build_sphere_tree(pts, pool, Progress::none(),
                      {.parallel_grain_points = 16, .morton_labels_from = 0}, &split_order);
    EXPECT_EQ(split_order, expected) << threads << " threads";
  }
}

TEST(SphereTree, AGivenOrderOfThePointsNamesThemWithoutChangingTheSplits) {
  // 70,000 points (a given order is used from 65,536) tied on a grid; the split order against
  // the brute-force median splits, with the points' Morton order given and with a permutation
  // that has nothing spatial about it.
  const PointSet pts = tied_grid(70000, 40, 50, 35, 22);
  const std::vector<std::uint32_t> expected = expected_split_order(pts);
  ThreadPool pool(2);
  std::vector<std::uint32_t> scrambled(pts.size());
  for (std::size_t r = 0; r < pts.size(); ++r) scrambled[r] = std::uint32_t((r * 4001) % pts.size());
  for (const auto& given : {morton_order(pts.positions, pool), scrambled}) {
    std::vector<std::uint32_t> split_order;
    build_sphere_tree(pts, pool, Progress::none(),
                      {.parallel_grain_points = 1000, .morton_order = &given}, &split_order);
    EXPECT_EQ(split_order, expected);
  }
}

TEST(SphereTree, SameBitsForAnyThreadCount) {
  const PointSet pts = sphere_points(8000, 10, true);
  const SphereTreeOptions fine{.parallel_grain_points = 100};
  const SphereTree ref = build(pts, 1, fine);
  for (unsigned threads : {1u, 2u, 4u}) {
    for (const SphereTreeOptions& o : {fine, SphereTreeOptions{}}) {
      const SphereTree t = build(pts, threads, o);
      ASSERT_EQ(t.nodes.size(), ref.nodes.size());
      EXPECT_EQ(std::memcmp(t.nodes.data(), ref.nodes.data(), ref.nodes.size() * sizeof(SphereNode)),
                0)
          << threads << " threads, grain " << o.parallel_grain_points;
      EXPECT_EQ(t.depth, ref.depth);
      EXPECT_EQ(t.view_sphere.radius, ref.view_sphere.radius);
    }
  }
}

TEST(SphereTree, ColorsAreRoundedMeansOfChildren) {
  const PointSet pts = sphere_points(2000, 11, true);
  const SphereTree t = build(pts);
  EXPECT_TRUE(t.has_colors);
  const auto by_pos = index_by_position(pts);
  for (const SphereNode& nd : t.nodes) {
    if (nd.child_count == 0) {
      EXPECT_EQ(nd.color, pts.colors[input_index(by_pos, nd.center)]);
      continue;
    }
    int sum[3] = {0, 0, 0};
    for (std::uint32_t k = 0; k < nd.child_count; ++k) {
      const Rgb8 c = t.nodes[nd.first_child + k].color;
      sum[0] += c.r;
      sum[1] += c.g;
      sum[2] += c.b;
    }
    const auto mean = [&](int s) { return int(std::floor(double(s) / nd.child_count + 0.5)); };
    EXPECT_EQ(nd.color.r, mean(sum[0]));
    EXPECT_EQ(nd.color.g, mean(sum[1]));
    EXPECT_EQ(nd.color.b, mean(sum[2]));
  }
  EXPECT_FALSE(build(sphere_points(50, 11, false)).has_colors);
}

TEST(SphereTree, BoundsAndViewSphere) {
  const PointSet pts = box_points(3000, 12, {2, 1, 4});
  const SphereTree t = build(pts);
  Vec3f lo = pts.positions[0], hi = lo;
  for (const Vec3f& p : pts.positions) {
    lo = min(lo, p);
    hi = max(hi, p);
  }
  EXPECT_EQ(t.bounds.lo, lo);
  EXPECT_EQ(t.bounds.hi, hi);
  const Vec3f c = (lo + hi) * 0.5f;
  double r = 0;
  for (const Vec3f& p : pts.positions) r = std::max(r, dist(p, c));
  EXPECT_EQ(t.view_sphere.center, c);
  EXPECT_NEAR(t.view_sphere.radius, r, 1e-6 * r);
}

// Records phases and sums the work reported (advance may come from several threads).
class RecordingProgress final : public Progress {
 public:
  void begin_phase(std::string_view name, std::uint64_t total) override {
    names.emplace_back(name);
    totals.push_back(total);
  }
  void advance(std::uint64_t units) override { done += units; }
  void end_phase() override { ++ended; }
  std::vector<std::string> names;
  std::vector<std::uint64_t> totals;
  std::atomic<std::uint64_t> done{0};
  int ended = 0;
};

TEST(SphereTree, ReportsHierarchyPhase) {
  const PointSet pts = sphere_points(5000, 15);
  ThreadPool pool(2);
  RecordingProgress progress;
  const SphereTree t = build_sphere_tree(pts, pool, progress, {.parallel_grain_points = 500});
  ASSERT_EQ(progress.names, std::vector<std::string>{"hierarchy"});
  EXPECT_EQ(progress.ended, 1);
  // One unit per point for the partition, one per node for the attributes.
  EXPECT_EQ(progress.totals[0], pts.size() + t.nodes.size());
  EXPECT_EQ(progress.done.load(), progress.totals[0]);
}

TEST(SphereTree, RejectsBadInput) {
  ThreadPool pool(1);
  const auto message = [&](const PointSet& p) -> std::string {
    try {
      build_sphere_tree(p, pool);
    } catch (const Error& e) {
      return e.what();
    }
    return "(no error)";
  };
  EXPECT_NE(message(PointSet{}).find("empty"), std::string::npos);
  PointSet no_normals = sphere_points(10, 13);
  no_normals.normals.clear();
  EXPECT_NE(message(no_normals).find("no normals"), std::string::npos);
  PointSet no_radii = sphere_points(10, 13);
  no_radii.radii.clear();
  EXPECT_NE(message(no_radii).find("no splat radii"), std::string::npos);
  PointSet short_colors = sphere_points(10, 13, true);
  short_colors.colors.pop_back();
  EXPECT_NE(message(short_colors).find("9 colors for 10 points"), std::string::npos);
  PointSet nan_pos = sphere_points(100, 13);
  nan_pos.positions[70].y = std::nanf("");
  nan_pos.positions[37].x = INFINITY;
  const std::string m = message(nan_pos);
  EXPECT_NE(m.find("point 37:"), std::string::npos) << m;
  EXPECT_NE(m.find("position"), std::string::npos) << m;
  PointSet bad_radius = sphere_points(100, 13);
  bad_radius.radii[5] = -1;
  EXPECT_NE(message(bad_radius).find("point 5: splat radius"), std::string::npos);
}

}  // namespace
}  // namespace pointillist
