// The quality rasterizer against exact references: ray-cast analytic surfaces shaded per pixel
// with the Blinn-Phong model of RenderSettings (computed here in double), flat planes, the
// analytic alpha blend of two colored planes, and the z-buffered triangles of the dragon.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <optional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "pointillist/core/error.hpp"
#include "pointillist/io/ply.hpp"
#include "pointillist/lod/sphere_tree.hpp"
#include "pointillist/prep/prepare.hpp"
#include "pointillist/eval/image_compare.hpp"
#include "pointillist/render/mesh_reference.hpp"
#include "pointillist/render/quality.hpp"
#include "pointillist/render/render.hpp"
#include "pointillist/scene/analytic.hpp"
#include "render_test_util.hpp"
#include "testing/testing.hpp"

using namespace pointillist;
using namespace pointillist::render_test;

namespace {

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

ImageRgb8View view_of(std::span<const Rgb8> px, int w, int h) { return {w, h, px}; }

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

namespace {

// A flat rectangle c + u·e1 + v·e2 (u in [u0, u1], v in [v0, v1], e1 ⟂ e2 unit, normal
// e1 × e2) sampled on a grid of spacing h, each sample moved by up to ±h/4 along u and v (seeded).
// Every point of the rectangle at least h/2 inside its edges is within h·(√½ + √⅛) ≈ 1.06·h of
// a sample, so discs of radius 1.2·h (×radius_scale 1.1 in quality mode) leave no gap.
struct PlanePatch {
  Vec3f c, e1, e2;
  float u0, u1, v0, v1;
  Rgb8 color;
  Vec3f normal() const { return cross(e1, e2); }
};
constexpr float kPatchRadiusOverSpacing = 1.2f;

void add_patch(const PlanePatch& p, float h, std::uint32_t seed, PointSet& out) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> jitter(-0.25f * h, 0.25f * h);
  const int nu = static_cast<int>(std::lround((p.u1 - p.u0) / h));
  const int nv = static_cast<int>(std::lround((p.v1 - p.v0) / h));
  for (int a = 0; a < nu; ++a) {
    for (int b = 0; b < nv; ++b) {
      const float u = p.u0 + (static_cast<float>(a) + 0.5f) * h + jitter(rng);
      const float v = p.v0 + (static_cast<float>(b) + 0.5f) * h + jitter(rng);
      out.positions.push_back(p.c + p.e1 * u + p.e2 * v);
      out.normals.push_back(p.normal());
      out.colors.push_back(p.color);
      out.radii.push_back(kPatchRadiusOverSpacing * h);
    }
  }
}

// Where the ray of pixel (i, j) of an axis camera (eye at the origin, world = eye space with
// depth = −z) meets the patch's plane, in the patch's (u, v); nullopt when it does not (t <= 0).
struct PatchHit {
  double u, v;
};
std::optional<PatchHit> hit_patch(const PlanePatch& p, const CameraFrame& cam, int i, int j) {
  const Vec3d d{(i + 0.5 - 0.5 * cam.width) / cam.focal_px, (0.5 * cam.height - j - 0.5) / cam.focal_px,
                -1.0};
  const Vec3d n = unit(to_d(p.normal()));
  const Vec3d c = to_d(p.c);
  const double t = dotd(n, c) / dotd(n, d);
  if (!(t > 0)) return std::nullopt;
  const Vec3d q{t * d.x - c.x, t * d.y - c.y, t * d.z - c.z};
  return PatchHit{dotd(q, to_d(p.e1)), dotd(q, to_d(p.e2))};
}
// Inside the rectangle by at least `margin` (world units, in the plane).
bool inside(const PlanePatch& p, const PatchHit& h, double margin) {
  return h.u >= p.u0 + margin && h.u <= p.u1 - margin && h.v >= p.v0 + margin && h.v <= p.v1 - margin;
}
// Outside the rectangle grown by `margin`.
bool outside(const PlanePatch& p, const PatchHit& h, double margin) {
  return h.u < p.u0 - margin || h.u > p.u1 + margin || h.v < p.v0 - margin || h.v > p.v1 + margin;
}

// The exact shade of the patch at pixel (i, j) (0..255, unrounded).
std::array<double, 3> patch_shade(const RenderSettings& s, const CameraFrame& cam,
                                  const PlanePatch& p, int i, int j) {
  return blinn_phong(s, cam, unit(to_d(p.normal())), view_vector(cam, i, j),
                     {p.color.r / 255.0, p.color.g / 255.0, p.color.b / 255.0});
}

double luma(double r, double g, double b) { return 0.299 * r + 0.587 * g + 0.114 * b; }

// Two parallel rectangles turned 30° about the y axis, 0.6 apart along their normal: a small
// red one in front covering the left part of a larger green one. Spacing h = 0.04, so discs have
// R = 1.1·1.2·h = 0.053 in quality mode and the gap is 11 R, far above Z-range's worst case
// 2R·(2·sin 30° + 0.5)·cos 30° = 0.14 (quality.hpp) and Z-threshold's ε·R = 0.053.
constexpr float kTwoPlaneSpacing = 0.04f;
constexpr double kTwoPlaneRadius = 1.1 * kPatchRadiusOverSpacing * kTwoPlaneSpacing;
struct TwoPlanes {
  PlanePatch front, back;
  PointSet points;
};
TwoPlanes two_planes() {
  const float a = 30.0f * static_cast<float>(kPiD) / 180.0f;
  const Vec3f e1{std::cos(a), 0, -std::sin(a)}, e2{0, 1, 0};
  const Vec3f n = cross(e1, e2);
  TwoPlanes t;
  t.front = {{0, 0, -2}, e1, e2, -1.2f, 0.0f, -0.8f, 0.8f, {220, 60, 40}};
  t.back = {Vec3f{0, 0, -2} - n * 0.6f, e1, e2, -1.6f, 1.6f, -1.2f, 1.2f, {40, 200, 90}};
  add_patch(t.front, kTwoPlaneSpacing, 1, t.points);
  add_patch(t.back, kTwoPlaneSpacing, 2, t.points);
  return t;
}

// Pixels of the two-plane view by what the exact geometry puts there: the front rectangle (at
// least h inside its edges, with the back one behind it), or the back one alone (the front
// plane's hit farther than R + 3 px from the front rectangle, so no front disc or low-pass
// footprint reaches it). Pixels near edges are left out.
struct PixelClasses {
  std::vector<std::pair<int, int>> front, back_only;
};
PixelClasses classify(const TwoPlanes& t, const CameraFrame& cam) {
  PixelClasses out;
  const double px_world = 3.0 * 3.0 / cam.focal_px / std::cos(kPiD / 6);  // 3 px at depth <= 3
  for (int j = 0; j < cam.height; ++j) {
    for (int i = 0; i < cam.width; ++i) {
      const auto f = hit_patch(t.front, cam, i, j);
      const auto b = hit_patch(t.back, cam, i, j);
      if (!f || !b || !inside(t.back, *b, kTwoPlaneSpacing)) continue;
      if (inside(t.front, *f, kTwoPlaneSpacing)) out.front.emplace_back(i, j);
      else if (outside(t.front, *f, kTwoPlaneRadius + px_world)) out.back_only.emplace_back(i, j);
    }
  }
  return out;
}

constexpr Reconstruction kBothRules[] = {Reconstruction::ZThreshold, Reconstruction::ZRange};
const char* rule_name(Reconstruction r) {
  return r == Reconstruction::ZRange ? "ZRange" : "ZThreshold";
}

}  // namespace

TEST(QualityRaster, FlatPlaneIsShadedUniformlyByNormalisedWeights) {
  // A plane facing the camera, filling the view, with one normal and one color: the exact shade
  // is one value, base·(ambient + diffuse·n·l) (no specular, so the view vector does not enter).
  // The renderer divides the kernel-weighted sums by the sum of weights; that sum varies from
  // pixel to pixel with the jittered samples (tens of percent), the quotient must not. Float
  // rounding is ~1e-6 relative, so every pixel should hold the exact value rounded: allowed are
  // a deviation of at most 1 level per channel (a value on a rounding boundary) and a luma
  // standard deviation of at most 0.25 levels (a quarter of the 8-bit step). Dropping the
  // division by the weight sum was measured to give luma 102 levels off with a standard
  // deviation of 4.8 levels (most pixels clamp at 255).
  ThreadPool pool(2);
  PointSet points;
  const PlanePatch plane{{0, 0, -2}, {1, 0, 0}, {0, 1, 0}, -1.8f, 1.8f, -1.4f, 1.4f, {}};
  add_patch(plane, 0.05f, 3, points);
  points.colors.clear();
  const SphereTree tree = build_sphere_tree(points, pool);
  const Camera camera = axis_camera(96, 72);
  const CameraFrame cam = make_camera_frame(camera);
  RenderSettings settings;
  settings.base_color = {0.9f, 0.6f, 0.3f};
  settings.light_dir_eye = {0.3f, 0.4f, 1.0f};
  settings.specular = 0;
  const double ndl = 1.0 / std::sqrt(0.09 + 0.16 + 1.0);  // n = (0, 0, 1) in eye space
  const double k = settings.ambient + settings.diffuse * ndl;
  const double exact[3] = {255 * 0.9 * k, 255 * 0.6 * k, 255 * 0.3 * k};  // 192.8, 128.6, 64.3
  const double exact_luma = luma(exact[0], exact[1], exact[2]);
  for (Reconstruction r : kBothRules) {
    Frame frame;
    render_quality(tree.view(), camera, settings, {.reconstruction = r}, pool, frame);
    double sum = 0, sum2 = 0, max_dev = 0;
    int count = 0;
    // Every pixel is interior: the plane's samples reach 1.8 and 1.4 from the axis, the view
    // 1.54 and 1.15 at depth 2. Skip a 2-pixel border anyway.
    for (int j = 2; j < cam.height - 2; ++j) {
      for (int i = 2; i < cam.width - 2; ++i) {
        const Rgb8 c = frame.color[static_cast<std::size_t>(j) * cam.width + i];
        const double y = luma(c.r, c.g, c.b) - exact_luma;
        sum += y;
        sum2 += y * y;
        ++count;
        max_dev = std::max({max_dev, std::abs(c.r - exact[0]), std::abs(c.g - exact[1]),
                            std::abs(c.b - exact[2])});
      }
    }
    const double mean = sum / count;
    const double sd = std::sqrt(std::max(0.0, sum2 / count - mean * mean));
    std::printf("%s: luma - exact: mean %.3f, sd %.3f; max channel deviation %.3f\n", rule_name(r),
                mean, sd, max_dev);
    EXPECT_LE(sd, 0.25) << rule_name(r);
    EXPECT_LE(std::abs(mean), 0.5) << rule_name(r);
    EXPECT_LE(max_dev, 1.0) << rule_name(r);
  }
}

TEST(QualityRaster, ImageBitsDoNotDependOnThreadCountOrScratchReuse) {
  ThreadPool one(1), two(2);
  const AnalyticScene scene = demo_scene();
  const SphereTree tree = sampled_tree(scene, 30000, two);
  // 160×120: one thread draws 4 bands of 30 rows, two threads 8 bands of 15 rows.
  const Camera cam = orbit_camera(tree.view_sphere, {.azimuth_deg = 40, .elevation_deg = 25,
                                                     .width = 160, .height = 120});
  const Camera other = orbit_camera(tree.view_sphere, {.azimuth_deg = 200, .width = 160, .height = 120});
  for (Reconstruction r : kBothRules) {
    for (float opacity : {1.0f, 0.5f}) {
      const QualitySettings q{.reconstruction = r, .opacity = opacity};
      const std::string what = std::string(rule_name(r)) + " opacity " + std::to_string(opacity);
      Frame a, b;
      render_quality(tree.view(), cam, RenderSettings{}, q, one, a);
      // Two threads, with scratch buffers left over from another view.
      QualityScratch scratch;
      render_quality(tree.view(), other, RenderSettings{}, q, two, b, scratch);
      render_quality(tree.view(), cam, RenderSettings{}, q, two, b, scratch);
      ASSERT_EQ(a.color.size(), b.color.size());
      EXPECT_EQ(std::memcmp(a.color.data(), b.color.data(), a.color.size() * sizeof(Rgb8)), 0) << what;
      EXPECT_EQ(std::memcmp(a.depth.data(), b.depth.data(), a.depth.size() * sizeof(float)), 0) << what;
      std::size_t drawn = 0;
      for (float d : a.depth) drawn += std::isfinite(d);
      EXPECT_GT(drawn, 2000u) << what;
    }
  }
}

TEST(QualityRaster, FrontPlaneHidesTheParallelPlaneBehindIt) {
  ThreadPool pool(2);
  const TwoPlanes planes = two_planes();
  const SphereTree tree = build_sphere_tree(planes.points, pool);
  const Camera camera = axis_camera(128, 96);
  const CameraFrame cam = make_camera_frame(camera);
  const PixelClasses px = classify(planes, cam);
  ASSERT_GT(px.front.size(), 1500u);
  ASSERT_GT(px.back_only.size(), 1000u);
  RenderSettings settings;
  settings.background = {10, 10, 30};
  for (Reconstruction r : kBothRules) {
    Frame frame;
    render_quality(tree.view(), camera, settings, {.reconstruction = r}, pool, frame);
    // Exact shade of the plane that should be seen, within 1 level (8-bit rounding of the
    // renderer plus float error); the planes' colors differ by 140+ levels in red and green.
    const auto check = [&](const std::vector<std::pair<int, int>>& pixels, const PlanePatch& p,
                           const char* which) {
      int bad = 0;
      for (auto [i, j] : pixels) {
        const auto want = patch_shade(settings, cam, p, i, j);
        const Rgb8 c = frame.color[static_cast<std::size_t>(j) * cam.width + i];
        const bool ok = std::abs(c.r - want[0]) <= 1.0 && std::abs(c.g - want[1]) <= 1.0 &&
                        std::abs(c.b - want[2]) <= 1.0;
        if (!ok && ++bad <= 3) {
          ADD_FAILURE() << rule_name(r) << " " << which << " pixel (" << i << ", " << j << "): got "
                        << int(c.r) << " " << int(c.g) << " " << int(c.b) << ", want " << want[0]
                        << " " << want[1] << " " << want[2];
        }
      }
      EXPECT_EQ(bad, 0) << rule_name(r) << " " << which << " of " << pixels.size();
    };
    check(px.front, planes.front, "front");
    check(px.back_only, planes.back, "back only");
  }
}

TEST(QualityRaster, OpacityBlendsTwoPlanesFrontToBack) {
  // color = A·c1 + A(1−A)·c2 + (1−A)²·bg where both planes are, A·c2 + (1−A)·bg where only the
  // back one is (quality.hpp), c1, c2 the exact shades. Tolerance 1.5 levels: the renderer
  // rounds each shade to 8 bits before compositing (at most 0.5·(A + A(1−A)) < 0.5) and the
  // result once more (0.5).
  ThreadPool pool(2);
  const TwoPlanes planes = two_planes();
  const SphereTree tree = build_sphere_tree(planes.points, pool);
  const Camera camera = axis_camera(128, 96);
  const CameraFrame cam = make_camera_frame(camera);
  const PixelClasses px = classify(planes, cam);
  RenderSettings settings;
  settings.background = {30, 60, 200};
  const Rgb8 bg = settings.background;
  for (Reconstruction r : kBothRules) {
    for (float opacity : {0.6f, 0.25f}) {
      const double a = opacity;
      Frame frame;
      render_quality(tree.view(), camera, settings, {.reconstruction = r, .opacity = opacity},
                     pool, frame);
      double worst = 0;
      for (bool both : {true, false}) {
        for (auto [i, j] : both ? px.front : px.back_only) {
          const auto c1 = patch_shade(settings, cam, planes.front, i, j);
          const auto c2 = patch_shade(settings, cam, planes.back, i, j);
          const double bgc[3] = {double(bg.r), double(bg.g), double(bg.b)};
          const Rgb8 got = frame.color[static_cast<std::size_t>(j) * cam.width + i];
          const double g[3] = {double(got.r), double(got.g), double(got.b)};
          for (int c = 0; c < 3; ++c) {
            const double want = both ? a * c1[c] + a * (1 - a) * c2[c] + (1 - a) * (1 - a) * bgc[c]
                                     : a * c2[c] + (1 - a) * bgc[c];
            worst = std::max(worst, std::abs(g[c] - want));
          }
        }
      }
      std::printf("%s, opacity %.2f: largest deviation from the analytic blend %.3f levels\n",
                  rule_name(r), opacity, worst);
      EXPECT_LE(worst, 1.5) << rule_name(r) << " opacity " << opacity;
    }
  }
}

TEST(QualityRaster, DragonBeatsFastCirclesAgainstTheTriangleMesh) {
  const auto path = pointillist::testing::cached_model("dragon_vrip.ply.gz");
  if (path.empty()) GTEST_SKIP() << "dragon_vrip.ply.gz not fetched (scripts/fetch-models.sh)";
  ThreadPool pool(2);
  PointSet mesh = read_ply(path.string());
  prepare_splats(mesh, pool, Progress::none());
  const SphereTree tree = build_sphere_tree(mesh, pool);
  const Camera cam = orbit_camera(tree.view_sphere, {.azimuth_deg = 30, .elevation_deg = 10,
                                                     .width = 400, .height = 300});
  Frame reference, fast, quality;
  render_mesh_reference(mesh, cam, RenderSettings{}, reference);
  render(tree.view(), cam, RenderSettings{}, pool, fast);
  const ImageRgb8View ref{reference.width, reference.height, reference.color};
  const ImageComparison f = compare_images(ref, {fast.width, fast.height, fast.color});
  for (Reconstruction r : kBothRules) {
    render_quality(tree.view(), cam, RenderSettings{}, {.reconstruction = r}, pool, quality);
    const ImageComparison q = compare_images(ref, {quality.width, quality.height, quality.color});
    std::printf("dragon 400x300, %s: fast %.2f dB ssim %.4f iou %.4f holes %llu | quality %.2f dB "
                "ssim %.4f iou %.4f holes %llu\n",
                rule_name(r), f.psnr_db, f.ssim, f.silhouette_iou, (unsigned long long)f.hole_count,
                q.psnr_db, q.ssim, q.silhouette_iou, (unsigned long long)q.hole_count);
    EXPECT_GE(q.psnr_db, f.psnr_db) << rule_name(r);
    EXPECT_EQ(q.hole_count, 0u) << rule_name(r);
    EXPECT_GT(q.interior_count, 20000u) << rule_name(r);
  }
}
