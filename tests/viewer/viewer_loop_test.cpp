// The viewer's loop driven by scripts through a window that records what it is shown: a settled
// view is the image a fresh headless render of the same camera draws; the camera stopping is
// followed by frames refining to full detail and then by none; a paged model settles with its
// pages loaded; toggles the models cannot draw are refused in the title and undone; closing the
// window ends the loop.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <deque>
#include <memory>
#include <string>
#include <thread>

#include "pointillist/core/progress.hpp"
#include "pointillist/format/ptl_v2.hpp"
#include "pointillist/io/ply.hpp"
#include "pointillist/io/png.hpp"
#include "pointillist/lod/sphere_tree.hpp"
#include "pointillist/pipeline/model.hpp"
#include "pointillist/prep/radii.hpp"
#include "pointillist/render/sequence.hpp"
#include "pointillist/scene/analytic.hpp"
#include "pointillist/viewer/viewer.hpp"
#include "testing/testing.hpp"

using namespace pointillist;
using ::testing::HasSubstr;

namespace {

class RecordingWindow final : public Window {
 public:
  void present(const Frame&) override { ++presented; }
  bool poll(InputEvent& e) override {
    if (pending.empty()) return false;
    e = pending.front();
    pending.pop_front();
    return true;
  }
  void wait(int ms) override { std::this_thread::sleep_for(std::chrono::milliseconds(std::min(ms, 2))); }
  void set_title(const std::string& t) override { titles.push_back(t); }
  void resize(int w, int h) override {
    pending.push_back({.type = InputEvent::Type::Resize, .width = w, .height = h});
  }
  bool set_overlay(const std::vector<std::string>& lines) override {
    overlays.push_back(lines);
    return true;
  }
  std::vector<std::vector<std::string>> overlays;
  std::deque<InputEvent> pending;
  std::vector<std::string> titles;
  int presented = 0;
};

SphereTree demo_tree(ThreadPool& pool) {
  SurfaceSamples s = sample_scene(demo_scene(), 20000, 7);
  s.points.normals = s.true_normals;
  s.points.radii = cloud_radii(s.points.positions, pool, Progress::none());
  return build_sphere_tree(s.points, pool);
}

std::vector<ScriptStep> script(const std::string& dir, const std::string& text) {
  std::ofstream(dir + "/s.events", std::ios::binary) << text;
  return read_event_script(dir + "/s.events");
}

struct Fixture {
  ThreadPool pool{2};
  SphereTree tree = demo_tree(pool);
  RenderModel model{.tree = tree.view(), .name = "demo"};
  std::vector<SceneInstance> scene{{.model = &model}};
  Camera home = orbit_camera(tree.view_sphere, {.azimuth_deg = 20, .elevation_deg = 10,
                                                .width = 320, .height = 240});
};

// Quiet options that play `text` as the script (written into `dir`).
ViewerOptions scripted(const pointillist::testing::TempDir& dir, const std::string& text) {
  ViewerOptions o;
  o.quiet = true;
  o.scripted = true;
  o.script = script(dir.path().string(), text);
  return o;
}

Frame fresh_render(std::span<const SceneInstance> scene, const Camera& c, const ViewerOptions& o,
                   ThreadPool& pool, Renderer* renderer = nullptr) {
  Renderer own;
  Frame f;
  render_settled(renderer ? *renderer : own, scene, c, o.settings, o.frame, pool, f);
  return f;
}

}  // namespace

TEST(ViewerLoop, SettledViewIsTheHeadlessRenderOfItsCamera) {
  Fixture fx;
  pointillist::testing::TempDir dir;
  Navigator nav(fx.home, fx.tree.view_sphere, {0, 1, 0});
  ViewerOptions o = scripted(
      dir, "drag left 100 100 160 120 4\nwheel 160 120 2\nsettle\nscreenshot " +
               dir.file("a.png") + "\nkey k\nkey m\nsettle\nscreenshot " + dir.file("b.png") +
               "\n");
  Renderer renderer;
  RecordingWindow window;
  const ViewerResult r = run_viewer(renderer, fx.scene, nav, window, fx.pool, o, stdout);
  ASSERT_EQ(r.screenshots.size(), 2u);
  // The camera moved (a drag and a zoom) and the screenshots are of the moved camera.
  EXPECT_GT(std::abs(nav.azimuth_deg() - 20), 1.0f);
  const ImageRgb8 b = read_png_rgb8(dir.file("b.png"));
  ViewerOptions quality = o;
  quality.settings.shape = SplatShape::Ellipse;
  quality.frame.rasterizer = Rasterizer::Quality;
  const Frame want_b = fresh_render(fx.scene, nav.camera(), quality, fx.pool);
  ASSERT_EQ(b.width, want_b.width);
  EXPECT_TRUE(std::equal(b.pixels.begin(), b.pixels.end(), want_b.color.begin()));
  const ImageRgb8 a = read_png_rgb8(dir.file("a.png"));
  const Frame want_a = fresh_render(fx.scene, nav.camera(), o, fx.pool);
  EXPECT_TRUE(std::equal(a.pixels.begin(), a.pixels.end(), want_a.color.begin()));
  EXPECT_FALSE(std::equal(a.pixels.begin(), a.pixels.end(), b.pixels.begin()));
  EXPECT_THAT(window.titles.back(), HasSubstr("Pointillist"));
  EXPECT_THAT(window.titles.back(), HasSubstr("quality ellipse qsplat"));
}

TEST(ViewerLoop, AfterTheCameraStopsFramesRefineToFullDetailThenStop) {
  Fixture fx;
  pointillist::testing::TempDir dir;
  Navigator nav(fx.home, fx.tree.view_sphere, {0, 1, 0});
  ViewerOptions o = scripted(dir, "drag left 50 50 150 50 6\nsettle\nwait 60\n");
  o.refine_frames = 5;
  // A target no frame can meet: every moving frame is coarser than full detail.
  o.fps = 100000;
  o.settings.threshold_px = 1.5f;
  Renderer renderer;
  RecordingWindow window;
  const ViewerResult r = run_viewer(renderer, fx.scene, nav, window, fx.pool, o, stdout);
  ASSERT_FALSE(r.frames.empty());
  std::size_t first_refine = 0;
  while (first_refine < r.frames.size() && std::string(r.frames[first_refine].phase) != "refine") {
    EXPECT_STREQ(r.frames[first_refine].phase, "moving");
    ++first_refine;
  }
  ASSERT_EQ(r.frames.size() - first_refine, 5u) << "refinement frames, then none while settled";
  EXPECT_GT(r.frames[first_refine - 1].detail, 1.5f);  // the controller coarsened
  for (std::size_t i = first_refine + 1; i < r.frames.size(); ++i) {
    EXPECT_LT(r.frames[i].detail, r.frames[i - 1].detail);
  }
  EXPECT_EQ(r.frames.back().detail, 1.5f);
  EXPECT_EQ(window.presented, int(r.frames.size()));
}

TEST(ViewerLoop, PagedModelSettlesWithItsPagesAndRefusesWhatPagesCannotDraw) {
  Fixture fx;
  pointillist::testing::TempDir dir;
  write_ptl_v2(dir.file("m.ptl"), fx.tree, "");
  OpenModelOptions open;
  open.paging = Paging::Always;
  const Model model = open_model(dir.file("m.ptl"), open, fx.pool, Progress::none());
  ASSERT_TRUE(model.paged());
  const std::vector<SceneInstance> scene{{.model = &model.renderable()}};
  Navigator nav(fx.home, fx.tree.view_sphere, {0, 1, 0});
  // SPT is not drawn from pages: refused, undone, the viewer goes on. Occlusion culling is (each
  // instance of a paged model one culling leaf): the screenshot below is taken with it on.
  ViewerOptions o = scripted(
      dir, "settle\nkey l\nsettle\nkey c\nsettle\nscreenshot " + dir.file("p.png") + "\n");
  Renderer renderer({.page_all = true, .memory_cap = 1u << 20});
  RecordingWindow window;
  const ViewerResult r = run_viewer(renderer, scene, nav, window, fx.pool, o, stdout);
  ASSERT_EQ(r.screenshots.size(), 1u);
  EXPECT_TRUE(renderer.complete());
  bool refused = false;
  for (const std::string& t : window.titles) {
    refused = refused || t.find("refused: ") != std::string::npos;
  }
  EXPECT_TRUE(refused) << window.titles.back();
  Renderer fresh({.page_all = true, .memory_cap = 1u << 20});
  const Frame want = fresh_render(scene, nav.camera(), o, fx.pool, &fresh);
  const ImageRgb8 p = read_png_rgb8(dir.file("p.png"));
  EXPECT_TRUE(std::equal(p.pixels.begin(), p.pixels.end(), want.color.begin()));
  // The same view of the same file decoded whole.
  open.paging = Paging::Never;
  const Model decoded = open_model(dir.file("m.ptl"), open, fx.pool, Progress::none());
  const std::vector<SceneInstance> whole_scene{{.model = &decoded.renderable()}};
  const Frame whole = fresh_render(whole_scene, nav.camera(), o, fx.pool);
  EXPECT_TRUE(std::equal(p.pixels.begin(), p.pixels.end(), whole.color.begin()));
}

TEST(ViewerLoop, HelpKeyShowsAndHidesTheOverlayWithoutChangingTheFrame) {
  Fixture fx;
  pointillist::testing::TempDir dir;
  Navigator nav(fx.home, fx.tree.view_sphere, {0, 1, 0});
  ViewerOptions o = scripted(dir, "settle\nscreenshot " + dir.file("a.png") +
                                      "\nkey h\nscreenshot " + dir.file("b.png") + "\nkey h\n");
  Renderer renderer;
  RecordingWindow window;
  const ViewerResult r = run_viewer(renderer, fx.scene, nav, window, fx.pool, o, stdout);
  ASSERT_EQ(window.overlays.size(), 2u);
  bool names_orbit = false;
  for (const std::string& line : window.overlays[0]) {
    names_orbit = names_orbit || line.find("left drag orbits") != std::string::npos;
  }
  EXPECT_TRUE(names_orbit);
  EXPECT_TRUE(window.overlays[1].empty());
  // The overlay is the window's: the frame (and its screenshot) is unchanged, and no frame was
  // drawn for it.
  const ImageRgb8 a = read_png_rgb8(dir.file("a.png")), b = read_png_rgb8(dir.file("b.png"));
  EXPECT_TRUE(std::equal(a.pixels.begin(), a.pixels.end(), b.pixels.begin()));
  EXPECT_EQ(r.screenshots.size(), 2u);
}

TEST(ViewerLoop, ClosingTheWindowOrQuitKeysEndTheLoop) {
  Fixture fx;
  for (const InputEvent& e : {InputEvent{.type = InputEvent::Type::Quit},
                              InputEvent{.type = InputEvent::Type::Key, .key = "escape"},
                              InputEvent{.type = InputEvent::Type::Key, .key = "q"}}) {
    Navigator nav(fx.home, fx.tree.view_sphere, {0, 1, 0});
    ViewerOptions o;
    o.quiet = true;
    Renderer renderer;
    RecordingWindow window;
    window.pending.push_back(e);
    const ViewerResult r = run_viewer(renderer, fx.scene, nav, window, fx.pool, o, stdout);
    EXPECT_TRUE(r.frames.empty());
  }
}

TEST(ViewerLoop, RenderCommandLineNamesTheCameraExactlyAndTheToggledModes) {
  Camera c;
  c.eye = {0.1f, -2.5e-7f, 3};
  c.target = {1.0f / 3.0f, 0, 0};
  c.up = {0, 0, 1};
  c.width = 640;
  c.height = 480;
  RenderSettings s;
  s.shape = SplatShape::Ellipse;
  FrameSettings f;
  f.rasterizer = Rasterizer::Quality;
  f.lod = LodScheme::Spt;
  f.epsilon_px = 2;
  f.splat_scale = 1.25f;
  const std::vector<std::string> base = {"pointillist", "render", "my scan.ply"};
  const std::string line = render_command_line(base, c, s, f, "out.png");
  EXPECT_EQ(line,
            "pointillist render 'my scan.ply' --size 640x480 --eye 0.100000001,-2.49999999e-07,3 "
            "--target 0.333333343,0,0 --up 0,0,1 --fov 30 --mode quality --splat ellipse --lod "
            "spt --epsilon 2 --radius-scale 1.25 -o out.png");
  // Nine significant digits give back the same floats.
  EXPECT_EQ(std::strtof("0.100000001", nullptr), c.eye.x);
  EXPECT_EQ(std::strtof("-2.49999999e-07", nullptr), c.eye.y);
  EXPECT_EQ(std::strtof("0.333333343", nullptr), c.target.x);
}

// Key p: hybrid points and triangles. On a mesh the settled view is the headless hybrid render
// of its camera (triangles drawn); on a point cloud the toggle is refused and undone.
TEST(ViewerLoop, HybridKeyDrawsTrianglesOnMeshesAndIsRefusedOnClouds) {
  ThreadPool pool(2);
  pointillist::testing::TempDir dir;
  // A UV sphere mesh of radius 1.
  PointSet mesh;
  const int stacks = 30, slices = 60;
  for (int i = 0; i <= stacks; ++i) {
    const float t = 3.14159265f * float(i) / float(stacks);
    for (int j = 0; j < slices; ++j) {
      const float p = 2 * 3.14159265f * float(j) / float(slices);
      mesh.positions.push_back({std::sin(t) * std::cos(p), std::cos(t), -std::sin(t) * std::sin(p)});
    }
  }
  for (int i = 0; i < stacks; ++i) {
    for (int j = 0; j < slices; ++j) {
      const auto a = std::uint32_t(i * slices + j), b = std::uint32_t(i * slices + (j + 1) % slices);
      mesh.triangles.push_back({a, a + slices, b + slices});
      mesh.triangles.push_back({a, b + slices, b});
    }
  }
  write_ply(dir.file("sphere.ply"), mesh);
  const Model model = open_model(dir.file("sphere.ply"), {}, pool, Progress::none());
  ASSERT_FALSE(model.triangles().empty());
  const std::vector<SceneInstance> scene{{.model = &model.renderable()}};
  const Camera home = orbit_camera(model.tree().view_sphere, {.distance = 1.6f, .width = 320,
                                                              .height = 240});
  Navigator nav(home, model.tree().view_sphere, {0, 1, 0});
  ViewerOptions o = scripted(dir, "key p\nsettle\nscreenshot " + dir.file("h.png") + "\n");
  Renderer renderer;
  RecordingWindow window;
  const ViewerResult r = run_viewer(renderer, scene, nav, window, pool, o, stdout);
  ASSERT_EQ(r.screenshots.size(), 1u);
  EXPECT_THAT(window.titles.back(), HasSubstr("spt hybrid"));
  ViewerOptions hybrid = o;
  hybrid.frame.lod = LodScheme::Spt;
  hybrid.frame.hybrid = true;
  Renderer fresh;
  Frame want;
  render_settled(fresh, scene, nav.camera(), hybrid.settings, hybrid.frame, pool, want);
  EXPECT_GT(want.stats.triangles, 0u);
  const ImageRgb8 h = read_png_rgb8(dir.file("h.png"));
  EXPECT_TRUE(std::equal(h.pixels.begin(), h.pixels.end(), want.color.begin()));

  Fixture fx;  // a point cloud: refused
  Navigator cloud_nav(fx.home, fx.tree.view_sphere, {0, 1, 0});
  ViewerOptions c = scripted(dir, "key p\nsettle\n");
  Renderer cloud_renderer;
  RecordingWindow cloud_window;
  run_viewer(cloud_renderer, fx.scene, cloud_nav, cloud_window, fx.pool, c, stdout);
  bool refused = false;
  for (const std::string& t : cloud_window.titles) {
    refused = refused || t.find("refused: ") != std::string::npos;
  }
  EXPECT_TRUE(refused);
  EXPECT_THAT(cloud_window.titles.back(), HasSubstr("fast circle qsplat \xc2\xb7"));  // undone
}
