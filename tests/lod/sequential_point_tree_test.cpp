#include "pointillist/lod/sequential_point_tree.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <random>
#include <set>
#include <string>
#include <tuple>

#include "lod/sphere_points.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/scene/analytic.hpp"

namespace pointillist {
namespace {

using testing::sphere_points;

SequentialPointTree build(const PointSet& points, unsigned threads = 2,
                          SequentialPointTreeOptions options = {}) {
  ThreadPool pool(threads);
  return build_sequential_point_tree(points, pool, Progress::none(), options);
}

// Samples of an analytic scene with exact normals and radii 2/sqrt(n) per unit of area scale
// (a disc of the mean area per sample on the unit sphere).
PointSet scene_points(const AnalyticScene& scene, std::size_t n, std::uint64_t seed) {
  SurfaceSamples s = sample_scene(scene, n, seed);
  PointSet p = std::move(s.points);
  p.normals = s.true_normals;
  const float r = static_cast<float>(std::sqrt(surface_area(scene) / (kPi * double(n))));
  p.radii.assign(p.size(), r);
  return p;
}

// A flat grid of side x side points on z = 0, spacing 1/side, normals +z, overlapping discs.
PointSet grid_points(int side) {
  PointSet p;
  const float h = 1.0f / static_cast<float>(side);
  for (int i = 0; i < side; ++i) {
    for (int j = 0; j < side; ++j) {
      p.positions.push_back({i * h, j * h, 0});
      p.normals.push_back({0, 0, 1});
      p.radii.push_back(0.75f * h);
    }
  }
  return p;
}

Vec3f center_of(const SequentialPointTree& t, std::size_t i) {
  return {t.center_x[i], t.center_y[i], t.center_z[i]};
}
Vec3f normal_of(const SequentialPointTree& t, std::size_t i) {
  return {t.normal_x[i], t.normal_y[i], t.normal_z[i]};
}

double dist(Vec3f a, Vec3f b) {
  const double dx = double(a.x) - b.x, dy = double(a.y) - b.y, dz = double(a.z) - b.z;
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

std::vector<std::vector<std::uint32_t>> children_of(const SequentialPointTree& t) {
  std::vector<std::vector<std::uint32_t>> c(t.node_count());
  for (std::uint32_t i = 0; i < t.node_count(); ++i) {
    if (t.parent[i] != kSptNoParent) c[t.parent[i]].push_back(i);
  }
  return c;
}

// ---- Errors of one node, against hand-computed values ---------------------------------------

TEST(SptErrors, CoplanarDiscsHaveNoPerpendicularError) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-1, 1), ur(0.01f, 0.3f);
  // Plane z = 0.25 with normal +z, and a tilted plane through the origin.
  const Vec3f tilted = normalized({1, 2, 3});
  const Vec3f a = normalized(cross(tilted, {1, 0, 0})), b = cross(tilted, a);
  std::vector<SptDisc> flat, slanted;
  for (int i = 0; i < 8; ++i) {
    flat.push_back({{u(rng), u(rng), 0.25f}, {0, 0, 1}, ur(rng)});
    slanted.push_back({a * u(rng) + b * u(rng), tilted, ur(rng)});
  }
  const SptNodeGeometry g = spt_combine_children(flat);
  EXPECT_EQ(g.perpendicular_error, 0.0f);
  EXPECT_NEAR(g.center.z, 0.25f, 1e-7);
  EXPECT_NEAR(spt_combine_children(slanted).perpendicular_error, 0.0f, 1e-6);
}

TEST(SptErrors, OffsetLayersGiveTheOffset) {
  // Two groups of parallel discs (tiny radii) at heights 0 and h: e_p = h, whatever the radii,
  // since parallel discs have no thickness along the node normal.
  const float h = 0.37f;
  std::vector<SptDisc> children = {{{0, 0, 0}, {0, 0, 1}, 0.001f},
                                   {{0.5f, 0.1f, 0}, {0, 0, 1}, 0.002f},
                                   {{0.2f, 0.4f, h}, {0, 0, 1}, 0.001f},
                                   {{-0.3f, 0.2f, h}, {0, 0, 1}, 0.003f}};
  EXPECT_NEAR(spt_combine_children(children).perpendicular_error, h, 1e-6);
}

TEST(SptErrors, FoldedPatchGivesTheFoldHeight) {
  // A roof: two discs of radius r tilted by ±alpha meet at a ridge at the origin; each reaches
  // 2·r·sin(alpha) below the ridge, the fold height. The mean normal is +z.
  const float r = 0.2f;
  for (const float alpha_deg : {10.0f, 30.0f, 60.0f}) {
    const float alpha = deg_to_rad(alpha_deg), s = std::sin(alpha), c = std::cos(alpha);
    const std::vector<SptDisc> roof = {{{-r * c, 0, -r * s}, {-s, 0, c}, r},
                                       {{r * c, 0, -r * s}, {s, 0, c}, r}};
    const SptNodeGeometry g = spt_combine_children(roof);
    EXPECT_NEAR(g.normal.z, 1.0f, 1e-6);
    EXPECT_NEAR(g.perpendicular_error, 2 * r * s, 1e-6) << alpha_deg << " degrees";
  }
}

TEST(SptErrors, GapBetweenDiscsGivesTangentialError) {
  // Two discs of radius r at (±a, 0, 0), normal +z: diameter 2(a + r); the narrowest width
  // is along y (one of the documented directions for n = +z): 2r. e_t = 2a.
  const float a = 1.0f, r = 0.05f;
  const std::vector<SptDisc> pair = {{{-a, 0, 0}, {0, 0, 1}, r}, {{a, 0, 0}, {0, 0, 1}, r}};
  const SptNodeGeometry g = spt_combine_children(pair);
  EXPECT_NEAR(g.diameter, 2 * (a + r), 1e-6);
  EXPECT_NEAR(g.tangential_error, 2 * a, 1e-6);
  EXPECT_EQ(g.perpendicular_error, 0.0f);
  // The same pair in a plane of arbitrary orientation: the directions are at most π/16 away
  // from the narrowest one, where the width grows to at most 2r + 2a·sin(π/16).
  const Vec3f n = normalized({0.3f, -0.5f, 0.8f}), t = normalized(cross(n, {0.2f, 1, 0.1f}));
  const std::vector<SptDisc> turned = {{t * -a, n, r}, {t * a, n, r}};
  const SptNodeGeometry h = spt_combine_children(turned);
  EXPECT_LE(h.tangential_error, 2 * a + 1e-5);
  EXPECT_GE(h.tangential_error, 2 * a - 2 * a * std::sin(kPi / 16) - 1e-5);
}

TEST(SptErrors, DenselyCoveredRegionsHaveSmallTangentialError) {
  // A disc-shaped region: one disc of radius R at the centre and six at distance sqrt(3)·R.
  // Diameter 2R(sqrt(3) + 1); every width is at least 2R(sqrt(3)·cos 30° + 1) = 5R, so
  // e_t <= 2R(sqrt(3) - 1.5) ≈ 0.085 of the diameter (a gap would give nearly all of it).
  const float R = 0.1f, d = std::sqrt(3.0f) * R;
  std::vector<SptDisc> hexagon = {{{0, 0, 0}, {0, 0, 1}, R}};
  for (int k = 0; k < 6; ++k) {
    const float phi = deg_to_rad(60.0f * k);
    hexagon.push_back({{d * std::cos(phi), d * std::sin(phi), 0}, {0, 0, 1}, R});
  }
  const SptNodeGeometry g = spt_combine_children(hexagon);
  EXPECT_NEAR(g.diameter, 2 * R * (std::sqrt(3.0f) + 1), 1e-6);
  EXPECT_GE(g.tangential_error, 0.0f);
  EXPECT_LE(g.tangential_error, 2 * R * (std::sqrt(3.0f) - 1.5f) + 1e-6);

  // A square covered by four discs, one around each quadrant: centres (±a, ±a), radius
  // a·sqrt(2). The disc around the square overshoots it along the axes: diameter 4·sqrt(2)·a,
  // narrowest width (along x) 2a(1 + sqrt(2)), so e_t = 2a(sqrt(2) - 1).
  const float a = 0.25f, rq = a * std::sqrt(2.0f);
  const std::vector<SptDisc> square = {{{-a, -a, 0}, {0, 0, 1}, rq},
                                       {{a, -a, 0}, {0, 0, 1}, rq},
                                       {{-a, a, 0}, {0, 0, 1}, rq},
                                       {{a, a, 0}, {0, 0, 1}, rq}};
  EXPECT_NEAR(spt_combine_children(square).tangential_error, 2 * a * (std::sqrt(2.0f) - 1), 1e-6);
}

TEST(SptErrors, TwoPointTreeRootErrorIsTheGap) {
  // Through the build: two coplanar splats 2a apart give a root with e_p = 0 and e_t = 2a.
  PointSet p;
  p.positions = {{1, 2, 3}, {1.8f, 2, 3}};
  p.normals = {{0, 0, 1}, {0, 0, 1}};
  p.radii = {0.01f, 0.01f};
  const SequentialPointTree t = build(p);
  ASSERT_EQ(t.node_count(), 3u);
  EXPECT_EQ(t.parent[0], kSptNoParent);
  EXPECT_NEAR(t.error[0], 0.8f, 1e-6);
  EXPECT_EQ(t.parent_error[0], INFINITY);
  EXPECT_NEAR(t.diameter[0], 0.82f, 1e-6);
  for (int i : {1, 2}) {
    EXPECT_EQ(t.is_leaf[i], 1);
    EXPECT_EQ(t.error[i], 0.0f);
    EXPECT_EQ(t.parent_error[i], t.error[0]);
  }
}

// ---- The hierarchy ---------------------------------------------------------------------------

TEST(SequentialPointTree, StructureMatchesTheDefinition) {
  const PointSet pts = scene_points(demo_scene(), 4000, 5);
  const SequentialPointTree t = build(pts);
  const std::size_t count = t.node_count();
  ASSERT_EQ(t.leaf_count, pts.size());
  for (auto* v : {&t.center_x, &t.center_y, &t.center_z, &t.normal_x, &t.normal_y, &t.normal_z,
                  &t.error, &t.parent_error}) {
    ASSERT_EQ(v->size(), count);
  }
  // Every input point is exactly one leaf, with its position, normal and diameter.
  std::map<std::tuple<float, float, float>, std::uint32_t> by_position;
  for (std::uint32_t i = 0; i < pts.size(); ++i) {
    by_position[{pts.positions[i].x, pts.positions[i].y, pts.positions[i].z}] = i;
  }
  ASSERT_EQ(by_position.size(), pts.size());
  std::set<std::uint32_t> seen;
  const auto children = children_of(t);
  std::size_t roots = 0;
  for (std::uint32_t i = 0; i < count; ++i) {
    if (t.parent[i] == kSptNoParent)
      ++roots;
    else
      EXPECT_LT(t.parent[i], i) << "parents come first";
    if (t.is_leaf[i]) {
      EXPECT_TRUE(children[i].empty());
      const auto it = by_position.find({t.center_x[i], t.center_y[i], t.center_z[i]});
      ASSERT_NE(it, by_position.end()) << "leaf " << i << " is no input point";
      EXPECT_TRUE(seen.insert(it->second).second) << "point " << it->second << " twice";
      EXPECT_EQ(t.diameter[i], 2 * pts.radii[it->second]);
      EXPECT_NEAR(dist(normal_of(t, i), pts.normals[it->second]), 0, 1e-6);
      EXPECT_EQ(t.error[i], 0.0f);
      continue;
    }
    // Interior: 2..8 children, mean centre, normalized mean normal, enclosing sphere.
    ASSERT_GE(children[i].size(), 2u);
    ASSERT_LE(children[i].size(), 8u);
    Vec3f c, n;
    for (std::uint32_t k : children[i]) {
      c += center_of(t, k);
      n += normal_of(t, k);
    }
    c = c / static_cast<float>(children[i].size());
    EXPECT_NEAR(dist(center_of(t, i), c), 0, 1e-5);
    EXPECT_NEAR(dist(normal_of(t, i), normalized(n)), 0, 1e-4) << i;
    double needed = 0;
    for (std::uint32_t k : children[i]) {
      needed = std::max(needed, dist(center_of(t, i), center_of(t, k)) + t.diameter[k] / 2.0);
      // Monotonic errors, and r_max(child) = r_min(parent).
      EXPECT_LE(t.error[k], t.error[i]);
      EXPECT_EQ(t.parent_error[k], t.error[i]);
    }
    EXPECT_GE(t.diameter[i] / 2.0, needed);
    EXPECT_LE(t.diameter[i] / 2.0, needed * (1 + 1e-5));
  }
  EXPECT_EQ(roots, 1u);
  EXPECT_EQ(t.parent[0], kSptNoParent);
  EXPECT_EQ(seen.size(), pts.size());
  EXPECT_GT(t.error[0], 0.0f);
}

TEST(SequentialPointTree, ListIsSortedByRMaxDescending) {
  const PointSet pts = scene_points(torus_scene(), 3000, 7);
  const SequentialPointTree t = build(pts, 2, {.chunk_level = 0});
  ASSERT_EQ(t.top_end, 0u);
  ASSERT_EQ(t.chunks.size(), 1u);
  EXPECT_EQ(t.chunks[0].begin, 0u);
  EXPECT_EQ(t.chunks[0].end, t.node_count());
  EXPECT_EQ(t.parent_error[0], INFINITY);
  for (std::size_t i = 1; i < t.node_count(); ++i) {
    ASSERT_GE(t.parent_error[i - 1], t.parent_error[i]) << "at " << i;
  }
  // r_max = parent_error / ε keeps the order for any ε.
  for (const float eps : {1e-4f, 0.3f}) {
    for (std::size_t i = 1; i < t.node_count(); ++i) {
      ASSERT_GE(t.parent_error[i - 1] / eps, t.parent_error[i] / eps);
    }
  }
}

// Brute force: for one eye distance r, every leaf has exactly one node on its path to the root
// (itself included) with r in [r_min, r_max).
void expect_one_node_per_leaf(const SequentialPointTree& t, float eps, float r) {
  for (std::uint32_t leaf = 0; leaf < t.node_count(); ++leaf) {
    if (!t.is_leaf[leaf]) continue;
    int drawn = 0;
    for (std::uint32_t i = leaf; i != kSptNoParent; i = t.parent[i]) {
      const float r_min = t.error[i] / eps, r_max = t.parent_error[i] / eps;
      if (r >= r_min && r < r_max) ++drawn;
    }
    ASSERT_EQ(drawn, 1) << "leaf " << leaf << ", eps " << eps << ", r " << r;
  }
}

TEST(SequentialPointTree, EachLeafIsCoveredByExactlyOneDrawnNode) {
  const PointSet pts = scene_points(sphere_scene(1.0f), 3000, 11);
  const SequentialPointTree t = build(pts, 2, {.chunk_level = 2});
  std::mt19937 rng(17);
  std::uniform_real_distribution<float> log_r(-4.0f, 4.0f);
  std::size_t interior_drawn = 0;
  for (const float eps : {1e-3f, 0.01f, 0.2f}) {
    for (int trial = 0; trial < 12; ++trial) {
      const float r = std::pow(10.0f, log_r(rng));
      expect_one_node_per_leaf(t, eps, r);
      for (std::uint32_t i = 0; i < t.node_count(); ++i) {
        interior_drawn += !t.is_leaf[i] && r >= t.error[i] / eps && r < t.parent_error[i] / eps;
      }
    }
  }
  EXPECT_GT(interior_drawn, 0u) << "the test should reach coarse levels too";
}

TEST(SequentialPointTree, DuplicatePositionsStillGiveATree) {
  PointSet p = sphere_points(200, 3);
  for (int i = 0; i < 30; ++i) {  // 31 splats at one spot
    p.positions.push_back(p.positions[0]);
    p.normals.push_back(p.normals[0]);
    p.radii.push_back(0.01f);
  }
  const SequentialPointTree t = build(p);
  EXPECT_EQ(std::count(t.is_leaf.begin(), t.is_leaf.end(), 1), 230);
  for (const auto& c : children_of(t)) EXPECT_LE(c.size(), 8u);
  expect_one_node_per_leaf(t, 0.01f, 0.5f);
  expect_one_node_per_leaf(t, 0.01f, 1e-6f);

  // Nothing but one spot (an empty bounding box): a balanced tree of up to 8 children.
  PointSet same;
  same.positions.assign(100, {1, 1, 1});
  same.normals.assign(100, {0, 1, 0});
  same.radii.assign(100, 0.1f);
  const SequentialPointTree s = build(same);
  EXPECT_EQ(std::count(s.is_leaf.begin(), s.is_leaf.end(), 1), 100);
  for (const auto& c : children_of(s)) EXPECT_LE(c.size(), 8u);
  for (std::uint32_t i = 0; i < s.node_count(); ++i) {
    EXPECT_EQ(s.error[i], 0.0f);  // coincident parallel discs: nothing to lose
    EXPECT_FLOAT_EQ(s.diameter[i], 0.2f);
  }
  expect_one_node_per_leaf(s, 0.01f, 1.0f);
}

TEST(SequentialPointTree, TinyEpsilonDrawsEveryLeafAtCloseRange) {
  const PointSet pts = scene_points(sphere_scene(1.0f), 2000, 13);
  const SequentialPointTree t = build(pts);
  const float eps = 1e-9f, r = 1.0f;
  std::size_t drawn_leaves = 0, drawn_interior = 0;
  for (std::uint32_t i = 0; i < t.node_count(); ++i) {
    const bool drawn = r >= t.error[i] / eps && r < t.parent_error[i] / eps;
    (t.is_leaf[i] ? drawn_leaves : drawn_interior) += drawn;
  }
  EXPECT_EQ(drawn_leaves, pts.size());
  EXPECT_EQ(drawn_interior, 0u);
  // Far away only the root is drawn.
  const float far = 1e6f;
  for (std::uint32_t i = 0; i < t.node_count(); ++i) {
    const bool drawn = far >= t.error[i] / 0.01f && far < t.parent_error[i] / 0.01f;
    EXPECT_EQ(drawn, i == 0) << i;
  }
}

TEST(SequentialPointTree, ColorEdgeRaisesTheError) {
  const PointSet white = grid_points(32);
  PointSet two_colors = white;
  for (const Vec3f& q : white.positions) {
    two_colors.colors.push_back(q.x < 0.3f ? Rgb8{255, 0, 0} : Rgb8{0, 0, 255});
  }
  const SequentialPointTree plain = build(white, 2, {.chunk_level = 0});
  const SequentialPointTree t = build(two_colors, 2, {.chunk_level = 0});
  ASSERT_TRUE(t.has_colors);
  ASSERT_EQ(t.node_count(), plain.node_count());
  // Without colours the flat grid's root is cheap to draw...
  EXPECT_LT(plain.error[0], 0.5f * plain.diameter[0]);
  // ... over the colour edge it may only be drawn once its whole disc is below the bound.
  EXPECT_GE(t.error[0], t.diameter[0]);

  // Nodes match by geometry; mixed subtrees and the interior children of mixed nodes are raised,
  // single-coloured subtrees away from the edge keep their error.
  std::map<std::tuple<float, float, float, float>, float> plain_error;
  for (std::uint32_t i = 0; i < plain.node_count(); ++i) {
    plain_error[{plain.center_x[i], plain.center_y[i], plain.center_z[i], plain.diameter[i]}] =
        plain.error[i];
  }
  std::vector<int> mask(t.node_count(), 0);  // bit 0: has red below, bit 1: has blue
  for (std::uint32_t leaf = 0; leaf < t.node_count(); ++leaf) {
    if (!t.is_leaf[leaf]) continue;
    const int bit = t.colors[leaf].r == 255 ? 1 : 2;
    for (std::uint32_t i = leaf; i != kSptNoParent; i = t.parent[i]) mask[i] |= bit;
  }
  std::size_t mixed = 0;
  for (std::uint32_t i = 0; i < t.node_count(); ++i) {
    const auto it = plain_error.find({t.center_x[i], t.center_y[i], t.center_z[i], t.diameter[i]});
    ASSERT_NE(it, plain_error.end()) << "same geometry, same nodes";
    const bool parent_mixed = t.parent[i] != kSptNoParent && mask[t.parent[i]] == 3;
    if (mask[i] == 3) {
      ++mixed;
      EXPECT_GE(t.error[i], t.diameter[i]) << i;
    } else if (parent_mixed && !t.is_leaf[i]) {
      // One colour, but its disc reaches across the edge into its siblings' colour.
      EXPECT_GE(t.error[i], t.diameter[i]) << i;
    } else if (t.is_leaf[i]) {
      EXPECT_EQ(t.error[i], 0.0f) << i;
    } else {
      // Away from the edge: raised at most by the monotonicity over such children.
      EXPECT_GE(t.error[i], it->second) << i;
      bool edge_child = false;
      for (std::uint32_t c = 0; c < t.node_count(); ++c) {
        edge_child = edge_child || (t.parent[c] == i && mask[c] == 3);
      }
      if (!edge_child) {
        EXPECT_EQ(t.error[i], it->second) << i;
      }
    }
  }
  EXPECT_GT(mixed, 1u);

  // An infinite tolerance turns the rule off.
  const SequentialPointTree off =
      build(two_colors, 2, {.chunk_level = 0, .color_tolerance = INFINITY});
  EXPECT_EQ(off.error, plain.error);
}

TEST(SequentialPointTree, MeanColorsAreStored) {
  PointSet p;
  p.positions = {{0, 0, 0}, {1, 0, 0}};
  p.normals = {{0, 0, 1}, {0, 0, 1}};
  p.radii = {0.1f, 0.1f};
  p.colors = {{200, 10, 0}, {100, 30, 255}};
  const SequentialPointTree t = build(p);
  ASSERT_EQ(t.colors.size(), 3u);
  EXPECT_EQ(t.colors[0], (Rgb8{150, 20, 128}));  // 127.5 rounds up
}

// ---- Chunks ----------------------------------------------------------------------------------

TEST(SequentialPointTree, ChunksPartitionTheListIntoSortedSubtrees) {
  const PointSet pts = scene_points(demo_scene(), 6000, 19);
  const std::uint32_t level = 2;
  const SequentialPointTree t = build(pts, 2, {.chunk_level = level});
  ASSERT_FALSE(t.chunks.empty());
  EXPECT_LE(t.chunks.size(), 64u);
  EXPECT_GT(t.top_end, 0u);
  // Contiguous, in order, covering everything after the top list.
  std::uint32_t at = t.top_end;
  for (const SptChunk& c : t.chunks) {
    EXPECT_EQ(c.begin, at);
    EXPECT_LT(c.begin, c.end);
    at = c.end;
  }
  EXPECT_EQ(at, t.node_count());
  const auto sorted = [&](std::uint32_t b, std::uint32_t e) {
    for (std::uint32_t i = b + 1; i < e; ++i) {
      if (t.parent_error[i - 1] < t.parent_error[i]) return false;
    }
    return true;
  };
  EXPECT_TRUE(sorted(0, t.top_end));
  for (std::uint32_t i = 0; i < t.top_end; ++i) EXPECT_FALSE(t.is_leaf[i]);

  // Octree cells at depth `level` of the bounding cube, computed here.
  const Vec3f e = t.bounds.extent();
  const double side = std::max({e.x, e.y, e.z}), cells = double(1 << level);
  const auto cell_of = [&](Vec3f p) {
    int idx[3];
    for (int a = 0; a < 3; ++a) {
      idx[a] = static_cast<int>(
          std::min(cells - 1, std::floor((double(p[a]) - t.bounds.lo[a]) / side * cells)));
    }
    return std::tuple{idx[0], idx[1], idx[2]};
  };
  std::vector<int> chunk_of(t.node_count(), -1);
  std::set<std::tuple<int, int, int>> chunk_cells;
  for (std::size_t k = 0; k < t.chunks.size(); ++k) {
    const SptChunk& c = t.chunks[k];
    EXPECT_TRUE(sorted(c.begin, c.end)) << "chunk " << k;
    // The first node is the chunk root: its parent is in the top list; all others stay inside.
    const std::uint32_t root_parent = t.parent[c.begin];
    EXPECT_TRUE(root_parent == kSptNoParent || root_parent < t.top_end);
    for (std::uint32_t i = c.begin + 1; i < c.end; ++i) {
      EXPECT_GE(t.parent[i], c.begin);
      EXPECT_LT(t.parent[i], i);
    }
    std::set<std::tuple<int, int, int>> leaf_cells;
    for (std::uint32_t i = c.begin; i < c.end; ++i) {
      chunk_of[i] = static_cast<int>(k);
      if (!t.is_leaf[i]) continue;
      leaf_cells.insert(cell_of(center_of(t, i)));
      EXPECT_LE(dist(center_of(t, i), c.bounds.center) + t.diameter[i] / 2.0,
                c.bounds.radius * (1 + 1e-5));
    }
    EXPECT_EQ(leaf_cells.size(), 1u) << "chunk " << k << " spans cells";
    EXPECT_TRUE(chunk_cells.insert(*leaf_cells.begin()).second) << "two chunks in one cell";
  }
  // Each top node spans more than one cell (else it would belong to a chunk).
  std::vector<std::set<std::tuple<int, int, int>>> top_cells(t.top_end);
  for (std::uint32_t leaf = t.top_end; leaf < t.node_count(); ++leaf) {
    if (!t.is_leaf[leaf]) continue;
    for (std::uint32_t i = leaf; i != kSptNoParent; i = t.parent[i]) {
      if (i < t.top_end) top_cells[i].insert(cell_of(center_of(t, leaf)));
    }
  }
  for (std::uint32_t i = 0; i < t.top_end; ++i) EXPECT_GE(top_cells[i].size(), 2u) << i;
  expect_one_node_per_leaf(t, 0.01f, 3.0f);
}

TEST(SequentialPointTree, SinglePointIsALeafRootAndOneChunk) {
  PointSet p;
  p.positions = {{1, 2, 3}};
  p.normals = {{0, 1, 0}};
  p.radii = {0.5f};
  const SequentialPointTree t = build(p);
  ASSERT_EQ(t.node_count(), 1u);
  EXPECT_EQ(t.is_leaf[0], 1);
  EXPECT_EQ(t.error[0], 0.0f);
  EXPECT_EQ(t.parent_error[0], INFINITY);
  EXPECT_EQ(t.diameter[0], 1.0f);
  ASSERT_EQ(t.chunks.size(), 1u);
  EXPECT_EQ(t.top_end, 0u);
  EXPECT_EQ(t.chunks[0].end, 1u);
}

// ---- Determinism and errors ------------------------------------------------------------------

TEST(SequentialPointTree, SameBitsForAnyThreadCountAndGrain) {
  const PointSet pts = sphere_points(40000, 23, true);
  const SequentialPointTree a = build(pts, 1);
  const SequentialPointTree b = build(pts, 3);
  const SequentialPointTree c = build(pts, 3, {.parallel_grain_points = 100});
  for (const SequentialPointTree* o : {&b, &c}) {
    EXPECT_EQ(a.center_x, o->center_x);
    EXPECT_EQ(a.center_y, o->center_y);
    EXPECT_EQ(a.center_z, o->center_z);
    EXPECT_EQ(a.normal_x, o->normal_x);
    EXPECT_EQ(a.normal_y, o->normal_y);
    EXPECT_EQ(a.normal_z, o->normal_z);
    EXPECT_EQ(a.diameter, o->diameter);
    EXPECT_EQ(a.error, o->error);
    EXPECT_EQ(a.parent_error, o->parent_error);
    EXPECT_EQ(a.is_leaf, o->is_leaf);
    EXPECT_EQ(a.parent, o->parent);
    ASSERT_EQ(a.colors.size(), o->colors.size());
    EXPECT_EQ(0, std::memcmp(a.colors.data(), o->colors.data(), a.colors.size() * sizeof(Rgb8)));
    EXPECT_EQ(a.top_end, o->top_end);
    ASSERT_EQ(a.chunks.size(), o->chunks.size());
    for (std::size_t k = 0; k < a.chunks.size(); ++k) {
      EXPECT_EQ(a.chunks[k].begin, o->chunks[k].begin);
      EXPECT_EQ(a.chunks[k].end, o->chunks[k].end);
    }
  }
}

TEST(SequentialPointTree, RejectsBadInputAndOptions) {
  ThreadPool pool(1);
  const auto message = [&](const PointSet& p, SequentialPointTreeOptions o = {}) -> std::string {
    try {
      build_sequential_point_tree(p, pool, Progress::none(), o);
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
  PointSet nan_normal = sphere_points(100, 13);
  nan_normal.normals[42].z = std::nanf("");
  const std::string m = message(nan_normal);
  EXPECT_NE(m.find("point 42: normal"), std::string::npos) << m;
  PointSet bad_radius = sphere_points(100, 13);
  bad_radius.radii[5] = -1;
  EXPECT_NE(message(bad_radius).find("point 5: splat radius"), std::string::npos);
  const PointSet ok = sphere_points(10, 13);
  EXPECT_THROW(build_sequential_point_tree(ok, pool, Progress::none(), {.chunk_level = 11}),
               OptionError);
  EXPECT_NE(message(ok, {.chunk_level = 11}).find("chunk_level 11"), std::string::npos);
  EXPECT_THROW(build_sequential_point_tree(ok, pool, Progress::none(), {.color_tolerance = -1}),
               OptionError);
  EXPECT_THROW(
      build_sequential_point_tree(ok, pool, Progress::none(), {.color_tolerance = std::nanf("")}),
      OptionError);
}

}  // namespace
}  // namespace pointillist
