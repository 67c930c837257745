// Small helpers shared by the render tests.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
#include <span>
#include <vector>

#include "pointillist/core/camera.hpp"
#include "pointillist/lod/sphere_tree.hpp"
#include "pointillist/render/render.hpp"
#include "pointillist/render/renderer.hpp"
#include "pointillist/scene/analytic.hpp"
#include "test_trees.hpp"

namespace pointillist::render_test {

constexpr double kPiD = 3.14159265358979323846;

// Eye at the origin looking down −Z with +Y up: eye space equals world space (right = +x,
// up = +y, depth = −z), exactly in float.
inline Camera axis_camera(int width, int height, float fov_deg = 60.0f) {
  Camera c;
  c.eye = {0, 0, 0};
  c.target = {0, 0, -1};
  c.up = {0, 1, 0};
  c.fov_deg = fov_deg;
  c.width = width;
  c.height = height;
  return c;
}

// f = (H/2) / tan(fov/2), in double.
inline double focal_px(const Camera& c) {
  return 0.5 * c.height / std::tan(0.5 * c.fov_deg * kPiD / 180.0);
}

inline SphereNode leaf(Vec3f center, float radius, Vec3f normal, Rgb8 color = {}) {
  SphereNode n;
  n.center = center;
  n.radius = radius;
  n.normal = normal;
  n.cone_sin = 0;
  n.color = color;
  return n;
}

// A tree that is a single leaf.
inline SphereTree single_leaf_tree(const SphereNode& n, bool has_colors = false) {
  SphereTree t;
  t.nodes = {n};
  t.leaf_count = 1;
  t.has_colors = has_colors;
  t.bounds.extend(n.center);
  t.view_sphere = {n.center, n.radius};
  return t;
}

// A root (no cone bound, sphere around everything) over the given leaves.
inline SphereTree root_with_leaves(const std::vector<SphereNode>& leaves, bool has_colors = false) {
  SphereTree t;
  SphereNode root;
  Aabb box;
  for (const SphereNode& l : leaves) box.extend(l.center);
  root.center = box.center();
  for (const SphereNode& l : leaves) {
    root.radius = std::max(root.radius, distance(root.center, l.center) + l.radius + 1e-4f);
  }
  root.normal = {0, 0, 1};
  root.cone_sin = 2.0f;
  root.first_child = 1;
  root.child_count = static_cast<std::uint8_t>(leaves.size());
  t.nodes.push_back(root);
  for (const SphereNode& l : leaves) t.nodes.push_back(l);
  t.leaf_count = leaves.size();
  t.depth = 1;
  t.has_colors = has_colors;
  t.bounds = box;
  t.view_sphere = {box.center(), root.radius};
  return t;
}

// Samples of an analytic scene with exact normals and splat radii from the sample density:
// r = spacing_factor·sqrt(area / (π·n)), so the discs cover the surface about spacing_factor²
// times over.
inline PointSet splat_samples(const AnalyticScene& scene, std::size_t n, std::uint64_t seed,
                              float spacing_factor = 2.0f) {
  SurfaceSamples s = sample_scene(scene, n, seed);
  PointSet p = std::move(s.points);
  p.normals = std::move(s.true_normals);
  const float r = spacing_factor *
                  static_cast<float>(std::sqrt(surface_area(scene) / (kPiD * static_cast<double>(n))));
  p.radii.assign(p.positions.size(), r);
  return p;
}

// All stream node indices in stream order.
inline std::vector<std::uint32_t> stream_nodes(const SplatStream& s) {
  std::vector<std::uint32_t> out;
  for (std::size_t c = 0; c < s.chunk_count; ++c) {
    out.insert(out.end(), s.chunks[c].node.begin(), s.chunks[c].node.begin() + s.chunks[c].count);
  }
  return out;
}

inline bool covered(const Frame& f, int i, int j) {
  return std::isfinite(f.depth[static_cast<std::size_t>(j) * f.width + i]);
}

// Whether two captured frames (anything with `color` and `depth` vectors) are the same bits.
template <class Shot>
bool same_bits(const Shot& a, const Shot& b) {
  return a.color.size() == b.color.size() && a.depth.size() == b.depth.size() &&
         std::memcmp(a.color.data(), b.color.data(), a.color.size() * sizeof(a.color[0])) == 0 &&
         std::memcmp(a.depth.data(), b.depth.data(), a.depth.size() * sizeof(a.depth[0])) == 0;
}

// A frame copied out of the renderer's Frame: colour, depth, splat count, occlusion counts.
struct Shot {
  std::vector<Rgb8> color;
  std::vector<float> depth;
  std::uint64_t splats = 0;
  OcclusionStats occlusion;
};
inline Shot capture(const Frame& f) {
  return {std::vector<Rgb8>(f.color.begin(), f.color.end()),
          std::vector<float>(f.depth.begin(), f.depth.end()), f.stats.splats, f.stats.occlusion};
}

// A strafe along +x by `span`, eye and target moving together, looking down −z.
struct StrafePath {
  float span = 0, eye_y = 0, target_y = 0, distance = 0, fov_deg = 0;
  int width = 0, height = 0;
  // Frame k of `frames` (frames ≥ 2).
  Camera camera(int k, int frames) const {
    Camera c;
    const float x = span * float(k) / float(frames - 1);
    c.eye = {x, eye_y, distance};
    c.target = {x, target_y, 0.0f};
    c.fov_deg = fov_deg;
    c.width = width;
    c.height = height;
    return c;
  }
};

// `frames` frames of `path` rendered by one Renderer (visibility kept from frame to frame).
inline std::vector<Shot> render_path(std::span<const SceneInstance> instances,
                                     const StrafePath& path, const RenderSettings& settings,
                                     const FrameSettings& fs, unsigned threads, int frames) {
  ThreadPool pool(threads);
  Renderer renderer;
  Frame frame;
  std::vector<Shot> out;
  for (int k = 0; k < frames; ++k) {
    renderer.render(instances, path.camera(k, frames), settings, fs, pool, frame);
    out.push_back(capture(frame));
  }
  return out;
}

// Renders paged `instances` (every model paged) until every page the view needs is resident,
// then `more` frames; returns the last frame and the pages loaded.
inline Shot settle_paged(std::span<const SceneInstance> instances, const Camera& camera,
                         const FrameSettings& fs, int more, ThreadPool& pool,
                         std::uint64_t& pages_loaded) {
  Renderer renderer({.page_all = true});
  Frame frame;
  for (int k = 0; k < 80 && more >= 0; ++k) {
    renderer.render(instances, camera, {}, fs, pool, frame);
    if (renderer.complete()) --more;
    renderer.load_requested(pool);
  }
  EXPECT_TRUE(renderer.complete());
  pages_loaded = renderer.paging_stats().cache.pages_loaded;
  return capture(frame);
}

}  // namespace pointillist::render_test
