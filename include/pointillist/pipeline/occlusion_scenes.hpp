// The acceptance scenes of occlusion culling (../shared/specs/occlusion-simplification-hybrid.md
// §1.8) as layouts: which models stand where, and their camera paths. generate_scene.hpp
// writes them as scene files; this header is the geometry alone, so tests can check it.
//
//   wall   a 40 × 10 rectangle x ∈ [−20, 20], y ∈ [0, 10], z = 0 facing +z (grid spacing 0.02:
//          2001 × 501 points), then 100 scanned models at x = −18 + 4i, z = −4 − 4j
//          (i, j = 0..9, i outer), yaw 36°·(i + j). Path "": 180 frames, fov 30°: frames 0–59
//          eye (0, 2, 30) looking at (0, 2, 0); frame f ≥ 60 moves eye and target by
//          x = 40·(f − 59)/120 (x = 40 at frame 179).
//   city   16 × 16 blocks of 12 units, block (i, j) (i outer) covering [12i, 12i + 12] ×
//          [12j, 12j + 12]: a building [12i + 2, 12i + 10] × [12j + 2, 12j + 10] whose 4 façades
//          (south z = 12j + 2, north z = 12j + 10, west x = 12i + 2, east x = 12i + 10, in this
//          order) are stacks of h/2 panels facing outward, h = city_building_height(i, j); then
//          scanned models at (12i + 1, 12j + 1), (12i + 11, 12j + 1), (12i + 1, 12j + 11),
//          (12i + 11, 12j + 11), yaw 0. The panel is 8 × 2 (x ∈ [−4, 4], y ∈ [0, 2], z = 0
//          facing +z, spacing 0.05: 161 × 41 points); panel k of a façade (k = 0..h/2 − 1) is
//          translated to (façade centre, 2k, façade plane) and turned by yaw 180° (south),
//          0° (north), −90° (west) or 90° (east). No ground. Paths (fov 60°), with
//          yaw(f) = 20°·sin(2π·f/100) and view directions (sin yaw, 0, cos yaw):
//            "-walk"   300 frames: eye (96, 1.7, 2 + 188·f/299), looking along yaw(f);
//            "-static" 60 frames of the walk's frame 150;
//            "-fly"    200 frames: eye (96 + 120·sin θ, 60, 96 + 120·cos θ), θ = 2π·f/200,
//                      looking at (96, 0, 96);
//            "-turn"   90 frames at (96, 1.7, 96) looking along yaw 360°·f/90.
//   field  16 × 16 scanned models at x = −30 + 4i, z = −30 + 4j (i outer), yaw 0. Path "":
//          120 frames, fov 30°, orbiting (0, 1, 0) at elevation 45°, azimuth 360°·f/120, at
//          distance 1.05·R/sin 15° where R = √(31² + 1² + 31²) reaches every corner of the
//          models' boxes, so everything is in view.
//   row    32 scanned models at x = 0.6 (k even) or −0.6 (k odd), z = −3k, yaw 0. Path "":
//          30 frames, fov 30°, eye (0, 1, 5) looking at (0, 1, 0) (down −z).
//
// Scanned models are stood on y = 0 scaled to bounding radius 1 (stand_on_ground); a path's
// frames carry no up vector (+Y).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "pointillist/core/math.hpp"
#include "pointillist/core/point_set.hpp"
#include "pointillist/io/camera_path.hpp"

namespace pointillist {

enum class OcclusionScene { Wall, City, Field, Row };

// "wall", "city", "field", "row".
const char* occlusion_scene_name(OcclusionScene scene);

// A rectangle x ∈ [x0, x1], y ∈ [y0, y1] at z = 0 facing +z, sampled on a regular grid of
// round(extent / spacing) + 1 columns and rows spread over the exact extent.
struct GridRectangle {
  std::string name;  // names the model file: "wall", "panel"
  float x0 = 0, x1 = 1, y0 = 0, y1 = 1;
  float spacing = 1;  // world units, > 0
};
std::uint32_t grid_columns(const GridRectangle& grid);
std::uint32_t grid_rows(const GridRectangle& grid);

// A grid's splat radius as a multiple of its spacing: discs of radius s/√2 centred on a square
// grid of spacing s just cover it; 0.75 keeps a margin (as CloudRadiusOptions says for grids).
inline constexpr float kGridRadiusFactor = 0.75f;

// The grid's samples, row by row from y0: positions, normals +Z, radii kGridRadiusFactor × the
// larger of the two actual spacings. Throws OptionError for a spacing that is not positive and
// finite, an empty rectangle or more than 2^31 samples.
PointSet sample_grid(const GridRectangle& grid);

// One instance of a layout.
struct LayoutInstance {
  // Which model: grids[grid] of the layout, or (grid < 0) the next scanned model in turn: the
  // k-th scanned instance of a layout uses scanned model k mod (number of scanned models).
  int grid = -1;
  // A grid: its translation. A scanned model: the point on y = 0 below its box centre.
  Vec3f position;
  float yaw_deg = 0;  // about +Y
};

struct LayoutPath {
  std::string suffix;       // the file is NAME + suffix + ".path" ("" or "-walk" and so on)
  std::string description;  // one line for the file's comment
  CameraPath path;
};

struct SceneLayout {
  std::vector<GridRectangle> grids;
  std::vector<LayoutInstance> instances;
  std::vector<LayoutPath> paths;
};

// The layout of `scene` (above). `spacing_scale` multiplies the grid spacing of the wall and
// the panels (1 = the specification's; 10 makes files 100 times smaller, for tests). Throws
// OptionError when spacing_scale is not positive and finite.
SceneLayout occlusion_scene_layout(OcclusionScene scene, float spacing_scale = 1.0f);

// The hash of the city's building heights, a small integer mix of the block indices:
//   h = i·0x9E3779B1 + j·0x85EBCA77 (mod 2^32); h ^= h >> 15; h *= 0x2C1B3C6D; h ^= h >> 12.
std::uint32_t city_hash(std::uint32_t i, std::uint32_t j);
// The façade height of block (i, j): 6 + 2·(city_hash(i, j) mod 8), an even number 6..20.
int city_building_height(std::uint32_t i, std::uint32_t j);

// An instance transform (scene.hpp's translate, rotate_deg, scale).
struct Placement {
  Vec3f translate{0, 0, 0};
  Vec3f rotate_deg{0, 0, 0};
  float scale = 1.0f;
};

// How a model stands at `foot` (a point on y = 0): turned so its up axis `up` becomes +Y (a Z-up
// LAS scan is turned by −90° about x), then by yaw_deg about +Y, scaled so its view sphere
// (centre of `bounds`, the largest distance to a sample) has radius 1, moved so the centre of
// its box is above `foot` and its lowest sample on y = foot.y. For an up axis along a
// coordinate axis the lowest sample is the box's; for another, the lowest box corner (the model
// may then float a little). Throws Error when the model has no extent (empty bounds or view
// sphere radius 0) or `up` is not a direction.
Placement stand_on_ground(const Aabb& bounds, const Sphere& view_sphere, Vec3f up, Vec3f foot,
                          float yaw_deg);

}  // namespace pointillist
