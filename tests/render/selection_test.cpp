// QSplat traversal: stream order, level of detail, culling, determinism.
#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <vector>

#include "pointillist/render/render.hpp"
#include "pointillist/scene/analytic.hpp"
#include "render_test_util.hpp"

using namespace pointillist;
using namespace pointillist::render_test;

namespace {

Frame render_with(const SphereTree& tree, const Camera& cam, const RenderSettings& s,
                  unsigned threads) {
  ThreadPool pool(threads);
  Frame f;
  render(tree.view(), cam, s, pool, f);
  return f;
}

bool same_image(const Frame& a, const Frame& b) {
  return a.width == b.width && a.height == b.height && a.color == b.color &&
         std::equal(a.depth.begin(), a.depth.end(), b.depth.begin(), b.depth.end(),
                    [](float x, float y) { return std::bit_cast<std::uint32_t>(x) ==
                                                  std::bit_cast<std::uint32_t>(y); });
}

int differing_pixels(const Frame& a, const Frame& b) {
  int n = 0;
  for (std::size_t i = 0; i < a.color.size(); ++i) {
    n += !(a.color[i] == b.color[i]) ||
         std::bit_cast<std::uint32_t>(a.depth[i]) != std::bit_cast<std::uint32_t>(b.depth[i]);
  }
  return n;
}

// A leaf is drawn at a tiny threshold without culling when its centre is in front of the eye and
// its normal does not point away from the eye (brute force, double precision).
bool leaf_is_drawable(const SphereNode& n, const Camera& cam) {
  const CameraFrame f = make_camera_frame(cam);
  const double dx = double(n.center.x) - cam.eye.x, dy = double(n.center.y) - cam.eye.y,
               dz = double(n.center.z) - cam.eye.z;
  const double z = dx * f.forward.x + dy * f.forward.y + dz * f.forward.z;
  const double facing = -(dx * n.normal.x + dy * n.normal.y + dz * n.normal.z);
  return z > 0 && facing >= 0;
}

}  // namespace

TEST(Selection, StreamIsTheDepthFirstOrderOfDrawableLeaves) {
  // Enough points for several selection tasks (one per ~2048 expected splats).
  const PointSet pts = splat_samples(torus_scene(), 20000, 7);
  const SphereTree tree = make_test_tree(pts);
  const Camera cam = orbit_camera(tree.view_sphere, {.azimuth_deg = 30, .elevation_deg = 20,
                                                     .width = 120, .height = 90});
  RenderSettings s;
  s.threshold_px = 1e-3f;
  s.frustum_culling = s.backface_culling = false;
  std::vector<std::uint32_t> want;
  std::function<void(std::uint32_t)> dfs = [&](std::uint32_t i) {
    const SphereNode& n = tree.nodes[i];
    if (n.child_count == 0) {
      if (leaf_is_drawable(n, cam)) want.push_back(i);
      return;
    }
    for (std::uint32_t c = 0; c < n.child_count; ++c) dfs(n.first_child + c);
  };
  dfs(0);
  for (unsigned threads : {1u, 2u}) {
    const Frame f = render_with(tree, cam, s, threads);
    EXPECT_GE(f.splats.chunk_count, 8u);  // the top was split into several subtrees
    EXPECT_EQ(stream_nodes(f.splats), want) << threads << " threads";
    EXPECT_EQ(f.stats.splats, want.size());
    EXPECT_EQ(f.stats.nodes_visited, tree.nodes.size());  // nothing culled, every node tested
  }
}

TEST(Selection, EveryFrontFacingLeafIsDrawnAtTinyThresholdWhenAllIsInView) {
  // Asserted: with culling on, a threshold of 1e-3 px and the whole model in view, the stream
  // holds exactly the leaves with z > 0 and n·(eye − c) ≥ 0, each once (leaves within 1e-6 of
  // edge-on may go either way).
  const PointSet pts = splat_samples(demo_scene(), 20000, 11);
  const SphereTree tree = make_test_tree(pts);
  for (float az : {0.0f, 140.0f}) {
    const Camera cam = orbit_camera(tree.view_sphere, {.azimuth_deg = az, .elevation_deg = 25,
                                                       .width = 160, .height = 120});
    RenderSettings s;
    s.threshold_px = 1e-3f;
    const Frame f = render_with(tree, cam, s, 2);
    std::vector<std::uint32_t> got = stream_nodes(f.splats);
    std::sort(got.begin(), got.end());
    EXPECT_TRUE(std::adjacent_find(got.begin(), got.end()) == got.end()) << "duplicates";
    std::size_t leaves = 0, missing = 0, extra = 0;
    for (std::uint32_t i = 0; i < tree.nodes.size(); ++i) {
      const SphereNode& n = tree.nodes[i];
      const bool in_stream = std::binary_search(got.begin(), got.end(), i);
      if (n.child_count != 0) {
        EXPECT_FALSE(in_stream) << "interior node " << i;
        continue;
      }
      ++leaves;
      const Vec3f v = cam.eye - n.center;
      const bool edge_on = std::abs(dot(v, n.normal)) < 1e-6f * length(v);
      if (edge_on) continue;
      missing += leaf_is_drawable(n, cam) && !in_stream;
      extra += !leaf_is_drawable(n, cam) && in_stream;
    }
    EXPECT_EQ(leaves, pts.size());
    EXPECT_EQ(missing, 0u) << "azimuth " << az;
    EXPECT_EQ(extra, 0u) << "azimuth " << az;
    EXPECT_GT(f.stats.culled_backface, 0u);
    EXPECT_EQ(f.stats.culled_frustum, 0u);
  }
}

TEST(Selection, SplatCountDoesNotGrowWithTheThreshold) {
  const PointSet pts = splat_samples(sphere_scene(), 30000, 3);
  const SphereTree tree = make_test_tree(pts);
  const Camera cam = orbit_camera(tree.view_sphere, {.azimuth_deg = 10, .elevation_deg = 10,
                                                     .width = 200, .height = 150});
  std::uint64_t previous = ~0ull, first = 0;
  for (float t : {0.5f, 1.0f, 2.0f, 4.0f, 8.0f}) {
    RenderSettings s;
    s.threshold_px = t;
    const Frame f = render_with(tree, cam, s, 2);
    EXPECT_LE(f.stats.splats, previous) << "threshold " << t;
    previous = f.stats.splats;
    if (first == 0) first = f.stats.splats;
  }
  EXPECT_LT(previous * 2, first);  // 16 times the threshold: far fewer splats
}

TEST(Selection, CullingNeverChangesTheImageWhenEveryLeafIsDrawn) {
  struct Case {
    const char* name;
    AnalyticScene scene;
  };
  const Case cases[] = {{"sphere", sphere_scene()}, {"torus", torus_scene()},
                        {"demo", demo_scene()}};
  for (const Case& c : cases) {
    const PointSet pts = splat_samples(c.scene, 15000, 5);
    const SphereTree tree = make_test_tree(pts);
    std::uint64_t frustum_culled = 0, backface_culled = 0;
    // Whole model in view, then close-ups with part of the model outside the image.
    for (const OrbitOptions& view :
         {OrbitOptions{.azimuth_deg = 20, .elevation_deg = 30, .width = 96, .height = 72},
          OrbitOptions{.azimuth_deg = 200, .elevation_deg = -40, .distance = 1.3f, .width = 96,
                       .height = 72},
          OrbitOptions{.azimuth_deg = 75, .elevation_deg = 5, .distance = 1.8f, .fov_deg = 20,
                       .width = 80, .height = 90}}) {
      const Camera cam = orbit_camera(tree.view_sphere, view);
      for (SplatShape shape : {SplatShape::Circle, SplatShape::Ellipse}) {
        RenderSettings on;
        on.threshold_px = 1e-3f;
        on.shape = shape;
        RenderSettings coarse = on;  // interior nodes drawn too: still no change (conservative cones)
        coarse.threshold_px = 3.0f;
        RenderSettings coarse_off = coarse;
        coarse_off.frustum_culling = coarse_off.backface_culling = false;
        EXPECT_TRUE(same_image(render_with(tree, cam, coarse, 2), render_with(tree, cam, coarse_off, 2)))
            << c.name << " coarse";
        RenderSettings no_frustum = on, no_backface = on, off = on;
        no_frustum.frustum_culling = false;
        no_backface.backface_culling = false;
        off.frustum_culling = off.backface_culling = false;
        const Frame f_on = render_with(tree, cam, on, 2);
        for (std::uint32_t i : stream_nodes(f_on.splats)) ASSERT_EQ(tree.nodes[i].child_count, 0);
        frustum_culled += f_on.stats.culled_frustum;
        backface_culled += f_on.stats.culled_backface;
        const Frame f_off = render_with(tree, cam, off, 2);
        EXPECT_EQ(differing_pixels(f_on, f_off), 0) << c.name << " az " << view.azimuth_deg;
        EXPECT_TRUE(same_image(render_with(tree, cam, no_frustum, 2), f_off)) << c.name;
        EXPECT_TRUE(same_image(render_with(tree, cam, no_backface, 2), f_off)) << c.name;
        EXPECT_LT(f_on.stats.nodes_visited, f_off.stats.nodes_visited) << c.name;
      }
    }
    EXPECT_GT(frustum_culled, 0u) << c.name;
    EXPECT_GT(backface_culled, 0u) << c.name;
  }
}

TEST(Selection, SameImageBitsWithOneTwoAndThreeThreads) {
  const PointSet pts = splat_samples(demo_scene(), 40000, 9);
  const SphereTree tree = make_test_tree(pts);
  const Camera cam = orbit_camera(tree.view_sphere, {.azimuth_deg = 35, .elevation_deg = 20,
                                                     .width = 203, .height = 117});
  for (SplatShape shape : {SplatShape::Square, SplatShape::Circle, SplatShape::Ellipse}) {
    for (float t : {1.0f, 3.0f}) {
      RenderSettings s;
      s.shape = shape;
      s.threshold_px = t;
      const Frame one = render_with(tree, cam, s, 1);
      EXPECT_GT(one.stats.splats, 1000u);
      for (unsigned threads : {2u, 3u}) {
        const Frame many = render_with(tree, cam, s, threads);
        EXPECT_TRUE(same_image(one, many)) << threads << " threads, shape " << int(shape);
        EXPECT_EQ(stream_nodes(one.splats), stream_nodes(many.splats));
        EXPECT_EQ(one.stats.nodes_visited, many.stats.nodes_visited);
        EXPECT_EQ(many.stats.threads, threads);
      }
    }
  }
}

TEST(Selection, FrameBuffersAreReusedAcrossFramesWithTheSameResult) {
  const PointSet pts = splat_samples(torus_scene(), 8000, 2);
  const SphereTree tree = make_test_tree(pts);
  ThreadPool pool(2);
  const Camera near_cam = orbit_camera(tree.view_sphere, {.azimuth_deg = 0, .width = 64, .height = 48});
  const Camera far_cam = orbit_camera(tree.view_sphere,
                                      {.azimuth_deg = 90, .distance = 9, .width = 80, .height = 40});
  Frame reused, fresh;
  render(tree.view(), near_cam, {}, pool, reused);
  render(tree.view(), far_cam, {}, pool, reused);
  render(tree.view(), far_cam, {}, pool, fresh);
  EXPECT_TRUE(same_image(reused, fresh));
  EXPECT_EQ(stream_nodes(reused.splats), stream_nodes(fresh.splats));
}
