// The Stanford dragon (fetched by scripts/fetch-models.sh): the splat rendering's silhouette must
// match a z-buffered rendering of the dragon's own triangles.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "pointillist/format/ptl_v2.hpp"
#include "pointillist/format/qs.hpp"
#include "pointillist/io/ply.hpp"
#include "pointillist/lod/sphere_tree.hpp"
#include "pointillist/prep/prepare.hpp"
#include "pointillist/render/mesh_reference.hpp"
#include "pointillist/lod/sequential_point_tree.hpp"
#include "pointillist/eval/image_compare.hpp"
#include "pointillist/render/render.hpp"
#include "pointillist/render/spt_render.hpp"
#include "testing/testing.hpp"

using namespace pointillist;

TEST(Dragon, SplatSilhouetteMatchesTheTriangleMesh) {
  const auto path = pointillist::testing::cached_model("dragon_vrip.ply.gz");
  if (path.empty()) GTEST_SKIP() << "dragon not fetched (run scripts/fetch-models.sh)";
  ThreadPool pool(2);
  const PointSet mesh = read_ply(path.string());
  ASSERT_EQ(mesh.size(), 437645u);
  PointSet splats = mesh;
  prepare_splats(splats, pool, Progress::none());
  const SphereTree tree = build_sphere_tree(splats, pool);
  for (float az : {0.0f, 90.0f, 215.0f}) {
    const Camera cam = orbit_camera(tree.view_sphere,
                                    {.azimuth_deg = az, .elevation_deg = 15, .width = 480, .height = 360});
    Frame mesh_frame;
    render_mesh_reference(mesh, cam, RenderSettings{}, mesh_frame);
    // Ellipse splats end where the surface ends: their silhouette must match the mesh's. Circle
    // splats (the default) stick out by a splat radius at the silhouette by design; they must
    // still cover every pixel of the mesh (see tests/pipeline/coverage_test.cpp).
    for (SplatShape shape : {SplatShape::Ellipse, SplatShape::Circle}) {
      Frame splat_frame;
      render(tree.view(), cam, RenderSettings{.shape = shape}, pool, splat_frame);
      std::size_t both = 0, either = 0, mesh_pixels = 0, holes = 0;
      const int w = cam.width, h = cam.height;
      auto mesh_at = [&](int x, int y) { return std::isfinite(mesh_frame.depth[std::size_t(y) * w + x]); };
      for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
          const bool s = std::isfinite(splat_frame.depth[std::size_t(y) * w + x]);
          const bool m = mesh_at(x, y);
          both += s && m;
          either += s || m;
          mesh_pixels += m;
          // A hole: a pixel the mesh covers, with all 8 neighbours covered too, left empty.
          if (m && !s && x > 0 && y > 0 && x + 1 < w && y + 1 < h) {
            bool interior = true;
            for (int dy = -1; dy <= 1; ++dy)
              for (int dx = -1; dx <= 1; ++dx) interior &= mesh_at(x + dx, y + dy);
            holes += interior;
          }
        }
      }
      // Circles: none. Ellipses: at most 2 isolated pixels (measured 1 in 172,800 at azimuths 0
      // and 90): an interior node drawn as one ellipse of its mean normal does not always cover
      // what its children's ellipses would where the surface curves away from the eye.
      if (shape == SplatShape::Circle) EXPECT_EQ(holes, 0u) << "circle, azimuth " << az;
      else EXPECT_LE(holes, 2u) << "ellipse, azimuth " << az;
      ASSERT_GT(mesh_pixels, 10000u);
      if (shape == SplatShape::Ellipse) {
        EXPECT_GE(double(both) / double(either), 0.97) << "ellipse, azimuth " << az;
      } else {
        EXPECT_GE(double(both) / double(mesh_pixels), 0.999) << "circle, azimuth " << az;
      }
    }
  }
}

TEST(Dragon, SequentialPointTreeImageMatchesTheQsplatTraversal) {
  const auto path = pointillist::testing::cached_model("dragon_vrip.ply.gz");
  if (path.empty()) GTEST_SKIP() << "dragon not fetched (run scripts/fetch-models.sh)";
  ThreadPool pool(2);
  PointSet splats = read_ply(path.string());
  prepare_splats(splats, pool, Progress::none());
  const SphereTree tree = build_sphere_tree(splats, pool);
  const SequentialPointTree spt = build_sequential_point_tree(splats, pool);
  for (float az : {0.0f, 150.0f}) {
    const Camera cam = orbit_camera(tree.view_sphere,
                                    {.azimuth_deg = az, .elevation_deg = 10, .width = 1280, .height = 720});
    Frame q, s;
    render(tree.view(), cam, RenderSettings{}, pool, q);
    SptSelectionStats tiny;
    render_spt(spt, cam, RenderSettings{}, {.epsilon_px = 1}, pool, s);
    // Same splats, different hierarchies and LOD rules: the images must agree closely. Measured
    // at 1280x720, azimuth 0: PSNR 35.9 dB, SSIM 0.988, IoU 0.995.
    const ImageComparison c =
        compare_images({q.width, q.height, q.color}, {s.width, s.height, s.color});
    EXPECT_GE(c.psnr_db, 32.0) << "azimuth " << az;
    EXPECT_GE(c.ssim, 0.97) << "azimuth " << az;
    EXPECT_GE(c.silhouette_iou, 0.98) << "azimuth " << az;
    EXPECT_EQ(c.hole_count, 0u) << "azimuth " << az;
    // With a tiny error bound every front-facing leaf is drawn, as in the QSplat traversal at a
    // tiny threshold.
    Frame all_q, all_s;
    render_spt(spt, cam, RenderSettings{}, {.epsilon_px = 1e-4f}, pool, all_s, &tiny);
    render(tree.view(), cam, RenderSettings{.threshold_px = 1e-4f}, pool, all_q);
    EXPECT_EQ(all_s.stats.splats, all_q.stats.splats) << "azimuth " << az;
  }
}

TEST(Dragon, CompactFileImagesAreAsGoodAsQsplatsAgainstTheTriangles) {
  // The same mesh written as .ptl version 2 and as QSplat's .qs (qsplat_make's rules), each
  // rendered and compared with the mesh's own triangles: v2 must be at least as good as QSplat
  // within small margins (bench/quality.sh measures 1280×720; here 640×480 for time).
  const auto path = pointillist::testing::cached_model("dragon_vrip.ply.gz");
  if (path.empty()) GTEST_SKIP() << "dragon not fetched (run scripts/fetch-models.sh)";
  ThreadPool pool(2);
  const PointSet mesh = read_ply(path.string());
  pointillist::testing::TempDir dir;
  PointSet splats = mesh;
  prepare_splats(splats, pool, Progress::none());
  write_ptl_v2(dir.file("d.ptl"), build_sphere_tree(splats, pool), "");
  const SphereTree v2 = PtlV2File::open(dir.file("d.ptl"))->decode_all();
  write_qs(dir.file("d.qs"), mesh);
  const SphereTree qs = read_qs(dir.file("d.qs")).tree;
  double psnr_sum[2] = {0, 0}, ssim_sum[2] = {0, 0};
  int cases = 0;
  for (float az : {0.0f, 135.0f}) {
    const Camera cam =
        orbit_camera(v2.view_sphere, {.azimuth_deg = az, .elevation_deg = az > 0 ? 20.0f : 0.0f,
                                      .width = 640, .height = 480});
    Frame reference;
    render_mesh_reference(mesh, cam, RenderSettings{}, reference);
    for (SplatShape shape : {SplatShape::Circle, SplatShape::Ellipse}) {
      ImageComparison c[2];
      for (int m = 0; m < 2; ++m) {
        Frame f;
        render((m == 0 ? v2 : qs).view(), cam, RenderSettings{.shape = shape}, pool, f);
        c[m] = compare_images({reference.width, reference.height, reference.color},
                              {f.width, f.height, f.color},
                              {.background = RenderSettings{}.background});
        psnr_sum[m] += c[m].psnr_db;
        ssim_sum[m] += c[m].ssim;
      }
      ++cases;
      std::printf("[dragon v2 vs qs] az %g %s: PSNR %.2f / %.2f dB, SSIM %.4f / %.4f, IoU %.4f / "
                  "%.4f, holes %zu / %zu\n",
                  az, shape == SplatShape::Circle ? "circle" : "ellipse", c[0].psnr_db,
                  c[1].psnr_db, c[0].ssim, c[1].ssim, c[0].silhouette_iou, c[1].silhouette_iou,
                  std::size_t(c[0].hole_count), std::size_t(c[1].hole_count));
      EXPECT_GE(c[0].psnr_db, c[1].psnr_db - 0.25) << "azimuth " << az;
      EXPECT_GE(c[0].ssim, c[1].ssim - 0.002) << "azimuth " << az;
      EXPECT_GE(c[0].silhouette_iou, c[1].silhouette_iou - 0.003) << "azimuth " << az;
      if (shape == SplatShape::Circle) {
        EXPECT_EQ(c[0].hole_count, 0u) << "azimuth " << az;
      }
    }
  }
  // On average over the views and kernels, at least as good.
  EXPECT_GE(psnr_sum[0] / cases, psnr_sum[1] / cases);
  EXPECT_GE(ssim_sum[0] / cases, ssim_sum[1] / cases);
}
