// generate_scene: the written scene files, read back with read_scene, against the formulas of
// the occlusion-culling specification (§1.8), computed here; the models' own samples (made by
// the test, or regenerated from the statue's seed) show where each instance stands.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include "pointillist/core/error.hpp"
#include "pointillist/io/camera_path.hpp"
#include "pointillist/io/ply.hpp"
#include "pointillist/pipeline/generate_scene.hpp"
#include "pointillist/pipeline/scene.hpp"
#include "pointillist/scene/analytic.hpp"
#include "testing/testing.hpp"

using namespace pointillist;

namespace {

constexpr double kPiD = 3.14159265358979323846;
constexpr float kTolerance = 1e-4f;

struct Generated {
  GeneratedScene result;
  Scene scene;
};

Generated generate(OcclusionScene kind, const std::string& json,
                   std::vector<std::string> models = {}, std::size_t statue_points = 400) {
  ThreadPool pool(2);
  GenerateSceneOptions o;
  o.scene = kind;
  o.output = json;
  o.models = std::move(models);
  o.statue_points = statue_points;
  o.spacing_scale = 10;
  Generated g{generate_scene(o, pool), {}};
  g.scene = read_scene(json, {}, pool, Progress::none());
  return g;
}

// What an instance's samples look like in the world.
struct Placed {
  float lowest_y = 0;
  Vec3f centre;      // the model's bounding sphere's centre (its box centre), placed
  float radius = 0;  // the largest distance from it to a placed sample
  Vec3f box_extent;  // of the placed samples
};

Placed place(const InstanceTransform& t, const std::vector<Vec3f>& samples) {
  Aabb own, placed;
  for (const Vec3f& p : samples) {
    own.extend(p);
    placed.extend(t.apply(p));
  }
  Placed out{placed.lo.y, t.apply(own.center()), 0, placed.extent()};
  for (const Vec3f& p : samples) {
    out.radius = std::max(out.radius, distance(t.apply(p), out.centre));
  }
  return out;
}

// The generated statue's samples, made again from its seed (generate_scene's default is 1).
std::vector<Vec3f> statue_samples(std::size_t n) {
  return sample_scene(statue_scene(), n, 1).points.positions;
}

void expect_near(Vec3f got, Vec3f want, float tolerance = kTolerance) {
  EXPECT_NEAR(got.x, want.x, tolerance);
  EXPECT_NEAR(got.y, want.y, tolerance);
  EXPECT_NEAR(got.z, want.z, tolerance);
}

Vec3f yaw_direction(double yaw_deg) {
  return {float(std::sin(yaw_deg * kPiD / 180)), 0, float(std::cos(yaw_deg * kPiD / 180))};
}

// The city's height hash as occlusion_scenes.hpp defines it.
int city_height(std::uint32_t i, std::uint32_t j) {
  std::uint32_t h = i * 0x9E3779B1u + j * 0x85EBCA77u;
  h ^= h >> 15;
  h *= 0x2C1B3C6Du;
  h ^= h >> 12;
  return 6 + 2 * int(h % 8);
}

// A façade panel as a key: its box (mm) and its outward normal.
using PanelKey = std::array<long, 9>;
PanelKey panel_key(Vec3f lo, Vec3f hi, Vec3f normal) {
  const auto mm = [](float v) { return std::lround(v * 1000.0f); };
  return {mm(lo.x), mm(lo.y), mm(lo.z), mm(hi.x), mm(hi.y), mm(hi.z),
          std::lround(normal.x), std::lround(normal.y), std::lround(normal.z)};
}

}  // namespace

TEST(OcclusionScenes, WallInstancesStandWhereTheSpecificationSays) {
  pointillist::testing::TempDir dir;
  const Generated g = generate(OcclusionScene::Wall, dir.file("wall.json"));
  const auto instances = g.scene.instances();
  ASSERT_EQ(instances.size(), 101u);
  EXPECT_EQ(g.result.scanned_instance_count, 100u);
  // The wall: one untransformed instance of a 40 × 10 grid at spacing 0.2 (0.02 × 10).
  EXPECT_TRUE(instances[0].transform.is_identity());
  const SphereTreeView& wall = instances[0].model->tree;
  EXPECT_EQ(wall.leaf_count, 201u * 51u);
  expect_near(wall.bounds.lo, {-20, 0, 0});
  expect_near(wall.bounds.hi, {20, 10, 0});
  const std::vector<Vec3f> samples = statue_samples(400);
  for (int i = 0; i < 10; ++i) {
    for (int j = 0; j < 10; ++j) {
      SCOPED_TRACE("i " + std::to_string(i) + ", j " + std::to_string(j));
      const InstanceTransform& t = instances[1 + 10 * i + j].transform;
      const Placed p = place(t, samples);
      EXPECT_NEAR(p.lowest_y, 0.0f, kTolerance);
      EXPECT_NEAR(p.radius, 1.0f, kTolerance);
      EXPECT_NEAR(p.centre.x, -18.0f + 4.0f * i, kTolerance);
      EXPECT_NEAR(p.centre.z, -4.0f - 4.0f * j, kTolerance);
      // Yaw about +Y: +X turns to (cos a, 0, −sin a).
      const double a = 36.0 * (i + j) * kPiD / 180.0;
      expect_near(t.rotate({1, 0, 0}), {float(std::cos(a)), 0, float(-std::sin(a))}, 1e-5f);
    }
  }
  const CameraPath path = read_camera_path(dir.file("wall.path"));
  ASSERT_EQ(path.frames.size(), 180u);
  EXPECT_EQ(path.fov_deg.value_or(0), 30.0f);
  for (int f : {0, 30, 59, 60, 100, 179}) {
    SCOPED_TRACE("frame " + std::to_string(f));
    const float x = f < 60 ? 0.0f : 40.0f * float(f - 59) / 120.0f;
    expect_near(path.frames[f].eye, {x, 2, 30});
    expect_near(path.frames[f].target, {x, 2, 0});
  }
  expect_near(path.frames[179].eye, {40, 2, 30});
}

TEST(OcclusionScenes, ZUpAndYUpModelsAlternateTurnedUprightOnTheGround) {
  pointillist::testing::TempDir dir;
  // A Z-up scan (as LAS files are), tall along z, far from the origin; and a Y-up one.
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  PointSet tall, flat;
  tall.up = {0, 0, 1};
  for (int n = 0; n < 1500; ++n) {
    tall.positions.push_back({10 + u(rng), 20 + 0.5f * u(rng), 5 + 3 * u(rng)});
    flat.positions.push_back({-1 + 2 * u(rng), 3 + u(rng), 0.2f * u(rng)});
  }
  tall.normals.assign(tall.size(), Vec3f{1, 0, 0});
  flat.normals.assign(flat.size(), Vec3f{0, 0, 1});
  write_ply(dir.file("tall.ply"), tall);
  write_ply(dir.file("flat.ply"), flat);
  const Generated g = generate(OcclusionScene::Row, dir.file("models/row.json"),
                               {dir.file("tall.ply"), dir.file("flat.ply")});
  const auto instances = g.scene.instances();
  ASSERT_EQ(instances.size(), 32u);
  ASSERT_EQ(g.result.models.size(), 2u);
  EXPECT_EQ(g.result.models[0].path, "../tall.ply");  // relative to the scene file
  EXPECT_EQ(g.result.models[0].instances, 16u);
  for (int k = 0; k < 32; ++k) {
    SCOPED_TRACE("k " + std::to_string(k));
    const bool is_tall = k % 2 == 0;
    const Placed p = place(instances[k].transform, is_tall ? tall.positions : flat.positions);
    EXPECT_NEAR(p.lowest_y, 0.0f, kTolerance);
    EXPECT_NEAR(p.radius, 1.0f, kTolerance);
    EXPECT_NEAR(p.centre.x, is_tall ? 0.6f : -0.6f, kTolerance);
    EXPECT_NEAR(p.centre.z, -3.0f * k, kTolerance);
    // The tall model's extent along z (about 3) stands along +y; the flat one keeps its y.
    const Vec3f own = bounding_box(is_tall ? tall.positions : flat.positions).extent();
    const float scale = instances[k].transform.scale;
    EXPECT_NEAR(p.box_extent.y, (is_tall ? own.z : own.y) * scale, kTolerance);
    if (is_tall) {
      EXPECT_GT(instances[k].transform.rotate({0, 0, 1}).y, 0.9999f);
    }
  }
  const CameraPath path = read_camera_path(dir.file("models/row.path"));
  ASSERT_EQ(path.frames.size(), 30u);
  EXPECT_EQ(path.fov_deg.value_or(0), 30.0f);
  expect_near(path.frames[29].eye, {0, 1, 5});
  expect_near(normalized(path.frames[29].target - path.frames[29].eye), {0, 0, -1});
}

TEST(OcclusionScenes, CityFacadesCoverEveryBuildingAndCornersHoldModels) {
  pointillist::testing::TempDir dir;
  const Generated g = generate(OcclusionScene::City, dir.file("city.json"), {}, 200);
  const auto instances = g.scene.instances();
  // Expected, from the specification: per block 4 façades of h/2 panels, facing outward, and
  // scanned models at the 4 corners.
  std::vector<PanelKey> want_panels;
  std::vector<std::pair<long, long>> want_models;
  for (std::uint32_t i = 0; i < 16; ++i) {
    for (std::uint32_t j = 0; j < 16; ++j) {
      const float x0 = 12.0f * i + 2, x1 = 12.0f * i + 10, z0 = 12.0f * j + 2, z1 = 12.0f * j + 10;
      for (int k = 0; k < city_height(i, j) / 2; ++k) {
        const float y0 = 2.0f * k, y1 = y0 + 2;
        want_panels.push_back(panel_key({x0, y0, z0}, {x1, y1, z0}, {0, 0, -1}));
        want_panels.push_back(panel_key({x0, y0, z1}, {x1, y1, z1}, {0, 0, 1}));
        want_panels.push_back(panel_key({x0, y0, z0}, {x0, y1, z1}, {-1, 0, 0}));
        want_panels.push_back(panel_key({x1, y0, z0}, {x1, y1, z1}, {1, 0, 0}));
      }
      for (float cx : {12.0f * i + 1, 12.0f * i + 11}) {
        for (float cz : {12.0f * j + 1, 12.0f * j + 11}) {
          want_models.push_back({std::lround(cx * 1000), std::lround(cz * 1000)});
        }
      }
    }
  }
  std::vector<PanelKey> got_panels;
  std::vector<std::pair<long, long>> got_models;
  const std::vector<Vec3f> statue = statue_samples(200);
  for (const SceneInstance& inst : instances) {
    const InstanceTransform& t = inst.transform;
    if (inst.model->tree.leaf_count == 17u * 5u) {  // the panel: 8 × 2 at spacing 0.5
      Aabb box;
      box.extend(t.apply({-4, 0, 0}));
      box.extend(t.apply({4, 2, 0}));
      got_panels.push_back(panel_key(box.lo, box.hi, t.rotate({0, 0, 1})));
    } else {
      const Placed p = place(t, statue);
      EXPECT_NEAR(p.lowest_y, 0.0f, kTolerance);
      EXPECT_NEAR(p.radius, 1.0f, kTolerance);
      got_models.push_back({std::lround(p.centre.x * 1000), std::lround(p.centre.z * 1000)});
    }
  }
  EXPECT_EQ(got_models.size(), 1024u);
  EXPECT_EQ(g.result.scanned_instance_count, 1024u);
  std::sort(want_panels.begin(), want_panels.end());
  std::sort(got_panels.begin(), got_panels.end());
  EXPECT_EQ(got_panels.size(), want_panels.size());
  EXPECT_TRUE(got_panels == want_panels);
  std::sort(want_models.begin(), want_models.end());
  std::sort(got_models.begin(), got_models.end());
  EXPECT_TRUE(got_models == want_models);
  // The heights vary: every value 6..20 occurs.
  std::vector<int> heights;
  for (std::uint32_t i = 0; i < 16; ++i) {
    for (std::uint32_t j = 0; j < 16; ++j) heights.push_back(city_height(i, j));
  }
  for (int h = 6; h <= 20; h += 2) EXPECT_NE(std::count(heights.begin(), heights.end(), h), 0);
}

TEST(OcclusionScenes, CityPathsFollowTheirFormulas) {
  pointillist::testing::TempDir dir;
  generate(OcclusionScene::City, dir.file("c.json"), {}, 100);
  const CameraPath walk = read_camera_path(dir.file("c-walk.path"));
  const CameraPath still = read_camera_path(dir.file("c-static.path"));
  const CameraPath fly = read_camera_path(dir.file("c-fly.path"));
  const CameraPath turn = read_camera_path(dir.file("c-turn.path"));
  ASSERT_EQ(walk.frames.size(), 300u);
  ASSERT_EQ(still.frames.size(), 60u);
  ASSERT_EQ(fly.frames.size(), 200u);
  ASSERT_EQ(turn.frames.size(), 90u);
  for (const CameraPath* p : {&walk, &still, &fly, &turn}) EXPECT_EQ(p->fov_deg.value_or(0), 60.0f);
  const auto direction = [](const CameraPathFrame& f) { return normalized(f.target - f.eye); };
  for (int f : {0, 25, 37, 150, 299}) {
    SCOPED_TRACE("walk frame " + std::to_string(f));
    expect_near(walk.frames[f].eye, {96, 1.7f, float(2 + 188.0 * f / 299)});
    expect_near(direction(walk.frames[f]), yaw_direction(20 * std::sin(2 * kPiD * f / 100)));
  }
  for (const CameraPathFrame& f : still.frames) {
    expect_near(f.eye, walk.frames[150].eye, 0);
    expect_near(f.target, walk.frames[150].target, 0);
  }
  for (int f : {0, 50, 133}) {
    SCOPED_TRACE("fly frame " + std::to_string(f));
    const double a = 2 * kPiD * f / 200;
    const Vec3f eye{float(96 + 120 * std::sin(a)), 60, float(96 + 120 * std::cos(a))};
    expect_near(fly.frames[f].eye, eye, 1e-3f);
    expect_near(fly.frames[f].target, {96, 0, 96});
  }
  for (int f : {0, 30, 45, 89}) {
    SCOPED_TRACE("turn frame " + std::to_string(f));
    expect_near(turn.frames[f].eye, {96, 1.7f, 96});
    expect_near(direction(turn.frames[f]), yaw_direction(360.0 * f / 90));
  }
}

TEST(OcclusionScenes, FieldOrbitKeepsEveryModelInView) {
  pointillist::testing::TempDir dir;
  const Generated g = generate(OcclusionScene::Field, dir.file("field.json"), {}, 100);
  const auto instances = g.scene.instances();
  ASSERT_EQ(instances.size(), 256u);
  std::vector<Sphere> spheres;
  for (int i = 0; i < 16; ++i) {
    for (int j = 0; j < 16; ++j) {
      const SceneInstance& inst = instances[16 * i + j];
      const Sphere& v = inst.model->tree.view_sphere;
      const Sphere s{inst.transform.apply(v.center), inst.transform.scale * v.radius};
      EXPECT_NEAR(s.center.x, -30.0f + 4 * i, kTolerance);
      EXPECT_NEAR(s.center.z, -30.0f + 4 * j, kTolerance);
      EXPECT_NEAR(s.radius, 1.0f, kTolerance);
      spheres.push_back(s);
    }
  }
  const CameraPath path = read_camera_path(dir.file("field.path"));
  ASSERT_EQ(path.frames.size(), 120u);
  const std::vector<Camera> cameras =
      path_cameras(path, "field.path", path.fov_deg.value_or(0), 1280, 720);
  for (std::size_t f = 0; f < cameras.size(); ++f) {
    const Vec3f from_centre = cameras[f].eye - Vec3f{0, 1, 0};
    EXPECT_NEAR(from_centre.y / length(from_centre), std::sin(kPiD / 4), 1e-5);
    expect_near(cameras[f].target, {0, 1, 0});
    const CameraFrame frame = make_camera_frame(cameras[f]);
    for (const Sphere& s : spheres) {
      for (const Plane& plane : frame.planes) ASSERT_GT(plane.distance(s.center), s.radius) << f;
    }
  }
  // Azimuth 360°·f/120: a quarter of the way round at frame 30.
  expect_near(normalized(Vec3f{cameras[30].eye.x, 0, cameras[30].eye.z}), {1, 0, 0}, 1e-5f);
}

TEST(OcclusionScenes, BadOutputsAndModelsAreNamed) {
  pointillist::testing::TempDir dir;
  ThreadPool pool(1);
  GenerateSceneOptions o;
  o.output = dir.file("wall.txt");
  try {
    generate_scene(o, pool);
    FAIL() << "no error";
  } catch (const OptionError& e) {
    EXPECT_NE(std::string(e.what()).find("wall.txt"), std::string::npos) << e.what();
  }
  o.output = dir.file("wall.json");
  o.models = {dir.file("missing.ptl")};
  try {
    generate_scene(o, pool);
    FAIL() << "no error";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("missing.ptl: no such model file"), std::string::npos)
        << e.what();
  }
  // A generated model would replace the given one.
  o.models = {dir.file("wall-wall.ptl")};
  EXPECT_THROW(generate_scene(o, pool), OptionError);
  EXPECT_FALSE(std::filesystem::exists(dir.file("wall.json")));
  EXPECT_FALSE(std::filesystem::exists(dir.file("wall.path")));
}

TEST(OcclusionScenes, StandOnGroundTurnsAnyUpAxisToYThenYaws) {
  const Aabb box{{1, 2, 3}, {2, 5, 4}};
  const Sphere sphere{box.center(), 2.0f};
  for (const Vec3f up : {Vec3f{0, 1, 0}, Vec3f{0, 0, 1}, Vec3f{1, 0, 0}, Vec3f{0, -1, 0},
                         Vec3f{0, 0, -1}, Vec3f{-1, 0, 0}, normalized(Vec3f{0.6f, 0.8f, 0.3f})}) {
    SCOPED_TRACE(std::to_string(up.x) + " " + std::to_string(up.y) + " " + std::to_string(up.z));
    const Placement p0 = stand_on_ground(box, sphere, up, {5, 0, -7}, 0.0f);
    const InstanceTransform t0 = make_transform(p0.translate, p0.rotate_deg, p0.scale);
    expect_near(t0.rotate(up), {0, 1, 0}, 1e-5f);
    EXPECT_NEAR(t0.scale, 0.5f, 1e-7f);
    for (const float yaw : {30.0f, 90.0f, -135.0f, 180.0f}) {
      const Placement p = stand_on_ground(box, sphere, up, {5, 0, -7}, yaw);
      const InstanceTransform t = make_transform(p.translate, p.rotate_deg, p.scale);
      // R(yaw) = Ry(yaw)·R(0): the same turn upright, then the yaw about +Y.
      const double a = yaw * kPiD / 180;
      for (const Vec3f v : {Vec3f{1, 0, 0}, Vec3f{0, 1, 0}, Vec3f{0, 0, 1}}) {
        const Vec3f r0 = t0.rotate(v);
        const Vec3f want{float(std::cos(a) * r0.x + std::sin(a) * r0.z), r0.y,
                         float(-std::sin(a) * r0.x + std::cos(a) * r0.z)};
        expect_near(t.rotate(v), want, 1e-5f);
      }
      expect_near(t.apply(box.center()), {5, t.apply(box.center()).y, -7}, 1e-5f);
      float lowest = 1e9f;
      for (int c = 0; c < 8; ++c) {
        lowest = std::min(lowest, t.apply({c & 1 ? box.hi.x : box.lo.x, c & 2 ? box.hi.y : box.lo.y,
                                           c & 4 ? box.hi.z : box.lo.z}).y);
      }
      EXPECT_NEAR(lowest, 0.0f, 1e-5f);
    }
  }
  EXPECT_THROW(stand_on_ground(Aabb{}, sphere, {0, 1, 0}, {0, 0, 0}, 0), Error);
  EXPECT_THROW(stand_on_ground(box, {box.center(), 0.0f}, {0, 1, 0}, {0, 0, 0}, 0), Error);
}
