// The quality mode's occluder pass (quality_occluders.hpp) against a brute-force oracle in
// double precision that applies the rule quality.hpp documents to every splat at every pixel:
// the occluder depth is never below the smallest reconstruction bound of a pixel's fragments
// (culling stays conservative), and it is finite wherever some splat surely gives a fragment
// (culling has something to test against).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "pointillist/core/camera.hpp"
#include "pointillist/core/thread_pool.hpp"
#include "pointillist/render/quality.hpp"
#include "pointillist/render/splat_stream.hpp"
#include "raster/quality_occluders.hpp"

using namespace pointillist;

namespace {

struct Disc {
  Vec3f center, normal;
  float radius;
};

// The documented fragment of a disc at pixel (i, j): kernel argument m and the fragment's
// reconstruction bound, in double; m = +∞ when the pixel gets no fragment.
struct OracleFragment {
  double m = std::numeric_limits<double>::infinity();
  double bound = 0;
};

OracleFragment oracle(const Disc& d, float x_px, float y_px,
                      const CameraFrame& cam, const QualitySettings& q, int i, int j) {
  const double r = double(q.radius_scale) * d.radius;
  const Vec3f dc = d.center - cam.eye;
  const double c[3] = {dot(dc, cam.right), dot(dc, cam.up), dot(dc, cam.forward)};
  const double n[3] = {dot(d.normal, cam.right), dot(d.normal, cam.up), dot(d.normal, cam.forward)};
  const double a = (i + 0.5 - 0.5 * cam.width) / cam.focal_px;
  const double b = (0.5 * cam.height - (j + 0.5)) / cam.focal_px;
  const double nc = n[0] * c[0] + n[1] * c[1] + n[2] * c[2];
  const double den = n[0] * a + n[1] * b + n[2];
  const double t = nc / den;
  double u = std::numeric_limits<double>::infinity();
  if (t > 0 && std::isfinite(t)) {
    const double e[3] = {t * a - c[0], t * b - c[1], t - c[2]};
    u = (e[0] * e[0] + e[1] * e[1] + e[2] * e[2]) / (r * r);
  }
  const double dx = i + 0.5 - x_px, dy = j + 0.5 - y_px;
  const double s = (dx * dx + dy * dy) / (double(q.lowpass_radius_px) * q.lowpass_radius_px);
  OracleFragment f;
  const double m = std::min(u, s);
  if (!(m <= 1.0)) return f;
  f.m = m;
  const double half = r * std::sqrt(std::max(0.0, 1.0 - n[2] * n[2]));
  const double lo = c[2] - half, hi = c[2] + half;
  const double depth = std::clamp(t > 0 && std::isfinite(t) ? t : c[2], lo, hi);
  f.bound = q.reconstruction == Reconstruction::ZRange ? hi + q.z_range_margin * r
                                                        : depth + q.z_threshold * r;
  return f;
}

}  // namespace

TEST(QualityOccluders, NeverBelowTheSmallestBoundAndFiniteWhereAFragmentIsSure) {
  Camera camera;
  camera.eye = {0, 0, 6};
  camera.target = {0, 0, 0};
  camera.fov_deg = 45;
  camera.width = 96;
  camera.height = 72;
  const CameraFrame cam = make_camera_frame(camera);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> pos(-2.0f, 2.0f), unit(-1.0f, 1.0f), rad(0.02f, 0.4f);
  std::vector<Disc> discs;
  while (discs.size() < 300) {
    Vec3f n{unit(rng), unit(rng), unit(rng)};
    if (length(n) < 0.1f) continue;
    discs.push_back({{pos(rng), pos(rng), pos(rng)}, n * (1.0f / length(n)), rad(rng)});
  }
  // Split over three chunks, as selection would give them.
  SplatStream stream;
  stream.with_discs = true;
  stream.chunks.resize(3);
  stream.chunk_count = 3;
  std::vector<float> x_px(discs.size()), y_px(discs.size());
  for (std::size_t k = 0; k < discs.size(); ++k) {
    const Disc& d = discs[k];
    const Vec3f dc = d.center - cam.eye;
    const float z = dot(dc, cam.forward);
    x_px[k] = 0.5f * cam.width + cam.focal_px * dot(dc, cam.right) / z;
    y_px[k] = 0.5f * cam.height - cam.focal_px * dot(dc, cam.up) / z;
    SplatChunk& ch = stream.chunks[k % 3];
    ch.reserve(ch.count + 1, false, true);
    const std::size_t i = ch.count++;
    ch.x_px[i] = x_px[k];
    ch.y_px[i] = y_px[k];
    ch.depth[i] = z;
    ch.size_px[i] = 2 * d.radius * cam.focal_px / z;
    ch.center[i] = d.center;
    ch.radius[i] = d.radius;
    ch.normal[i] = d.normal;
    ch.node[i] = static_cast<std::uint32_t>(k);
  }
  ThreadPool pool(2);
  for (Reconstruction rule : {Reconstruction::ZRange, Reconstruction::ZThreshold}) {
    QualitySettings q;
    q.reconstruction = rule;
    std::vector<float> bound(static_cast<std::size_t>(cam.width) * cam.height,
                             std::numeric_limits<float>::infinity());
    quality_detail::OccluderScratch scratch;
    QualityScratch prepared;
    const RenderSettings settings;
    // Two batches, as culling draws them.
    const SoftwareQueries::Rect r1 = quality_detail::draw_quality_occluders(
        stream, 0, 1, cam, settings, q, pool, prepared, scratch, bound);
    const SoftwareQueries::Rect r2 = quality_detail::draw_quality_occluders(
        stream, 1, 3, cam, settings, q, pool, prepared, scratch, bound);
    std::size_t sure = 0, lowered = 0;
    for (int j = 0; j < cam.height; ++j) {
      for (int i = 0; i < cam.width; ++i) {
        double smallest = std::numeric_limits<double>::infinity(), best_m = 2;
        for (std::size_t k = 0; k < discs.size(); ++k) {
          const OracleFragment f =
              oracle(discs[k], x_px[k], y_px[k], cam, q, i, j);
          if (!(f.m <= 1.0)) continue;
          smallest = std::min(smallest, f.bound);
          best_m = std::min(best_m, f.m);
        }
        const float u = bound[static_cast<std::size_t>(j) * cam.width + i];
        // Conservative: never below the pixel's smallest bound (float rounding aside), and
        // untouched where the pixel gets no fragment at all.
        if (std::isfinite(smallest)) {
          ASSERT_GE(double(u), smallest - 1e-4 * std::abs(smallest)) << i << "," << j;
        } else {
          ASSERT_EQ(u, std::numeric_limits<float>::infinity()) << i << "," << j;
        }
        if (best_m <= 0.99) {
          ++sure;
          EXPECT_TRUE(std::isfinite(u)) << i << "," << j;
        }
        if (std::isfinite(u)) {
          ++lowered;
          const bool in1 = i >= r1.x0 && i < r1.x1 && j >= r1.y0 && j < r1.y1;
          const bool in2 = i >= r2.x0 && i < r2.x1 && j >= r2.y0 && j < r2.y1;
          EXPECT_TRUE(in1 || in2) << "pixel " << i << "," << j << " lowered outside the rects";
        }
      }
    }
    EXPECT_GT(sure, 2000u);
    EXPECT_GE(lowered, sure);
  }
}

TEST(QualityOccluders, QueryFootprintCoversTheDiscsAndTheirKeys) {
  QualitySettings q;
  q.radius_scale = 1.5f;
  q.z_range_margin = 0.5f;
  q.lowpass_radius_px = 2.0f;
  const QueryFootprint range = quality_detail::quality_query_footprint(q, 1.0f);
  EXPECT_GE(range.footprint_scale, 1.5f);
  EXPECT_GE(range.depth_scale, 1.5f * 1.5f);  // (1 + margin) disc radii in front
  EXPECT_GE(range.pad_px, 2.0f);
  q.reconstruction = Reconstruction::ZThreshold;
  const QueryFootprint threshold = quality_detail::quality_query_footprint(q, 2.0f);
  EXPECT_GE(threshold.footprint_scale, 3.0f);  // the splat scale grows the discs too
  EXPECT_GE(threshold.depth_scale, 3.0f);
}
