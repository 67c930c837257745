// Eye-dome lighting against its formula on constructed depth buffers and on rendered planes (a
// plane facing the camera is left as it is, a depth step is darkened on its far side only), and
// two-sided lighting on a plane seen from behind (drawn, lit as from the front).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "pointillist/core/error.hpp"
#include "pointillist/lod/sphere_tree.hpp"
#include "pointillist/render/eye_dome.hpp"
#include "pointillist/render/render.hpp"
#include "pointillist/render/renderer.hpp"

using namespace pointillist;

namespace {

// A frame whose left half is at depth `near` and right half at `far`, grey 200.
Frame step_frame(int w, int h, float near, float far) {
  Frame f;
  f.width = w;
  f.height = h;
  f.color.assign(std::size_t(w) * h, Rgb8{200, 200, 200});
  f.depth.assign(std::size_t(w) * h, far);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w / 2; ++x) f.depth[std::size_t(y) * w + x] = near;
  }
  return f;
}

// Points on a square of the plane z = z0, normals +z, spacing `step`.
PointSet square(float half, float step, float z0, float x0 = 0) {
  PointSet p;
  for (float y = -half; y <= half; y += step) {
    for (float x = -half; x <= half; x += step) {
      p.positions.push_back({x0 + x, y, z0});
      p.normals.push_back({0, 0, 1});
      p.radii.push_back(step * 0.8f);
    }
  }
  return p;
}

Frame draw(const PointSet& points, const Camera& c, const RenderSettings& s) {
  ThreadPool pool(2);
  const SphereTree tree = build_sphere_tree(points, pool);
  RenderModel model{.tree = tree.view()};
  const SceneInstance inst{.model = &model};
  Renderer renderer;
  Frame f;
  renderer.render({&inst, 1}, c, s, FrameSettings{}, pool, f);
  return f;
}

Camera looking_down_z(float eye_z, int size = 200) {
  Camera c;
  c.eye = {0, 0, eye_z};
  c.target = {0, 0, 0};
  c.width = c.height = size;
  return c;
}

int drawn(const Frame& f) {
  int n = 0;
  for (float d : f.depth) n += std::isfinite(d);
  return n;
}

}  // namespace

TEST(EyeDome, DarkensTheFarSideOfADepthStepByTheFormula) {
  ThreadPool pool(2);
  const float near = 5, far = 6, strength = 0.02f;
  Frame f = step_frame(20, 6, near, far);
  apply_eye_dome_lighting(f, strength, pool);
  const float step = std::log2(far / near);
  for (int y = 0; y < 6; ++y) {
    // Interior rows see three nearer neighbours, the border rows two.
    const int nearer = (y == 0 || y == 5) ? 2 : 3;
    const float want = 200.0f * std::exp(-300.0f * strength * float(nearer) * step / 8.0f);
    EXPECT_NEAR(f.color[y * 20 + 10].r, want, 0.51f) << "row " << y;
    for (int x : {0, 5, 9, 11, 19}) EXPECT_EQ(f.color[y * 20 + x].r, 200) << x << "," << y;
  }
}

TEST(EyeDome, LeavesBackgroundAndFlatPlanesAloneAndRefusesBadStrengths) {
  ThreadPool pool(2);
  Frame f = step_frame(8, 8, 3, 3);
  f.depth[9] = std::numeric_limits<float>::infinity();  // an undrawn pixel among drawn ones
  f.color[9] = {1, 2, 3};
  apply_eye_dome_lighting(f, 5, pool);
  for (std::size_t i = 0; i < f.color.size(); ++i) {
    EXPECT_EQ(f.color[i].r, i == 9 ? 1 : 200) << i;
  }
  EXPECT_THROW(apply_eye_dome_lighting(f, -1, pool), OptionError);
  EXPECT_THROW(apply_eye_dome_lighting(f, std::nanf(""), pool), OptionError);
}

TEST(EyeDome, RenderedPlaneFacingTheCameraIsUnchangedAndAStepDarkensOnlyItsFarSide) {
  const Camera c = looking_down_z(4);
  const PointSet plane = square(1, 0.02f, 0);
  RenderSettings edl;
  edl.edl_strength = 1;
  const Frame plain = draw(plane, c, RenderSettings{});
  const Frame shaded = draw(plane, c, edl);
  ASSERT_GT(drawn(plain), 10000);
  for (std::size_t i = 0; i < plain.color.size(); ++i) {
    ASSERT_EQ(plain.color[i], shaded.color[i]) << "pixel " << i;
  }
  // A smaller square 0.5 in front: its own pixels and the far plane away from its outline keep
  // their colours; the far plane's pixels along the outline get darker.
  PointSet step = plane;
  const PointSet front = square(0.3f, 0.02f, 0.5f);
  step.positions.insert(step.positions.end(), front.positions.begin(), front.positions.end());
  step.normals.insert(step.normals.end(), front.normals.begin(), front.normals.end());
  step.radii.insert(step.radii.end(), front.radii.begin(), front.radii.end());
  const Frame a = draw(step, c, RenderSettings{}), b = draw(step, c, edl);
  int darker = 0, changed_elsewhere = 0;
  for (int y = 1; y < 199; ++y) {
    for (int x = 1; x < 199; ++x) {
      const std::size_t i = std::size_t(y) * 200 + x;
      bool next_to_nearer = false;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          next_to_nearer |= a.depth[i + dy * 200 + dx] < a.depth[i] - 0.1f;
        }
      }
      if (next_to_nearer) {
        darker += b.color[i].r < a.color[i].r;
      } else {
        changed_elsewhere += !(b.color[i] == a.color[i]);
      }
    }
  }
  EXPECT_GT(darker, 100);
  EXPECT_EQ(changed_elsewhere, 0);
}

TEST(TwoSided, PlaneSeenFromBehindIsDrawnAndLitAsFromTheFront) {
  const PointSet plane = square(1, 0.02f, 0);
  const Frame front = draw(plane, looking_down_z(4), RenderSettings{});
  const Frame behind = draw(plane, looking_down_z(-4), RenderSettings{});
  RenderSettings two;
  two.two_sided = true;
  const Frame both = draw(plane, looking_down_z(-4), two);
  ASSERT_GT(drawn(front), 10000);
  EXPECT_EQ(drawn(behind), 0);  // culled: it faces away
  EXPECT_EQ(drawn(both), drawn(front));
  // The headlight sees the back as the front: the same colour at the centre and the same
  // colours overall.
  EXPECT_EQ(both.color[100 * 200 + 100], front.color[100 * 200 + 100]);
  long sum_front = 0, sum_both = 0;
  for (std::size_t i = 0; i < front.color.size(); ++i) {
    sum_front += front.color[i].r;
    sum_both += both.color[i].r;
  }
  EXPECT_EQ(sum_both, sum_front);
  // The front view is unchanged by two-sided lighting.
  const Frame front_two = draw(plane, looking_down_z(4), two);
  for (std::size_t i = 0; i < front.color.size(); ++i) ASSERT_EQ(front.color[i], front_two.color[i]);
}
