// The viewer's camera controls against the projection of known world points: a drag moves the
// model with the mouse, the wheel keeps the point under the cursor, panning drags the pivot's
// plane along, the axis views look along the model's axes and keep its up axis up.
#include <gtest/gtest.h>

#include <cmath>

#include "pointillist/core/camera.hpp"
#include "pointillist/viewer/navigation.hpp"

using namespace pointillist;

namespace {

struct Pixel {
  float x, y;
};

// Pixel position of world point p (independent of the navigator: the pinhole model of
// core/camera.hpp written out).
Pixel project(const Camera& c, Vec3f p) {
  const CameraFrame f = make_camera_frame(c);
  const Vec3f d = p - f.eye;
  const float z = dot(d, f.forward);
  return {0.5f * float(c.width) + f.focal_px * dot(d, f.right) / z,
          0.5f * float(c.height) - f.focal_px * dot(d, f.up) / z};
}

const Sphere kSphere{{1, 2, 3}, 2};

Navigator front_navigator(Vec3f up = {0, 1, 0}) {
  const Camera home = orbit_camera(kSphere, {.width = 800, .height = 600, .up = up});
  return Navigator(home, kSphere, up);
}

}  // namespace

TEST(Navigator, StartsAtTheHomeCameraAndMatchesRenderViewAngles) {
  for (Vec3f up : {Vec3f{0, 1, 0}, Vec3f{0, 0, 1}}) {
    const Camera home = orbit_camera(kSphere, {.azimuth_deg = 30, .elevation_deg = 20,
                                               .width = 800, .height = 600, .up = up});
    const Navigator nav(home, kSphere, up);
    EXPECT_NEAR(nav.azimuth_deg(), 30, 1e-3);
    EXPECT_NEAR(nav.elevation_deg(), 20, 1e-3);
    const Camera c = nav.camera();
    EXPECT_LT(length(c.eye - home.eye), 1e-4f);
    EXPECT_LT(length(c.target - home.target), 1e-6f);
  }
}

TEST(Navigator, DraggingRightMovesTheFrontOfTheModelRightAndDownShowsTheTop) {
  Navigator nav = front_navigator();
  const Vec3f front = kSphere.center + Vec3f{0, 0, kSphere.radius};  // nearest the eye
  const Vec3f top = kSphere.center + Vec3f{0, kSphere.radius, 0};
  const Pixel before = project(nav.camera(), front);
  nav.orbit(60, 0);
  const Pixel after = project(nav.camera(), front);
  EXPECT_GT(after.x, before.x + 10);
  EXPECT_NEAR(after.y, before.y, 1e-3);
  // 60 px of a 600 px high window: a tenth of 180 degrees.
  EXPECT_NEAR(nav.azimuth_deg(), -18, 1e-4);
  nav = front_navigator();
  const float top_depth_before = make_camera_frame(nav.camera()).depth(top);
  const Pixel front_before = project(nav.camera(), front);
  nav.orbit(0, 90);
  EXPECT_NEAR(nav.elevation_deg(), 27, 1e-4);
  EXPECT_GT(project(nav.camera(), front).y, front_before.y + 10);  // the front goes down
  // Looking from higher up, the top comes closer than the centre's plane was.
  EXPECT_LT(make_camera_frame(nav.camera()).depth(top), top_depth_before);
  nav.orbit(0, 100000);
  EXPECT_EQ(nav.elevation_deg(), 90);  // stops at the pole
}

TEST(Navigator, OrbitKeepsTheModelUpAxisUpInTheImage) {
  for (Vec3f up : {Vec3f{0, 1, 0}, Vec3f{0, 0, 1}, Vec3f{1, 0, 0}}) {
    Navigator nav = front_navigator(up);
    nav.orbit(123, -45);
    nav.orbit(-31, 77);
    const CameraFrame f = make_camera_frame(nav.camera());
    // Turntable: the horizon stays level (the screen's x axis is perpendicular to up) and up
    // points up on the screen.
    EXPECT_NEAR(dot(f.right, up), 0, 1e-5);
    EXPECT_GT(dot(f.up, up), 0);
  }
}

TEST(Navigator, WheelKeepsThePointUnderTheCursor) {
  Navigator nav = front_navigator();
  const float x = 600, y = 150;
  const CameraFrame f = make_camera_frame(nav.camera());
  const Vec3f ray = f.forward + f.right * ((x - 400) / f.focal_px) + f.up * ((300 - y) / f.focal_px);
  const float depth = 0.9f * nav.distance();
  const Vec3f p = f.eye + ray * depth;  // a surface point seen at (x, y)
  const float distance = nav.distance();
  nav.zoom(2, x, y, depth);
  const Pixel at = project(nav.camera(), p);
  EXPECT_NEAR(at.x, x, 2e-3);
  EXPECT_NEAR(at.y, y, 2e-3);
  EXPECT_NEAR(nav.distance(), distance * 0.64f, 1e-4);
  // Without a depth (the background under the cursor), the pivot's depth is used.
  const Vec3f q = nav.camera().eye +
                  (make_camera_frame(nav.camera()).forward * nav.distance());  // the pivot
  const Pixel q_before = project(nav.camera(), q);
  nav.zoom(-3, q_before.x, q_before.y);
  const Pixel q_after = project(nav.camera(), q);
  EXPECT_NEAR(q_after.x, 400, 2e-3);
  EXPECT_NEAR(q_after.y, 300, 2e-3);
  EXPECT_NEAR(nav.distance(), distance * 0.64f / 0.512f, 1e-3);
}

TEST(Navigator, PanDragsThePivotPlaneWithTheCursor) {
  Navigator nav = front_navigator();
  const Vec3f pivot = nav.pivot();
  nav.pan(40, -25);
  const Pixel at = project(nav.camera(), pivot);
  EXPECT_NEAR(at.x, 440, 1e-2);
  EXPECT_NEAR(at.y, 275, 1e-2);
}

TEST(Navigator, AxisViewsLookAlongTheModelAxesAndResetGoesHome) {
  Navigator nav = front_navigator(Vec3f{0, 0, 1});  // a LAS scan: +Z up
  const Camera home = nav.camera();
  const struct {
    AxisView view;
    Vec3f from;  // direction from the centre to the eye
  } kCases[] = {{AxisView::Top, {0, 0, 1}}, {AxisView::Bottom, {0, 0, -1}},
                {AxisView::Front, {0, -1, 0}}, {AxisView::Back, {0, 1, 0}},
                {AxisView::Right, {1, 0, 0}}, {AxisView::Left, {-1, 0, 0}}};
  for (const auto& c : kCases) {
    nav.axis_view(c.view);
    const Camera cam = nav.camera();
    EXPECT_LT(length(nav.pivot() - kSphere.center), 1e-6f);
    EXPECT_GT(dot(normalized(cam.eye - cam.target), c.from), 0.9999f) << int(c.view);
    EXPECT_NO_THROW(make_camera_frame(cam)) << int(c.view);  // the poles too
  }
  nav.reset();
  EXPECT_LT(length(nav.camera().eye - home.eye), 1e-4f);
}

TEST(Navigator, PickedPointBecomesThePivotWithTheEyeInPlace) {
  Navigator nav = front_navigator();
  const Vec3f eye = nav.camera().eye;
  nav.pick_pivot(700, 100, 5.0f);
  const Camera c = nav.camera();
  EXPECT_LT(length(c.eye - eye), 1e-4f);
  const Pixel at = project(c, nav.pivot());
  EXPECT_NEAR(at.x, 400, 1e-2);
  EXPECT_NEAR(at.y, 300, 1e-2);
}

TEST(Navigator, OrthographicZoomAndPanKeepThePointUnderTheCursor) {
  Navigator nav = front_navigator();
  nav.toggle_ortho();
  ASSERT_TRUE(nav.ortho());
  // The same scale at the pivot: its plane's points stay where they were.
  const Camera persp_home = orbit_camera(kSphere, {.width = 800, .height = 600});
  const Vec3f on_pivot_plane = kSphere.center + Vec3f{0.5f, -0.3f, 0};
  const Pixel before_toggle = project(persp_home, on_pivot_plane);
  const auto ortho_project = [](const Camera& c, Vec3f p) {
    const CameraFrame f = make_camera_frame(c);
    EXPECT_TRUE(f.ortho);
    const Vec3f d = p - f.eye;
    return Pixel{400 + f.focal_px * dot(d, f.right), 300 - f.focal_px * dot(d, f.up)};
  };
  const Pixel after_toggle = ortho_project(nav.camera(), on_pivot_plane);
  EXPECT_NEAR(after_toggle.x, before_toggle.x, 1e-2);
  EXPECT_NEAR(after_toggle.y, before_toggle.y, 1e-2);
  const float height = nav.camera().ortho_height;
  const Vec3f p = kSphere.center + Vec3f{0.7f, 0.4f, 0.2f};
  const Pixel at = ortho_project(nav.camera(), p);
  nav.zoom(3, at.x, at.y, 1.0f);
  const Pixel zoomed = ortho_project(nav.camera(), p);
  EXPECT_NEAR(zoomed.x, at.x, 2e-3);
  EXPECT_NEAR(zoomed.y, at.y, 2e-3);
  EXPECT_NEAR(nav.camera().ortho_height, height * 0.512f, 1e-5);
  nav.pan(-30, 12);
  const Pixel panned = ortho_project(nav.camera(), p);
  EXPECT_NEAR(panned.x, at.x - 30, 1e-2);
  EXPECT_NEAR(panned.y, at.y + 12, 1e-2);
  nav.toggle_ortho();
  EXPECT_FALSE(nav.ortho());
}
