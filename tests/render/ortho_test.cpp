// The orthographic camera (Camera::ortho_height) against exact expectations: a cube face seen
// head-on is the exact square of its side over the view height (the ray-cast reference too),
// whatever the eye's distance; every kernel, both level-of-detail schemes and the mesh reference
// draw it, in fast and quality mode; a plan view from the pole works; occlusion culling gives the
// same bits.
#include <gtest/gtest.h>

#include <cmath>

#include "pointillist/core/error.hpp"
#include "pointillist/lod/sphere_tree.hpp"
#include "pointillist/prep/radii.hpp"
#include "pointillist/render/mesh_reference.hpp"
#include "pointillist/render/renderer.hpp"
#include "pointillist/scene/analytic.hpp"

using namespace pointillist;

namespace {

constexpr int kSize = 200;

// The cube [-1, 1]³ seen along −Z from distance `eye_z`, 4 world units high: 50 px per unit, so
// the front face covers pixel centres 50..149 in both directions.
Camera head_on(float eye_z) {
  Camera c;
  c.eye = {0, 0, eye_z};
  c.target = {0, 0, 0};
  c.width = c.height = kSize;
  c.ortho_height = 4;
  return c;
}

// An orthographic orbit camera around the cube's bounding sphere, 10 radii away.
Camera ortho_orbit(float azimuth_deg, float elevation_deg, float height) {
  Camera c = orbit_camera({{0, 0, 0}, std::sqrt(3.0f)},
                          {.azimuth_deg = azimuth_deg, .elevation_deg = elevation_deg,
                           .distance = 10, .width = kSize, .height = kSize});
  c.ortho_height = height;
  return c;
}

struct Cube {
  ThreadPool pool{2};
  SphereTree tree;
  RenderModel model;
  SceneInstance inst;
  Cube() {
    SurfaceSamples s = sample_scene(cube_scene(1), 300000, 3);
    s.points.normals = s.true_normals;
    s.points.radii = cloud_radii(s.points.positions, pool, Progress::none());
    tree = build_sphere_tree(s.points, pool);
    model.tree = tree.view();
    inst.model = &model;
  }
  Frame draw(const Camera& c, RenderSettings s = {}, FrameSettings f = {}) {
    Renderer r;
    Frame frame;
    r.render({&inst, 1}, c, s, f, pool, frame);
    return frame;
  }
};

// Drawn pixels inside the exact square 50..149 and outside it grown by `margin` pixels.
struct SquareCount {
  int inside = 0, far_outside = 0;
};
SquareCount count(const Frame& f, int margin) {
  SquareCount n;
  for (int y = 0; y < kSize; ++y) {
    for (int x = 0; x < kSize; ++x) {
      const bool drawn = std::isfinite(f.depth[y * kSize + x]);
      const bool in = x >= 50 && x <= 149 && y >= 50 && y <= 149;
      const bool near = x >= 50 - margin && x <= 149 + margin && y >= 50 - margin &&
                        y <= 149 + margin;
      n.inside += drawn && in;
      n.far_outside += drawn && !near;
    }
  }
  return n;
}

}  // namespace

TEST(Ortho, RayCastCubeFaceIsTheExactSquare) {
  for (float eye_z : {3.0f, 300.0f}) {
    const RayCastImage img = ray_cast_image(cube_scene(1), head_on(eye_z));
    for (int y = 0; y < kSize; ++y) {
      for (int x = 0; x < kSize; ++x) {
        const bool in = x >= 50 && x <= 149 && y >= 50 && y <= 149;
        ASSERT_EQ(img.covered[y * kSize + x] != 0, in) << x << "," << y << " eye " << eye_z;
        if (in) {
          ASSERT_NEAR(img.depth[y * kSize + x], eye_z - 1, 1e-3f * eye_z);
        }
      }
    }
  }
}

TEST(Ortho, SplatCubeFaceIsTheSquareWhateverTheDistanceKernelOrScheme) {
  Cube cube;
  for (float eye_z : {3.0f, 300.0f}) {
    for (SplatShape shape : {SplatShape::Square, SplatShape::Circle, SplatShape::Ellipse}) {
      for (LodScheme lod : {LodScheme::QSplat, LodScheme::Spt}) {
        RenderSettings s;
        s.shape = shape;
        FrameSettings f;
        f.lod = lod;
        const Frame frame = cube.draw(head_on(eye_z), s, f);
        // Every pixel of the face; ellipses (which follow the side faces, seen edge-on) nothing
        // beyond two pixels of its edge; circles and squares of the side faces stick out by
        // their radius (up to 4 px for the coarser nodes SPT stops at).
        const SquareCount n = count(frame, shape == SplatShape::Ellipse ? 2 : 4);
        EXPECT_EQ(n.inside, 100 * 100) << eye_z << " " << name(shape) << " " << name(lod);
        EXPECT_EQ(n.far_outside, 0) << eye_z << " " << name(shape) << " " << name(lod);
        EXPECT_NEAR(frame.depth[100 * kSize + 100], eye_z - 1, 0.02f + 1e-4f * eye_z);
      }
    }
  }
}

TEST(Ortho, ParallelEdgesStayParallelFromAnAngle) {
  // From azimuth 30°, elevation 20°: the cube's near and far vertical edges project with the
  // same length in an orthographic view (perspective would make the near one longer). Measure
  // the drawn column heights a little inside the left and right silhouette.
  Cube cube;
  const Camera c = ortho_orbit(30, 0, 4);
  RenderSettings ellipses;  // the top and bottom faces, seen edge-on, add no height
  ellipses.shape = SplatShape::Ellipse;
  const Frame f = cube.draw(c, ellipses);
  const auto column_height = [&](int x) {
    int h = 0;
    for (int y = 0; y < kSize; ++y) h += std::isfinite(f.depth[y * kSize + x]);
    return h;
  };
  int left = 0, right = kSize - 1;
  while (left < kSize && column_height(left) == 0) ++left;
  while (right > 0 && column_height(right) == 0) --right;
  ASSERT_LT(left + 10, right);
  // Elevation 0: every column of the silhouette is 2 units = 100 px high (± splat overhang).
  EXPECT_NEAR(column_height(left + 4), 100, 2);
  EXPECT_NEAR(column_height(right - 4), 100, 2);
  EXPECT_NEAR(column_height((left + right) / 2), 100, 2);
}

TEST(Ortho, PlanViewFromThePoleSeesTheTopFace) {
  Cube cube;
  const Camera c = ortho_orbit(0, 90, 4);
  const Frame f = cube.draw(c);
  EXPECT_EQ(count(f, 2).inside, 100 * 100);
  EXPECT_EQ(count(f, 2).far_outside, 0);
  EXPECT_NEAR(f.depth[100 * kSize + 100], 10 * std::sqrt(3.0f) - 1, 0.05f);
}

TEST(Ortho, QualityModeDrawsTheSquareWhateverTheDistance) {
  Cube cube;
  FrameSettings quality;
  quality.rasterizer = Rasterizer::Quality;
  for (float eye_z : {3.0f, 300.0f}) {
    const Frame frame = cube.draw(head_on(eye_z), {}, quality);
    const SquareCount n = count(frame, 2);
    EXPECT_EQ(n.inside, 100 * 100) << eye_z;
    EXPECT_EQ(n.far_outside, 0) << eye_z;
    EXPECT_NEAR(frame.depth[100 * kSize + 100], eye_z - 1, 0.02f + 1e-4f * eye_z);
    // Lit head-on by the headlight along parallel rays: one colour over the face's interior.
    EXPECT_EQ(frame.color[70 * kSize + 70], frame.color[130 * kSize + 120]) << eye_z;
  }
}

TEST(Ortho, OcclusionCullingGivesTheSameBits) {
  Cube cube;
  Camera c = ortho_orbit(20, 15, 5);
  FrameSettings culled;
  culled.occlusion.method = OcclusionMethod::ChcPlusPlus;
  culled.occlusion.leaf_points = 256;
  const Frame a = cube.draw(c), b = cube.draw(c, {}, culled);
  for (std::size_t i = 0; i < a.color.size(); ++i) ASSERT_EQ(a.color[i], b.color[i]) << i;
  c.ortho_height = -1;
  EXPECT_THROW(make_camera_frame(c), OptionError);
}

TEST(Ortho, MeshReferenceDrawsTheExactSquare) {
  // Two triangles of the square [-1, 1]² at z = 1 facing +Z.
  PointSet mesh;
  mesh.positions = {{-1, -1, 1}, {1, -1, 1}, {1, 1, 1}, {-1, 1, 1}};
  mesh.normals.assign(4, Vec3f{0, 0, 1});
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  Frame f;
  render_mesh_reference(mesh, head_on(7), RenderSettings{}, f);
  const SquareCount n = count(f, 0);
  EXPECT_EQ(n.inside, 100 * 100);
  EXPECT_EQ(n.far_outside, 0);
  EXPECT_NEAR(f.depth[100 * kSize + 100], 6, 1e-4f);
}
