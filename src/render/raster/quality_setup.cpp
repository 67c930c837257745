// Per-splat setup of the quality rasterizer: the node's disc in eye coordinates, its depth
// interval, its pixel box (the exact screen bound of the node's sphere, united with the
// low-pass disc), and the binning of splats into bands of rows.
#include <algorithm>
#include <cmath>
#include <limits>

#include "raster/clip_lanes.hpp"
#include "raster/quality_kernel.hpp"

namespace pointillist::quality_detail {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
// Relative and absolute slack on pixel boxes, so a pixel whose kernel test passes after rounding
// is never left outside the box.
constexpr float kBoxSlackRel = 1e-4f;
constexpr float kBoxSlackPx = 1e-2f;

struct Range {
  float lo, hi;
};

// Slopes x/z of the two planes through the eye tangent to a sphere of radius r around (x, z)
// (eye coordinates, z = depth): the sphere's projection spans these slopes. Unbounded sides when
// the sphere reaches behind the eye's side planes or holds the eye.
Range tangent_slopes(float x, float z, float r) {
  const float l2 = x * x + z * z, r2 = r * r;
  if (!(l2 > r2 * (1.0f + 1e-4f))) return {-kInf, kInf};
  const float s = std::sqrt(l2 - r2);
  const float den_hi = z * s - r * x, den_lo = z * s + r * x;
  return {den_lo > 0 ? (x * s - r * z) / den_lo : -kInf,
          den_hi > 0 ? (x * s + r * z) / den_hi : kInf};
}

// First and last pixel index whose centre (index + ½) lies in [lo, hi], clipped to [0, n − 1]
// (returned as floats; last < first when there is none).
Range pixel_span(float lo, float hi, int n) {
  const float nf = static_cast<float>(n);
  const float a = std::min(nf + 1.0f, std::max(-1.0f, lo - 0.5f));
  const float b = std::min(nf + 1.0f, std::max(-1.0f, hi - 0.5f));
  return {std::max(0.0f, std::ceil(a)), std::min(nf - 1.0f, std::floor(b))};
}

// Pixels per band: the quality rasterizer's accumulators (36 bytes per pixel) of a band stay in
// a core's L2 cache.
constexpr int kBandPixels = 1 << 13;
constexpr int kBandsPerThread = 4;

struct BandLayout {
  int rows = 1, count = 1;
};

// About kBandPixels pixels per band, and at least kBandsPerThread bands per thread when the
// image is tall enough. Changes speed only, never the image.
BandLayout choose_bands(int width, int height, unsigned threads) {
  BandLayout l;
  constexpr int kLanes = render_detail::kLanes;
  const int groups = (width + kLanes - 1) / kLanes;
  l.rows = std::max(1, kBandPixels / (groups * kLanes));
  const int wanted = static_cast<int>(threads) * kBandsPerThread;
  l.rows = std::max(1, std::min(l.rows, (height + wanted - 1) / wanted));
  l.count = (height + l.rows - 1) / l.rows;
  return l;
}

}  // namespace

SetupConstants quality_setup(const CameraFrame& camera, const RenderSettings& settings,
                             const QualitySettings& quality, bool has_colors, unsigned threads) {
  const BandLayout bands = choose_bands(camera.width, camera.height, threads);
  SetupConstants setup;
  setup.camera = camera;
  setup.rule = rule_constants(quality);
  setup.lowpass_radius_px = quality.lowpass_radius_px;
  setup.radius_scale = quality.radius_scale;
  setup.has_colors = has_colors;
  setup.base_color = settings.base_color;
  setup.band_rows = bands.rows;
  setup.band_count = bands.count;
  return setup;
}

void prepare_chunk(const SplatChunk& chunk, const SetupConstants& k, bool features,
                   std::vector<float>& splats, std::vector<std::uint32_t>& bins,
                   std::vector<float>& planes) {
  const std::size_t n = chunk.count;
  // Grown by half again when short; released when far larger than needed (a chunk's index
  // gets other parts of the scene from frame to frame: see SplatStream::trim).
  const std::size_t need = kStride * n;
  if (splats.size() > 4 * need + kStride * SplatStream::kTrimSlack) {
    std::vector<float>().swap(splats);
  }
  if (splats.size() < need) splats.resize(std::max(need, splats.size() + splats.size() / 2));
  const CameraFrame& cam = k.camera;
  const float f = cam.focal_px;
  const float half_w = 0.5f * static_cast<float>(cam.width);
  const float half_h = 0.5f * static_cast<float>(cam.height);
  const float rho = k.lowpass_radius_px;
  constexpr float kColorScale = 1.0f / 255.0f;

  const std::size_t bands = static_cast<std::size_t>(k.band_count);
  bins.assign(bands + 1, 0);
  for (std::size_t i = 0; i < n; ++i) {
    float* s = &splats[kStride * i];
    const Vec3f normal = chunk.normal[i];
    const Vec3f d = chunk.center[i] - cam.eye;
    const Vec3f c{dot(d, cam.right), dot(d, cam.up), dot(d, cam.forward)};
    const Vec3f nn{dot(normal, cam.right), dot(normal, cam.up), dot(normal, cam.forward)};
    const float r = k.radius_scale * chunk.radius[i];
    s[kCx] = c.x;
    s[kCy] = c.y;
    s[kCz] = c.z;
    s[kNx] = nn.x;
    s[kNy] = nn.y;
    s[kNz] = nn.z;
    s[kWx] = normal.x;
    s[kWy] = normal.y;
    s[kWz] = normal.z;
    s[kNc] = dot(nn, c);
    s[kInvR2] = 1.0f / (r * r);
    s[kSx] = chunk.x_px[i];
    s[kSy] = chunk.y_px[i];
    // Depth over the disc c + r·(cos φ·e1 + sin φ·e2): c_z ± r·√(e1_z² + e2_z²) = ± r·√(1 − n_z²).
    const float half_depth = r * std::sqrt(std::max(0.0f, 1.0f - nn.z * nn.z));
    s[kDepthLo] = c.z - half_depth;
    s[kDepthHi] = c.z + half_depth;
    if (k.rule.z_range) {
      s[kKey] = s[kDepthLo] - k.rule.z_range_margin * r;
      s[kBound] = s[kDepthHi] + k.rule.z_range_margin * r;
    } else {
      s[kKey] = 0;
      s[kBound] = k.rule.z_threshold * r;
    }
    if (k.has_colors) {
      const Rgb8 color = chunk.color[i];
      s[kBaseR] = static_cast<float>(color.r) * kColorScale;
      s[kBaseG] = static_cast<float>(color.g) * kColorScale;
      s[kBaseB] = static_cast<float>(color.b) * kColorScale;
    } else {
      s[kBaseR] = k.base_color.x;
      s[kBaseG] = k.base_color.y;
      s[kBaseB] = k.base_color.z;
    }
    if (features) {
      s[kSurface] = bits_to_float(chunk.surface[i]);
      s[kClipFirst] = bits_to_float(chunk.clip_first[i]);
      s[kClipCode] = bits_to_float(chunk.clip_code[i]);
    }
    // Pixel box: the sphere's projection (pixel x = W/2 + f·slope_x, y = H/2 − f·slope_y),
    // united with the low-pass disc around the projected centre.
    // Orthographic: the sphere's shadow is c ± r in eye-space units.
    const Range sx = cam.ortho ? Range{c.x - r, c.x + r} : tangent_slopes(c.x, c.z, r);
    const Range sy = cam.ortho ? Range{c.y - r, c.y + r} : tangent_slopes(c.y, c.z, r);
    const float x_lo = half_w + f * sx.lo, x_hi = half_w + f * sx.hi;
    const float y_lo = half_h - f * sy.hi, y_hi = half_h - f * sy.lo;
    const float slack_x = kBoxSlackPx + kBoxSlackRel * (x_hi - x_lo);
    const float slack_y = kBoxSlackPx + kBoxSlackRel * (y_hi - y_lo);
    const Range pi = pixel_span(std::min(x_lo - slack_x, s[kSx] - rho),
                                std::max(x_hi + slack_x, s[kSx] + rho), cam.width);
    const Range pj = pixel_span(std::min(y_lo - slack_y, s[kSy] - rho),
                                std::max(y_hi + slack_y, s[kSy] + rho), cam.height);
    s[kI0] = pi.lo;
    s[kI1] = pi.hi;
    s[kJ0] = pj.lo;
    s[kJ1] = pj.hi;
    if (pi.hi >= pi.lo && pj.hi >= pj.lo) {
      const int b0 = static_cast<int>(pj.lo) / k.band_rows, b1 = static_cast<int>(pj.hi) / k.band_rows;
      for (int b = b0; b <= b1; ++b) ++bins[static_cast<std::size_t>(b) + 1];
    }
  }
  if (features) {
    render_detail::eye_space_planes(chunk, cam, planes);
  } else {
    planes.clear();
  }
  // Counting sort by band, stream order within each band: bins[b] serves as band b's write
  // cursor (ending at band b + 1's start), then the starts are shifted back into place.
  for (std::size_t b = 0; b < bands; ++b) bins[b + 1] += bins[b];
  const std::size_t base = bands + 1;
  bins.resize(base + bins[bands]);
  for (std::size_t i = 0; i < n; ++i) {
    const float* s = &splats[kStride * i];
    if (!(s[kI1] >= s[kI0] && s[kJ1] >= s[kJ0])) continue;
    const int b0 = static_cast<int>(s[kJ0]) / k.band_rows;
    const int b1 = static_cast<int>(s[kJ1]) / k.band_rows;
    for (int b = b0; b <= b1; ++b) {
      bins[base + bins[static_cast<std::size_t>(b)]++] = static_cast<std::uint32_t>(i);
    }
  }
  for (std::size_t b = bands; b-- > 1;) bins[b] = bins[b - 1];
  bins[0] = 0;
}

}  // namespace pointillist::quality_detail
