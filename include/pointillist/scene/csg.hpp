// Constructive-solid-geometry test scenes with exact face labels (specs/sharp-features.md §4.1,
// §4.2): boxes, spheres and capped cylinders combined by one operation, sampled near-uniformly
// (J mode, as in the dissertation) or uniformly at random (R mode), each sample with its exact
// normal and the label of the primitive face it lies on; and an exact ray caster that returns
// the same labels, the reference for the feature-aware renderer.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "pointillist/core/camera.hpp"
#include "pointillist/core/math.hpp"
#include "pointillist/core/point_set.hpp"

namespace pointillist {

enum class PrimitiveKind {
  Box,       // centre ± half; faces −x, +x, −y, +y, −z, +z (labels 0..5)
  Sphere,    // centre, radius; one face
  Cylinder,  // centre, radius, half_length along `axis`; faces side, −cap, +cap (labels 0..2)
  // Open surfaces (no inside; only in CsgOp::Separate scenes):
  Quad,      // the rectangle `center` + s·edge_u + t·edge_v, s, t in [0, 1]; one face, normal
             // along cross(edge_u, edge_v)
  Crease,    // spec T15's height field y = 0.5·|x|·max(0, 1 − z), x in [−1, 1], z in [0, 2],
             // moved by `center`; normals up (+y); faces x < 0, x > 0 (where z < 1: the two
             // sides of a crease that fades out at z = 1) and the flat part z ≥ 1
};

struct Primitive {
  PrimitiveKind kind = PrimitiveKind::Box;
  Vec3f center;
  Vec3f half{1, 1, 1};  // Box
  float radius = 1;     // Sphere, Cylinder
  float half_length = 1;  // Cylinder
  int axis = 1;         // Cylinder: 0 = x, 1 = y, 2 = z
  Vec3f edge_u, edge_v;  // Quad
  // Box: the J-mode spacing h of the faces normal to x, y and z (0: the scene's), for a cube of
  // mixed density (spec T2); R mode draws the same counts.
  Vec3f face_spacing{0, 0, 0};
};

enum class CsgOp {
  Union,         // the boundary of the union of all primitives
  Intersection,  // of the intersection of all
  Difference,    // the first primitive minus all the others
  Separate,      // no operation: every primitive's whole surface (interpenetrating surfaces)
};

struct CsgScene {
  std::string name;
  std::vector<Primitive> primitives;
  CsgOp op = CsgOp::Union;
  float spacing = 0.04f;  // h, the J-mode sample spacing of the scene
  // Scanner-like noise on the samples (spec T14), drawn after sampling from a stream of its own
  // (the noise-free samples stay those of the scene without it): each normal tilted by an angle
  // of standard deviation `normal_noise_degrees` about a uniformly random tangent axis, each
  // position moved along its exact normal by a normal deviate of standard deviation
  // `position_noise`·spacing. Labels stay; the reference stays the exact surface.
  float normal_noise_degrees = 0;
  float position_noise = 0;

  // Number of face labels: primitive k's faces are labels first_label(k) ...
  std::uint32_t label_count() const;
  std::uint32_t first_label(std::size_t primitive) const;
};

// The scenes of spec §4.2 by id: "T1" cube, "T2" cube of mixed density, "T3" cylinder, "T4"
// plate with a hole, "T5" union and "T6" intersection of two spheres, "T7" bitten cube, "T8"
// step, "T9" two interpenetrating spheres, "T10" crossed capped cylinders, "T11" thin slab,
// "T12-θ" wedge of two strips with interior dihedral θ degrees (20, 30, 45, 60, 90, 120, 150,
// 165; "T12" is 90), "T13" smooth sphere, "T14-2" and "T14-5" the cube with 2° and 5° noise
// ("T14" is 2°), "T15" open crease. Throws OptionError naming the known ids for another.
CsgScene csg_scene(const std::string& id);
std::vector<std::string> csg_scene_ids();

enum class SamplingMode {
  Jittered,  // J: round(area/h²) samples a face on a grid jittered by ±0.25·h (spheres: a
             // Fibonacci lattice jittered by 0.1·h); radius 1.0 × mean 5-NN distance
  Random,    // R: the same count uniformly at random
};

struct CsgSamples {
  PointSet points;  // positions and exact outward normals (no radii: prep computes them)
  std::vector<std::uint32_t> labels;  // face label of each sample (ground truth)
};

// Samples of the scene's boundary from a fixed seed: each primitive face is sampled over its
// whole area and a sample kept iff it lies on the result's boundary (union: outside every other
// primitive; intersection: inside every other; difference: the first primitive's samples
// outside the others, the others' inside the first with their normals flipped).
CsgSamples sample_csg(const CsgScene& scene, SamplingMode mode, std::uint64_t seed);

// The result's surfaces as groups of face labels: faces of different primitives on one plane
// (the step's L-shaped front is two boxes' faces) are one surface of the result, so they share
// a group; any other face is a group of its own. Groups are numbered 0, 1, ... in label order;
// one entry per label of the scene (planes are told apart from the samples' normals and
// positions, to 0.01; a face with no samples is its own group).
std::vector<std::uint32_t> csg_surface_groups(const CsgScene& scene, const CsgSamples& samples);

// Whether point p of the plane of face `label` lies on that face of the result: within the
// face's extent (a box face's rectangle, a cap's disc) and on the result's boundary. Exact for
// the planar faces (box faces, caps); for a curved face (sphere, cylinder side) only the
// boundary test applies. The ground truth of which part of a splat must be clipped.
bool csg_face_contains(const CsgScene& scene, std::uint32_t label, Vec3f p);
// Whether face `label` is planar (a box face, a cap, a quad, the crease's flat part).
bool csg_face_is_planar(const CsgScene& scene, std::uint32_t label);

struct CsgHit {
  float t = 0;        // distance along the unit direction
  Vec3f normal;       // exact outward normal of the result's surface
  std::uint32_t label = 0;
};

// First point of the scene's boundary along origin + t·dir (dir unit, t > 0), found by
// classifying the intervals every primitive cuts out of the ray.
std::optional<CsgHit> ray_cast_csg(const CsgScene& scene, Vec3f origin, Vec3f dir);

// The exact image: for each pixel centre, the hit of the camera ray.
struct CsgImage {
  int width = 0, height = 0;
  std::vector<std::uint32_t> label;  // face label, kNoLabel where the ray misses
  std::vector<float> depth;          // along the view direction (CameraFrame::depth), +inf
  std::vector<Vec3f> normal;
};
constexpr std::uint32_t kNoLabel = 0xffffffffu;
CsgImage ray_cast_csg_image(const CsgScene& scene, const Camera& camera);

// Bounding box of the primitives.
Aabb csg_bounds(const CsgScene& scene);

}  // namespace pointillist
