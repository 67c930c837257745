// The layouts of the occlusion-culling acceptance scenes (see occlusion_scenes.hpp).
#include "pointillist/pipeline/occlusion_scenes.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "pointillist/core/error.hpp"
#include "pointillist/pipeline/scene.hpp"

namespace pointillist {
namespace {

constexpr double kPiD = 3.14159265358979323846;

std::uint32_t grid_count(float extent, float spacing) {
  if (!(spacing > 0.0f) || !std::isfinite(spacing) || !(extent > 0.0f) ||
      !std::isfinite(extent)) {
    throw OptionError("grid: extent " + std::to_string(extent) + " and spacing " +
                      std::to_string(spacing) + " must be positive finite numbers");
  }
  const double steps = std::round(double(extent) / double(spacing));
  if (steps > double(1u << 30)) {
    throw OptionError("grid: spacing " + std::to_string(spacing) + " is too fine for extent " +
                      std::to_string(extent));
  }
  return static_cast<std::uint32_t>(std::max(1.0, steps)) + 1;
}

Vec3f direction_of_yaw(double yaw_deg) {
  const double a = yaw_deg * kPiD / 180.0;
  return {static_cast<float>(std::sin(a)), 0.0f, static_cast<float>(std::cos(a))};
}

CameraPathFrame looking(Vec3f eye, Vec3f target) { return {eye, target, std::nullopt, 0}; }

LayoutPath wall_path() {
  LayoutPath p{"", "wall: 180 frames, 0-59 static at eye (0 2 30) looking at (0 2 0), then eye "
               "and target strafe to x = 40", {}};
  p.path.fov_deg = 30.0f;
  for (int f = 0; f < 180; ++f) {
    const float x = f < 60 ? 0.0f : static_cast<float>(40.0 * (f - 59) / 120.0);
    p.path.frames.push_back(looking({x, 2, 30}, {x, 2, 0}));
  }
  return p;
}

// The street walk P1's frame f: eye (96, 1.7, 2 + 188·f/299), yaw 20°·sin(2π·f/100).
CameraPathFrame city_walk_frame(int f) {
  const Vec3f eye{96.0f, 1.7f, static_cast<float>(2.0 + 188.0 * f / 299.0)};
  const double yaw = 20.0 * std::sin(2.0 * kPiD * f / 100.0);
  return looking(eye, eye + direction_of_yaw(yaw));
}

std::vector<LayoutPath> city_paths() {
  LayoutPath walk{"-walk", "city P1, street walk: 300 frames, eye (96 1.7 2) to (96 1.7 190), "
                  "yaw 20 deg * sin(2 pi f / 100) from +z", {}};
  for (int f = 0; f < 300; ++f) walk.path.frames.push_back(city_walk_frame(f));
  LayoutPath still{"-static", "city P2, static: 60 frames at the walk's frame 150", {}};
  still.path.frames.assign(60, city_walk_frame(150));
  LayoutPath fly{"-fly", "city P3, fly-over: 200 frames, eye at height 60 circling (96 0 96) at "
                 "radius 120, looking at the centre", {}};
  for (int f = 0; f < 200; ++f) {
    const double a = 2.0 * kPiD * f / 200.0;
    fly.path.frames.push_back(looking({static_cast<float>(96.0 + 120.0 * std::sin(a)), 60.0f,
                                       static_cast<float>(96.0 + 120.0 * std::cos(a))},
                                      {96, 0, 96}));
  }
  LayoutPath turn{"-turn", "city P4, turn: 90 frames at (96 1.7 96), yaw 360 deg * f / 90 from "
                  "+z", {}};
  for (int f = 0; f < 90; ++f) {
    const Vec3f eye{96.0f, 1.7f, 96.0f};
    turn.path.frames.push_back(looking(eye, eye + direction_of_yaw(360.0 * f / 90.0)));
  }
  std::vector<LayoutPath> paths = {walk, still, fly, turn};
  for (LayoutPath& p : paths) p.path.fov_deg = 60.0f;
  return paths;
}

void add_city(SceneLayout& layout, float spacing_scale) {
  layout.grids.push_back({"panel", -4, 4, 0, 2, 0.05f * spacing_scale});
  for (std::uint32_t i = 0; i < 16; ++i) {
    for (std::uint32_t j = 0; j < 16; ++j) {
      const float x = 12.0f * static_cast<float>(i), z = 12.0f * static_cast<float>(j);
      const int panels = city_building_height(i, j) / 2;
      // South, north, west, east: (façade centre, yaw turning the panel's +z outward).
      const std::pair<Vec3f, float> facades[4] = {{{x + 6, 0, z + 2}, 180.0f},
                                                  {{x + 6, 0, z + 10}, 0.0f},
                                                  {{x + 2, 0, z + 6}, -90.0f},
                                                  {{x + 10, 0, z + 6}, 90.0f}};
      for (const auto& [centre, yaw] : facades) {
        for (int k = 0; k < panels; ++k) {
          layout.instances.push_back({0, centre + Vec3f{0, 2.0f * static_cast<float>(k), 0}, yaw});
        }
      }
      for (const Vec3f corner : {Vec3f{x + 1, 0, z + 1}, Vec3f{x + 11, 0, z + 1},
                                 Vec3f{x + 1, 0, z + 11}, Vec3f{x + 11, 0, z + 11}}) {
        layout.instances.push_back({-1, corner, 0.0f});
      }
    }
  }
  layout.paths = city_paths();
}

void add_field(SceneLayout& layout) {
  for (int i = 0; i < 16; ++i) {
    for (int j = 0; j < 16; ++j) {
      layout.instances.push_back(
          {-1, {static_cast<float>(-30 + 4 * i), 0, static_cast<float>(-30 + 4 * j)}, 0.0f});
    }
  }
  // The models' boxes lie in [−31, 31] × [0, 2] × [−31, 31]: a sphere of radius R around
  // (0, 1, 0) holds them, and at 1.05·R / sin(fov/2) it fits the view (as orbit_camera frames).
  const double radius = std::sqrt(31.0 * 31.0 + 1.0 + 31.0 * 31.0);
  const double distance = 1.05 * radius / std::sin(15.0 * kPiD / 180.0);
  const double el = 45.0 * kPiD / 180.0;
  LayoutPath p{"", "field: 120 frames orbiting (0 1 0) at elevation 45 deg, everything in view",
               {}};
  p.path.fov_deg = 30.0f;
  for (int f = 0; f < 120; ++f) {
    const double az = 2.0 * kPiD * f / 120.0;
    const Vec3f eye{static_cast<float>(distance * std::cos(el) * std::sin(az)),
                    static_cast<float>(1.0 + distance * std::sin(el)),
                    static_cast<float>(distance * std::cos(el) * std::cos(az))};
    p.path.frames.push_back(looking(eye, {0, 1, 0}));
  }
  layout.paths = {p};
}

void add_row(SceneLayout& layout) {
  for (int k = 0; k < 32; ++k) {
    layout.instances.push_back(
        {-1, {k % 2 == 0 ? 0.6f : -0.6f, 0, static_cast<float>(-3 * k)}, 0.0f});
  }
  LayoutPath p{"", "row: 30 frames, eye (0 1 5) looking down -z", {}};
  p.path.fov_deg = 30.0f;
  p.path.frames.assign(30, looking({0, 1, 5}, {0, 1, 0}));
  layout.paths = {p};
}

// Rotation angles (x, y, z in degrees, applied x first as make_transform does) of R =
// Ry(yaw)·A, where A turns `up` onto +Y along the shortest arc.
Vec3f turn_up_then_yaw(Vec3f up, float yaw_deg) {
  const float up_length = length(up);
  if (!(up_length > 0.0f) || !std::isfinite(up_length)) {
    throw Error("the model's up axis is not a direction");
  }
  const Vec3f u = up / up_length;
  if (u == Vec3f{0, 1, 0}) return {0, yaw_deg, 0};
  if (u == Vec3f{0, 0, 1}) return {-90, yaw_deg, 0};  // Rx(−90°) takes +Z to +Y
  // Rodrigues: A = I·c + [k]×·s + k·kᵀ·(1 − c) about k = u × Y / |u × Y|, c = u·Y.
  double a[3][3];
  const double ux = u.x, uy = u.y, uz = u.z;
  double kx = -uz, kz = ux;  // u × (0, 1, 0)
  const double ky = 0;
  const double s = std::sqrt(kx * kx + kz * kz), c = uy;
  if (s < 1e-12) {
    kx = 1;  // u = −Y: half a turn about x (c = −1 gives diag(1, −1, −1) below)
    kz = 0;
  } else {
    kx /= s;
    kz /= s;
  }
  const double k[3] = {kx, ky, kz}, t = 1 - c;
  const double cross_k[3][3] = {{0, -kz, ky}, {kz, 0, -kx}, {-ky, kx, 0}};
  for (int r = 0; r < 3; ++r) {
    for (int q = 0; q < 3; ++q) {
      a[r][q] = (r == q ? c : 0.0) + cross_k[r][q] * s + k[r] * k[q] * t;
    }
  }
  const double yaw = yaw_deg * kPiD / 180.0, cy = std::cos(yaw), sy = std::sin(yaw);
  const double ry[3][3] = {{cy, 0, sy}, {0, 1, 0}, {-sy, 0, cy}};
  double m[3][3];
  for (int r = 0; r < 3; ++r) {
    for (int q = 0; q < 3; ++q) {
      m[r][q] = ry[r][0] * a[0][q] + ry[r][1] * a[1][q] + ry[r][2] * a[2][q];
    }
  }
  // m = Rz(γ)·Ry(β)·Rx(α): m[2][0] = −sin β, m[2][1] = cos β sin α, m[2][2] = cos β cos α,
  // m[1][0] = sin γ cos β, m[0][0] = cos γ cos β; at cos β = 0 take α = 0.
  const double beta = std::asin(std::clamp(-m[2][0], -1.0, 1.0));
  double alpha = 0, gamma = 0;
  if (std::cos(beta) > 1e-9) {
    alpha = std::atan2(m[2][1], m[2][2]);
    gamma = std::atan2(m[1][0], m[0][0]);
  } else {
    gamma = std::atan2(-m[0][1], m[1][1]);
  }
  const double to_deg = 180.0 / kPiD;
  return {static_cast<float>(alpha * to_deg), static_cast<float>(beta * to_deg),
          static_cast<float>(gamma * to_deg)};
}

}  // namespace

const char* occlusion_scene_name(OcclusionScene scene) {
  switch (scene) {
    case OcclusionScene::Wall: return "wall";
    case OcclusionScene::City: return "city";
    case OcclusionScene::Field: return "field";
    case OcclusionScene::Row: return "row";
  }
  return "?";
}

std::uint32_t grid_columns(const GridRectangle& g) { return grid_count(g.x1 - g.x0, g.spacing); }
std::uint32_t grid_rows(const GridRectangle& g) { return grid_count(g.y1 - g.y0, g.spacing); }

PointSet sample_grid(const GridRectangle& g) {
  const std::uint32_t columns = grid_columns(g), rows = grid_rows(g);
  if (std::uint64_t(columns) * rows > (std::uint64_t(1) << 31)) {
    throw OptionError("grid " + g.name + ": " + std::to_string(columns) + " x " +
                      std::to_string(rows) + " samples are more than a model holds (2^31)");
  }
  const double step_x = (double(g.x1) - g.x0) / (columns - 1);
  const double step_y = (double(g.y1) - g.y0) / (rows - 1);
  const float radius = kGridRadiusFactor * static_cast<float>(std::max(step_x, step_y));
  PointSet points;
  const std::size_t n = std::size_t(columns) * rows;
  points.positions.reserve(n);
  for (std::uint32_t r = 0; r < rows; ++r) {
    for (std::uint32_t c = 0; c < columns; ++c) {
      points.positions.push_back({static_cast<float>(g.x0 + step_x * c),
                                  static_cast<float>(g.y0 + step_y * r), 0.0f});
    }
  }
  points.normals.assign(n, Vec3f{0, 0, 1});
  points.radii.assign(n, radius);
  return points;
}

SceneLayout occlusion_scene_layout(OcclusionScene scene, float spacing_scale) {
  if (!(spacing_scale > 0.0f) || !std::isfinite(spacing_scale)) {
    throw OptionError("spacing scale " + std::to_string(spacing_scale) +
                      " must be a positive number (1 = the specification's grid spacing)");
  }
  SceneLayout layout;
  switch (scene) {
    case OcclusionScene::Wall:
      layout.grids.push_back({"wall", -20, 20, 0, 10, 0.02f * spacing_scale});
      layout.instances.push_back({0, {0, 0, 0}, 0.0f});
      for (int i = 0; i < 10; ++i) {
        for (int j = 0; j < 10; ++j) {
          layout.instances.push_back({-1,
                                      {static_cast<float>(-18 + 4 * i), 0,
                                       static_cast<float>(-4 - 4 * j)},
                                      36.0f * static_cast<float>(i + j)});
        }
      }
      layout.paths = {wall_path()};
      break;
    case OcclusionScene::City: add_city(layout, spacing_scale); break;
    case OcclusionScene::Field: add_field(layout); break;
    case OcclusionScene::Row: add_row(layout); break;
  }
  return layout;
}

std::uint32_t city_hash(std::uint32_t i, std::uint32_t j) {
  std::uint32_t h = i * 0x9E3779B1u + j * 0x85EBCA77u;
  h ^= h >> 15;
  h *= 0x2C1B3C6Du;
  h ^= h >> 12;
  return h;
}

int city_building_height(std::uint32_t i, std::uint32_t j) {
  return 6 + 2 * static_cast<int>(city_hash(i, j) % 8);
}

Placement stand_on_ground(const Aabb& bounds, const Sphere& view_sphere, Vec3f up, Vec3f foot,
                          float yaw_deg) {
  if (bounds.empty() || !(view_sphere.radius > 0.0f) || !std::isfinite(view_sphere.radius)) {
    throw Error("the model has no extent (all its samples are at one point); it cannot be "
                "scaled to radius 1");
  }
  Placement p;
  p.rotate_deg = turn_up_then_yaw(up, yaw_deg);
  p.scale = 1.0f / view_sphere.radius;
  // The rotation the renderer will apply (floats from these angles), so the model stands
  // exactly where it is drawn.
  const InstanceTransform t = make_transform({0, 0, 0}, p.rotate_deg, p.scale);
  float lowest = std::numeric_limits<float>::max();
  for (int corner = 0; corner < 8; ++corner) {
    const Vec3f q{corner & 1 ? bounds.hi.x : bounds.lo.x, corner & 2 ? bounds.hi.y : bounds.lo.y,
                  corner & 4 ? bounds.hi.z : bounds.lo.z};
    lowest = std::min(lowest, t.apply(q).y);
  }
  const Vec3f centre = t.apply(bounds.center());
  p.translate = {foot.x - centre.x, foot.y - lowest, foot.z - centre.z};
  return p;
}

}  // namespace pointillist
