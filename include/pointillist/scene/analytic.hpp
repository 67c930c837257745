// Analytic test and demo scenes: shapes with exact surfaces, exact normals and exact ray casting.
// They are the oracles for normal estimation, coverage and image-quality tests, and the built-in
// demo model (`pointillist demo`).
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "pointillist/core/camera.hpp"
#include "pointillist/core/math.hpp"
#include "pointillist/core/point_set.hpp"

namespace pointillist {

enum class ShapeKind {
  Sphere,  // radius a
  Torus,   // major radius a (centre to tube centre), minor radius b, axis = local y
  Cube,    // half side a, sharp edges and corners
};

struct AnalyticShape {
  ShapeKind kind = ShapeKind::Sphere;
  Vec3f center;
  float a = 1.0f;
  float b = 0.0f;
  // Orthonormal local frame (columns of the rotation local -> world).
  Vec3f axis_x{1, 0, 0}, axis_y{0, 1, 0}, axis_z{0, 0, 1};
};

struct AnalyticScene {
  std::vector<AnalyticShape> shapes;
};

// The demo scene: a sphere, a torus tilted 60° and a cube turned 30°, side by side, not touching.
AnalyticScene demo_scene();
// A stand-in statue for scenes of many instances (generate --scene wall|city|field|row without
// models): a cube pedestal (half side 0.35) standing on y = 0, a sphere (radius 0.4) on it and a
// ring (torus 0.55 / 0.1) around the sphere tilted 60° about x, so its front and side differ.
AnalyticScene statue_scene();
// Single shapes centred at the origin (for focused tests).
AnalyticScene sphere_scene(float radius = 1.0f);
AnalyticScene torus_scene(float major = 1.0f, float minor = 0.35f);
AnalyticScene cube_scene(float half_side = 1.0f);

// Total surface area of the scene.
double surface_area(const AnalyticScene& scene);

struct SurfaceSamples {
  PointSet points;                  // positions only (no normals, colors, radii)
  std::vector<Vec3f> true_normals;  // exact outward unit normal of each sample
  std::vector<std::uint32_t> shape_ids;
  // Distance from each sample to the nearest sharp edge of its shape (+inf for smooth shapes).
  std::vector<float> edge_distance;
};

// `count` samples spread uniformly by area over all shapes (independent uniform draws), from a
// fixed seed, so the same arguments always give the same samples.
SurfaceSamples sample_scene(const AnalyticScene& scene, std::size_t count, std::uint64_t seed);

struct RayHit {
  float t = 0;        // distance along the (unit) direction
  Vec3f normal;       // exact outward unit normal
  std::uint32_t shape = 0;
};

// First intersection of the ray origin + t·dir (dir unit length, t > 0) with the scene.
std::optional<RayHit> ray_cast(const AnalyticScene& scene, Vec3f origin, Vec3f dir);

// Exact per-pixel reference: for each pixel centre, the hit of the camera ray (or none).
struct RayCastImage {
  int width = 0, height = 0;
  std::vector<std::uint8_t> covered;  // 1 where the ray hits a surface
  std::vector<float> depth;           // depth along the view direction (CameraFrame::depth), +inf
  std::vector<Vec3f> normal;          // exact normal at the hit
};
RayCastImage ray_cast_image(const AnalyticScene& scene, const Camera& camera);

// Bounding box of the scene's surfaces.
Aabb scene_bounds(const AnalyticScene& scene);

struct AnalyticClosest {
  Vec3f point;     // nearest surface point (world)
  Vec3f normal;    // unit outward normal there; off the surface near a cube's edge or corner, the
                   // direction from the point to the query (the distance's gradient)
  float distance;  // unsigned distance from the query to `point` (world units)
};

// Exact closest surface point to `p` over all shapes, each in its own frame (center, axis_x/y/z):
// sphere |‖p−c‖ − a|; torus |√((√(x²+z²) − a)² + y²) − b| (a ≥ b); cube: the box's nearest point,
// points inside it projected to the nearest face (ties go to the lower axis). Where several
// surface points are equally near (a sphere's or torus' centre, the torus' axis) one of them is
// returned; ties between shapes go to the lower shape index. An empty scene gives distance +inf.
AnalyticClosest closest_point(const AnalyticScene& scene, Vec3f p);

}  // namespace pointillist
