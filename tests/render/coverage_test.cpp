// Silhouettes of splat renderings against exact references: ray casting of an analytic sphere, and
// the z-buffered triangles of the Stanford dragon (when the model has been fetched).
#include <gtest/gtest.h>

#include <cmath>

#include "pointillist/io/ply.hpp"
#include "pointillist/lod/sphere_tree.hpp"
#include "pointillist/prep/prepare.hpp"
#include "pointillist/render/mesh_reference.hpp"
#include "pointillist/render/render.hpp"
#include "pointillist/scene/analytic.hpp"
#include "render_test_util.hpp"
#include "testing/testing.hpp"

using namespace pointillist;
using namespace pointillist::render_test;

namespace {

struct Overlap {
  double iou = 0;
  int holes = 0;  // uncovered pixels whose reference pixel and 8 neighbours are all covered
  int reference_pixels = 0;
  int missed = 0;  // reference pixels left uncovered (holes and silhouette edge)
};

template <class ReferenceCovered>
Overlap compare(const Frame& frame, ReferenceCovered ref) {
  Overlap o;
  int both = 0, either = 0;
  const int w = frame.width, h = frame.height;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const bool r = ref(x, y);
      const bool s = covered(frame, x, y);
      both += r && s;
      either += r || s;
      o.reference_pixels += r;
      o.missed += r && !s;
      if (r && !s && x > 0 && y > 0 && x + 1 < w && y + 1 < h) {
        bool interior = true;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) interior &= ref(x + dx, y + dy);
        o.holes += interior;
      }
    }
  }
  o.iou = either ? double(both) / either : 1.0;
  return o;
}

}  // namespace

TEST(Coverage, SphereSplatsCoverTheRayCastSilhouetteWithoutHoles) {
  // 100,000 samples on a Fibonacci lattice (evenly spaced, spacing s = sqrt(4π/n)) with exact
  // normals and radius 0.8·s, so every surface point is within a radius of some sample.
  const std::size_t n = 100000;
  const double spacing = std::sqrt(4 * kPiD / n);
  PointSet pts;
  const double golden_angle = kPiD * (3 - std::sqrt(5.0));
  for (std::size_t i = 0; i < n; ++i) {
    const double y = 1 - 2 * (i + 0.5) / n, ring = std::sqrt(1 - y * y), phi = golden_angle * i;
    const Vec3f p{float(ring * std::cos(phi)), float(y), float(ring * std::sin(phi))};
    pts.positions.push_back(p);
    pts.normals.push_back(p);
  }
  pts.radii.assign(n, static_cast<float>(0.8 * spacing));
  const SphereTree tree = make_test_tree(pts);
  const AnalyticScene scene = sphere_scene(1.0f);
  ThreadPool pool(2);
  for (float distance : {1.6f, 4.0f, 12.0f}) {
    const Camera cam = orbit_camera(tree.view_sphere, {.azimuth_deg = 25, .elevation_deg = 20,
                                                       .distance = distance, .width = 200,
                                                       .height = 160});
    const RayCastImage ref = ray_cast_image(scene, cam);
    for (SplatShape shape : {SplatShape::Circle, SplatShape::Ellipse, SplatShape::Square}) {
      RenderSettings s;
      s.shape = shape;
      Frame frame;
      render(tree.view(), cam, s, pool, frame);
      const Overlap o = compare(frame, [&](int x, int y) { return ref.covered[y * 200 + x] != 0; });
      const char* name = shape == SplatShape::Circle ? "circle"
                         : shape == SplatShape::Ellipse ? "ellipse" : "square";
      EXPECT_EQ(o.holes, 0) << "distance " << distance << " " << name;
      EXPECT_GT(o.reference_pixels, 1000);
      // The silhouette grows by the splat radius (less for ellipses, more for squares), and a
      // splat smaller than a pixel still covers the pixel holding its centre: at distance 12 the
      // sphere is 25 px in radius and nodes of at most 1 px stand out by up to one pixel, which
      // alone bounds the overlap near 0.96.
      const double want = distance > 10 ? 0.96 : (shape == SplatShape::Square ? 0.97 : 0.98);
      EXPECT_GE(o.iou, want) << "distance " << distance << " " << name;
    }
  }
}

TEST(Coverage, DragonSplatSilhouetteMatchesItsTriangles) {
  const auto path = pointillist::testing::cached_model("dragon_vrip.ply.gz");
  if (path.empty()) GTEST_SKIP() << "dragon_vrip.ply.gz not fetched (scripts/fetch-models.sh)";
  ThreadPool pool(2);
  PointSet mesh = read_ply(path.string());
  ASSERT_TRUE(mesh.is_mesh());
  prepare_splats(mesh, pool, Progress::none(), {.normals = NormalSource::Mesh});
  const SphereTree tree = build_sphere_tree(mesh, pool);
  for (float az : {0.0f, 120.0f}) {
    const Camera cam = orbit_camera(tree.view_sphere, {.azimuth_deg = az, .elevation_deg = 15,
                                                       .width = 1280, .height = 720});
    Frame triangles;
    render_mesh_reference(mesh, cam, RenderSettings{}, triangles);
    for (SplatShape shape : {SplatShape::Circle, SplatShape::Ellipse}) {
      RenderSettings s;
      s.shape = shape;
      Frame splats;
      render(tree.view(), cam, s, pool, splats);
      const Overlap o = compare(splats, [&](int x, int y) { return covered(triangles, x, y); });
      EXPECT_GT(o.reference_pixels, 100000);
      // Ellipses follow the silhouette; circles (QSplat's radii: the smallest circle around each
      // incident triangle) stick out by a splat radius there (IoU 0.970 at azimuth 0), so for
      // them the test asserts coverage: every mesh pixel but a thousandth of the edge.
      if (shape == SplatShape::Ellipse) {
        EXPECT_GE(o.iou, 0.97) << "azimuth " << az << " ellipse";
      } else {
        EXPECT_GE(o.iou, 0.95) << "azimuth " << az << " circle";
        EXPECT_LE(o.missed, o.reference_pixels / 1000) << "azimuth " << az << " circle";
      }
    }
  }
}
