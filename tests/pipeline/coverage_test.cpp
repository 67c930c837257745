// End to end: samples without normals -> PCA normals and radii -> hierarchy -> splats, checked
// against exact ray casting of the analytic surfaces.
//
// Silhouette accuracy is asserted for the ellipse kernel, whose splats are the projected discs and
// so end where the surface ends. Circle splats (the default, as in QSplat) are screen-facing discs
// of the node's full diameter: at the silhouette they stick out by one projected splat radius, so
// their silhouette is larger by design (IoU 0.91-0.95 on this sphere, see README); for them the
// tests assert what they promise: no hole, and every reference pixel covered.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "pointillist/lod/sphere_tree.hpp"
#include "pointillist/prep/prepare.hpp"
#include "pointillist/render/render.hpp"
#include "pointillist/scene/analytic.hpp"

using namespace pointillist;

namespace {

struct Coverage {
  double iou = 0;
  int holes = 0;  // background pixels strictly inside the reference silhouette
  int reference_pixels = 0;
  int missed = 0;  // reference pixels the splats leave uncovered (holes and silhouette edge)
};

// Holes are counted only where the reference pixel and its 8 neighbours are all covered, so a
// silhouette edge that falls between pixel centres is not mistaken for a hole.
Coverage compare_coverage(const RayCastImage& ref, const Frame& frame) {
  Coverage c;
  int both = 0, either = 0;
  const int w = ref.width, h = ref.height;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const std::size_t i = std::size_t(y) * w + x;
      const bool r = ref.covered[i] != 0;
      const bool s = std::isfinite(frame.depth[i]);
      both += r && s;
      either += r || s;
      c.reference_pixels += r;
      c.missed += r && !s;
      if (r && !s && x > 0 && y > 0 && x + 1 < w && y + 1 < h) {
        bool interior = true;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) interior &= ref.covered[i + dy * w + dx] != 0;
        c.holes += interior;
      }
    }
  }
  c.iou = either ? double(both) / either : 1.0;
  return c;
}

SphereTree prepared_tree(const AnalyticScene& scene, std::size_t samples, ThreadPool& pool) {
  PointSet points = sample_scene(scene, samples, 42).points;
  prepare_splats(points, pool, Progress::none(), {.normals = NormalSource::Pca});
  return build_sphere_tree(points, pool);
}

}  // namespace

TEST(Coverage, SphereFromBarePointsCoversItsRayCastSilhouetteWithoutHoles) {
  ThreadPool pool(2);
  const AnalyticScene scene = sphere_scene(1.0f);
  const SphereTree tree = prepared_tree(scene, 60'000, pool);
  // Close-up (part of the sphere fills the view), medium and far.
  for (float distance : {1.6f, 4.0f, 12.0f}) {
    const Camera cam = orbit_camera(tree.view_sphere, {.azimuth_deg = 25,
                                                       .elevation_deg = 20,
                                                       .distance = distance,
                                                       .width = 400,
                                                       .height = 320});
    const RayCastImage reference = ray_cast_image(scene, cam);
    for (SplatShape shape : {SplatShape::Ellipse, SplatShape::Circle}) {
      const bool ellipse = shape == SplatShape::Ellipse;
      Frame frame;
      render(tree.view(), cam, RenderSettings{.shape = shape}, pool, frame);
      const Coverage c = compare_coverage(reference, frame);
      SCOPED_TRACE(std::string(ellipse ? "ellipse" : "circle") + " at distance " +
                   std::to_string(distance));
      EXPECT_GT(c.reference_pixels, 1000);
      EXPECT_EQ(c.holes, 0);
      if (ellipse) EXPECT_GE(c.iou, 0.98);
      else EXPECT_LE(c.missed, c.reference_pixels / 1000);
    }
  }
}

TEST(Coverage, DemoSceneWithSharpCubeRendersWithoutHoles) {
  ThreadPool pool(2);
  const AnalyticScene scene = demo_scene();
  const SphereTree tree = prepared_tree(scene, 150'000, pool);
  for (float az : {0.0f, 70.0f}) {
    const Camera cam = orbit_camera(
        tree.view_sphere, {.azimuth_deg = az, .elevation_deg = 25, .width = 480, .height = 270});
    const RayCastImage reference = ray_cast_image(scene, cam);
    for (SplatShape shape : {SplatShape::Ellipse, SplatShape::Circle}) {
      const bool ellipse = shape == SplatShape::Ellipse;
      Frame frame;
      render(tree.view(), cam, RenderSettings{.shape = shape}, pool, frame);
      const Coverage c = compare_coverage(reference, frame);
      SCOPED_TRACE(std::string(ellipse ? "ellipse" : "circle") + " at azimuth " +
                   std::to_string(az));
      EXPECT_EQ(c.holes, 0);
      // 0.95, not the sphere's 0.98: splats on the cube's faces overhang its sharp edges by up to a
      // splat radius (edge clipping is not built yet); measured 0.966 at azimuth 0.
      if (ellipse) EXPECT_GE(c.iou, 0.95);
      else EXPECT_LE(c.missed, c.reference_pixels / 1000);
    }
  }
}
