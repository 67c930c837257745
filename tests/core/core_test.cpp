#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include "pointillist/core/camera.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/core/point_set.hpp"
#include "pointillist/core/thread_pool.hpp"

using namespace pointillist;

TEST(ThreadPool, RunsEveryTaskExactlyOnce) {
  for (unsigned threads : {1u, 2u, 5u}) {
    ThreadPool pool(threads);
    std::vector<std::atomic<int>> hits(1000);
    for (int round = 0; round < 20; ++round) pool.run(hits.size(), [&](std::size_t i) { ++hits[i]; });
    for (auto& h : hits) EXPECT_EQ(h.load(), 20);
  }
}

TEST(ThreadPool, RethrowsTheLowestIndexException) {
  ThreadPool pool(3);
  try {
    pool.run(100, [](std::size_t i) {
      if (i == 17 || i == 60) throw std::runtime_error("task " + std::to_string(i));
    });
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "task 17");
  }
  // The pool still works afterwards.
  std::atomic<int> n{0};
  pool.run(10, [&](std::size_t) { ++n; });
  EXPECT_EQ(n.load(), 10);
}

TEST(ThreadPool, ParallelForCoversTheRangeInFixedChunks) {
  ThreadPool pool(2);
  std::vector<int> v(1003, 0);
  parallel_for(pool, v.size(), 100, [&](std::size_t b, std::size_t e) {
    EXPECT_EQ(b % 100, 0u);
    for (std::size_t i = b; i < e; ++i) v[i] += 1;
  });
  EXPECT_EQ(std::accumulate(v.begin(), v.end(), 0), 1003);
}

TEST(Camera, OrbitPlacesTheEyeAsTheArchitectureSays) {
  const Sphere vs{{1, 2, 3}, 2.0f};
  const Camera c = orbit_camera(vs, {.azimuth_deg = 90, .elevation_deg = 0, .distance = 3});
  EXPECT_NEAR(c.eye.x, 1 + 6, 1e-5f);
  EXPECT_NEAR(c.eye.y, 2, 1e-5f);
  EXPECT_NEAR(c.eye.z, 3, 1e-5f);
  const Camera d = orbit_camera(vs, {.fov_deg = 30});
  EXPECT_NEAR(length(d.eye - vs.center), 2.0f * 1.05f / std::sin(deg_to_rad(15)), 1e-4f);
  EXPECT_THROW(orbit_camera(vs, {.elevation_deg = 90.5f}), OptionError);
  // The poles are plan views: the eye straight above (below) the centre, -Z' up in the image.
  const Camera top = orbit_camera(vs, {.elevation_deg = 90, .distance = 3});
  EXPECT_NEAR(top.eye.x, 1, 1e-5f);
  EXPECT_NEAR(top.eye.y, 2 + 6, 1e-5f);
  EXPECT_NEAR(top.eye.z, 3, 1e-5f);
  const CameraFrame f = make_camera_frame(top);
  EXPECT_NEAR(f.up.z, -1, 1e-5f);
  EXPECT_NEAR(f.right.x, 1, 1e-5f);
  EXPECT_NO_THROW(make_camera_frame(orbit_camera(vs, {.azimuth_deg = 30, .elevation_deg = -90})));
}

TEST(Camera, OrbitAroundAZUpAxisKeepsZUpAndMeasuresElevationFromTheXYPlane) {
  const Sphere vs{{1, 2, 3}, 2.0f};
  // Azimuth 0, elevation 30°, distance 3 radii, +Z up: the eye is 6 units away, in front along
  // −Y (Z' = X × up = −Y), 6·sin 30° = 3 above the centre.
  const Camera c = orbit_camera(
      vs, {.azimuth_deg = 0, .elevation_deg = 30, .distance = 3, .up = {0, 0, 2}});
  EXPECT_NEAR(c.eye.x, 1, 1e-5f);
  EXPECT_NEAR(c.eye.y, 2 - 6 * std::cos(deg_to_rad(30)), 1e-5f);
  EXPECT_NEAR(c.eye.z, 3 + 3, 1e-5f);
  EXPECT_NEAR(c.up.z, 1, 1e-6f);
  // Azimuth 90°: along +X, as with +Y up.
  const Camera d = orbit_camera(vs, {.azimuth_deg = 90, .distance = 3, .up = {0, 0, 1}});
  EXPECT_NEAR(d.eye.x, 7, 1e-5f);
  EXPECT_NEAR(d.eye.z, 3, 1e-5f);
  // The default equals an explicit +Y.
  const Camera e = orbit_camera(vs, {.azimuth_deg = 40, .elevation_deg = 20});
  const Camera f = orbit_camera(vs, {.azimuth_deg = 40, .elevation_deg = 20, .up = {0, 1, 0}});
  EXPECT_EQ(e.eye, f.eye);
  EXPECT_THROW(orbit_camera(vs, {.up = {0, 0, 0}}), OptionError);
}

TEST(Camera, FrameProjectsWithTheStatedFocalLengthAndFrustum) {
  const Camera c{.eye = {0, 0, 10}, .target = {0, 0, 0}, .fov_deg = 90, .width = 200, .height = 100};
  const CameraFrame f = make_camera_frame(c);
  EXPECT_NEAR(f.focal_px, 50.0f, 1e-4f);  // (H/2)/tan(45°)
  EXPECT_NEAR(f.depth({0, 0, 0}), 10.0f, 1e-5f);
  EXPECT_NEAR(f.forward.z, -1.0f, 1e-6f);
  EXPECT_NEAR(f.right.x, 1.0f, 1e-6f);
  // A point at the top edge of the view: y = depth * tan(45°) -> on the top plane.
  EXPECT_NEAR(f.planes[3].distance({0, 10, 0}), 0.0f, 1e-4f);
  EXPECT_GT(f.planes[3].distance({0, 9, 0}), 0.0f);
  EXPECT_LT(f.planes[3].distance({0, 11, 0}), 0.0f);
  // Horizontal half extent = depth * (W/2)/f = 20.
  EXPECT_NEAR(f.planes[1].distance({20, 0, 0}), 0.0f, 1e-4f);
  EXPECT_LT(f.planes[0].distance({-21, 0, 0}), 0.0f);
  EXPECT_THROW(make_camera_frame(Camera{.eye = {0, 0, 0}, .target = {0, 0, 0}}), OptionError);
  EXPECT_THROW(make_camera_frame(Camera{.eye = {0, 5, 0}, .target = {0, 0, 0}}), OptionError);
}

TEST(PointSet, ViewSphereIsBoxCentreAndFarthestSample) {
  const std::vector<Vec3f> p{{0, 0, 0}, {2, 0, 0}, {0, 4, 0}};
  const Sphere s = view_sphere(p);
  EXPECT_EQ(s.center, (Vec3f{1, 2, 0}));
  EXPECT_NEAR(s.radius, std::sqrt(5.0f), 1e-6f);
}
