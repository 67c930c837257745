// The hierarchy over the analytic demo scene (sphere, torus, cube with sharp edges), with exact
// normals as the oracle.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "pointillist/lod/sphere_tree.hpp"
#include "pointillist/scene/analytic.hpp"

namespace pointillist {
namespace {

PointSet demo_points(std::size_t count) {
  const AnalyticScene scene = demo_scene();
  SurfaceSamples s = sample_scene(scene, count, 31);
  PointSet p = std::move(s.points);
  p.normals = s.true_normals;
  // Splats about 1.5 times the mean sample spacing, so they overlap.
  const float r = 1.5f * std::sqrt(float(surface_area(scene)) / (float(count) * kPi));
  p.radii.assign(p.size(), r);
  return p;
}

double angle_between(Vec3f a, Vec3f b) {
  const double d = double(dot(a, b)) / (double(length(a)) * double(length(b)));
  return std::acos(std::clamp(d, -1.0, 1.0));
}

void collect_leaves(const SphereTree& t, std::uint32_t node, std::vector<std::uint32_t>& out) {
  const SphereNode& nd = t.nodes[node];
  if (nd.child_count == 0) out.push_back(node);
  for (std::uint32_t k = 0; k < nd.child_count; ++k) collect_leaves(t, nd.first_child + k, out);
}

TEST(SphereTreeScene, SubtreeBoundsHoldOnTheDemoScene) {
  const PointSet pts = demo_points(6000);
  ThreadPool pool(2);
  const SphereTree t = build_sphere_tree(pts, pool);
  EXPECT_EQ(t.leaf_count, pts.size());
  std::size_t flat_nodes = 0;
  for (std::uint32_t i = 0; i < t.nodes.size(); ++i) {
    const SphereNode& n = t.nodes[i];
    if (n.child_count == 0) continue;
    std::vector<std::uint32_t> leaves;
    collect_leaves(t, i, leaves);
    bool same_normal = true;
    for (std::uint32_t l : leaves) {
      const SphereNode& leaf = t.nodes[l];
      // Every splat of the subtree lies in the node's sphere.
      EXPECT_LE(double(distance(leaf.center, n.center)) + leaf.radius, n.radius * (1 + 1e-5))
          << "node " << i;
      if (n.cone_sin < 1) {
        EXPECT_LE(angle_between(n.normal, leaf.normal), std::asin(double(n.cone_sin)) + 1e-5)
            << "node " << i;
      }
      same_normal = same_normal && leaf.normal == t.nodes[leaves[0]].normal;
    }
    // Subtrees on one flat cube face: the cone collapses to (almost) nothing.
    if (same_normal) {
      ++flat_nodes;
      EXPECT_LE(n.cone_sin, 1e-6f) << "node " << i;
      EXPECT_LE(angle_between(n.normal, t.nodes[leaves[0]].normal), 1e-6) << "node " << i;
    }
  }
  EXPECT_GT(flat_nodes, 100u);  // the cube holds a sixth or so of the samples
}

}  // namespace
}  // namespace pointillist
