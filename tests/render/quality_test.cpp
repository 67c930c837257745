// The quality rasterizer against exact references: ray-cast analytic surfaces shaded per pixel
// with the Blinn-Phong model of RenderSettings (computed here in double), flat planes, and the
// analytic alpha blend of two colored planes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "pointillist/core/error.hpp"
#include "pointillist/lod/sphere_tree.hpp"
#include "pointillist/prep/prepare.hpp"
#include "pointillist/render/image_compare.hpp"
#include "pointillist/render/quality.hpp"
#include "pointillist/render/render.hpp"
#include "pointillist/scene/analytic.hpp"
#include "render_test_util.hpp"

using namespace pointillist;
using namespace pointillist::render_test;

namespace {

struct Vec3d {
  double x, y, z;
};
Vec3d to_d(Vec3f v) { return {v.x, v.y, v.z}; }
double dotd(Vec3d a, Vec3d b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
Vec3d unit(Vec3d a) {
  const double l = std::sqrt(dotd(a, a));
  return {a.x / l, a.y / l, a.z / l};
}

// RenderSettings' Blinn-Phong model (settings.hpp) in double with an exact power: n the unit
// normal, v the unit vector to the eye (world space), base linear 0..1. Returns 0..255 floats.
std::array<double, 3> blinn_phong(const RenderSettings& s, const CameraFrame& cam, Vec3d n, Vec3d v,
                                  Vec3d base) {
  const Vec3d le = unit(to_d(s.light_dir_eye));
  const Vec3d l = unit({cam.right.x * le.x + cam.up.x * le.y - cam.forward.x * le.z,
                        cam.right.y * le.x + cam.up.y * le.y - cam.forward.y * le.z,
                        cam.right.z * le.x + cam.up.z * le.y - cam.forward.z * le.z});
  const double ndl = dotd(n, l);
  const Vec3d h = unit({l.x + v.x, l.y + v.y, l.z + v.z});
  const double spec = ndl > 0 ? s.specular * std::pow(std::max(0.0, dotd(n, h)), s.shininess) : 0;
  const double k = s.ambient + s.diffuse * std::max(0.0, ndl);
  const double b[3] = {base.x, base.y, base.z};
  std::array<double, 3> out{};
  for (int c = 0; c < 3; ++c) out[c] = 255 * std::clamp(b[c] * k + spec, 0.0, 1.0);
  return out;
}

// Unit vector from the surface seen at pixel (i, j) toward the eye (world space).
Vec3d view_vector(const CameraFrame& cam, int i, int j) {
  const double a = (i + 0.5 - 0.5 * cam.width) / cam.focal_px;
  const double b = (0.5 * cam.height - j - 0.5) / cam.focal_px;
  return unit({-(a * cam.right.x + b * cam.up.x + cam.forward.x),
               -(a * cam.right.y + b * cam.up.y + cam.forward.y),
               -(a * cam.right.z + b * cam.up.z + cam.forward.z)});
}

// The exact image: ray_cast_image's normals shaded per pixel, background elsewhere.
std::vector<Rgb8> reference_image(const AnalyticScene& scene, const Camera& camera,
                                  const RenderSettings& s) {
  const RayCastImage rc = ray_cast_image(scene, camera);
  const CameraFrame cam = make_camera_frame(camera);
  std::vector<Rgb8> img(rc.covered.size(), s.background);
  for (int j = 0; j < rc.height; ++j) {
    for (int i = 0; i < rc.width; ++i) {
      const std::size_t p = static_cast<std::size_t>(j) * rc.width + i;
      if (!rc.covered[p]) continue;
      const auto c = blinn_phong(s, cam, to_d(rc.normal[p]), view_vector(cam, i, j),
                                 to_d(s.base_color));
      img[p] = Rgb8{static_cast<std::uint8_t>(std::lround(c[0])),
                    static_cast<std::uint8_t>(std::lround(c[1])),
                    static_cast<std::uint8_t>(std::lround(c[2]))};
    }
  }
  return img;
}

ImageRgb8View view_of(const std::vector<Rgb8>& px, int w, int h) { return {w, h, px}; }

// Scene samples as a scanner would give them: positions only, then PCA normals and cloud radii
// (prepare_splats), then the hierarchy.
SphereTree sampled_tree(const AnalyticScene& scene, std::size_t n, ThreadPool& pool) {
  PointSet p = sample_scene(scene, n, 7).points;
  prepare_splats(p, pool, Progress::none());
  return build_sphere_tree(p, pool);
}

}  // namespace

TEST(QualityRaster, BeatsFastCirclesByThreeDecibelsWithoutHolesAtThreeDistances) {
  ThreadPool pool(2);
  const AnalyticScene scene = sphere_scene(1.0f);
  const SphereTree tree = sampled_tree(scene, 40000, pool);
  RenderSettings settings;
  settings.background = {20, 40, 60};
  for (float distance : {1.6f, 4.0f, 12.0f}) {
    const Camera cam = orbit_camera(tree.view_sphere, {.azimuth_deg = 30, .elevation_deg = 20,
                                                       .distance = distance, .width = 200,
                                                       .height = 150});
    const std::vector<Rgb8> ref = reference_image(scene, cam, settings);
    Frame fast, quality;
    render(tree.view(), cam, settings, pool, fast);
    render_quality(tree.view(), cam, settings, QualitySettings{}, pool, quality);
    const ImageCompareOptions opt{.background = settings.background};
    const ImageComparison f = compare_images(view_of(ref, 200, 150), view_of(fast.color, 200, 150), opt);
    const ImageComparison q = compare_images(view_of(ref, 200, 150), view_of(quality.color, 200, 150), opt);
    std::printf("distance %.1f: fast %.2f dB ssim %.4f holes %llu | quality %.2f dB ssim %.4f holes %llu\n",
                distance, f.psnr_db, f.ssim, (unsigned long long)f.hole_count, q.psnr_db, q.ssim,
                (unsigned long long)q.hole_count);
    EXPECT_GE(q.psnr_db, f.psnr_db + 3.0) << "distance " << distance;
    EXPECT_EQ(q.hole_count, 0u) << "distance " << distance;
    EXPECT_GT(q.interior_count, 1000u) << "distance " << distance;
  }
}
