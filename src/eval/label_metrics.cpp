// Label metrics of a test render against an exact label reference (specs/sharp-features.md
// §4.5); every definition is in the header.
#include "pointillist/eval/label_metrics.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <string>
#include <utility>

#include "pointillist/core/error.hpp"
#include "pointillist/core/normal_color.hpp"

namespace pointillist {
namespace {

constexpr std::size_t kMaxPalette = 250;
constexpr int kDirectionRadius = 3;  // the 7×7 window that orients a profile

using Mask = std::vector<std::uint8_t>;

std::string rgb_text(Rgb8 c) {
  return std::to_string(c.r) + "," + std::to_string(c.g) + "," + std::to_string(c.b);
}

int channel_distance(Rgb8 a, Rgb8 b) {
  return std::max({std::abs(int(a.r) - b.r), std::abs(int(a.g) - b.g), std::abs(int(a.b) - b.b)});
}

void check_options(const LabelCompareOptions& o, Rgb8 background) {
  const auto bad = [](const std::string& what) { throw Error("label comparison: " + what); };
  if (o.palette.empty() || o.palette.size() > kMaxPalette) {
    bad("the palette has " + std::to_string(o.palette.size()) + " colours; give 1 to " +
        std::to_string(kMaxPalette));
  }
  if (o.tolerance < 0 || o.tolerance > 64) {
    bad("tolerance " + std::to_string(o.tolerance) + " levels is out of range; give 0 to 64");
  }
  if (o.band_px < 0 || o.band_px > 256 || o.mix_band_px < 0 || o.mix_band_px > 256) {
    bad("band widths " + std::to_string(o.band_px) + " and " + std::to_string(o.mix_band_px) +
        " px are out of range; give 0 to 256");
  }
  if (o.max_profiles < 0 || o.profile_length_px < 2 || o.profile_length_px > 4096) {
    bad("profiles: " + std::to_string(o.max_profiles) + " of " +
        std::to_string(o.profile_length_px) +
        " px; give a count >= 0 and a length of 2 to 4096 px");
  }
  const int apart = 2 * o.tolerance + 1;
  for (std::size_t i = 0; i < o.palette.size(); ++i) {
    if (channel_distance(o.palette[i], background) < apart) {
      bad("palette colour " + std::to_string(i) + " (" + rgb_text(o.palette[i]) +
          ") is within " + std::to_string(apart - 1) + " levels of the background " +
          rgb_text(background) + "; choose another background");
    }
    for (std::size_t j = 0; j < i; ++j) {
      if (channel_distance(o.palette[i], o.palette[j]) < apart) {
        bad("palette colours " + std::to_string(j) + " and " + std::to_string(i) + " (" +
            rgb_text(o.palette[j]) + ", " + rgb_text(o.palette[i]) +
            ") cannot be told apart at a tolerance of " + std::to_string(o.tolerance) +
            " levels; lower the tolerance");
      }
    }
  }
}

// Chebyshev dilation by k px (separable max over a (2k+1)² square); outside the image is 0.
Mask dilate(const Mask& m, int w, int h, int k) {
  Mask rows(m.size()), out(m.size());
  for (int y = 0; y < h; ++y) {
    int last = -k - 1;  // the last set pixel of this row seen so far, looking ahead by k
    for (int x = 0; x < w + k; ++x) {
      if (x < w && m[std::size_t(y) * w + x]) last = x;
      const int at = x - k;
      if (at >= 0) rows[std::size_t(y) * w + at] = (x - last <= 2 * k) ? 1 : 0;
    }
  }
  for (int x = 0; x < w; ++x) {
    int last = -k - 1;
    for (int y = 0; y < h + k; ++y) {
      if (y < h && rows[std::size_t(y) * w + x]) last = y;
      const int at = y - k;
      if (at >= 0) out[std::size_t(at) * w + x] = (y - last <= 2 * k) ? 1 : 0;
    }
  }
  return out;
}

struct Geometry {
  int w = 0, h = 0;
  Mask covered, interior, boundary;
};

Geometry geometry(const std::vector<std::uint8_t>& ref, int w, int h) {
  Geometry g{w, h, Mask(ref.size()), Mask(ref.size()), Mask(ref.size())};
  for (std::size_t i = 0; i < ref.size(); ++i) g.covered[i] = ref[i] != kLabelBackground;
  Mask background(ref.size());
  for (std::size_t i = 0; i < ref.size(); ++i) background[i] = !g.covered[i];
  const Mask near_background = dilate(background, w, h, 1);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const std::size_t i = std::size_t(y) * w + x;
      const bool border = x == 0 || y == 0 || x == w - 1 || y == h - 1;
      g.interior[i] = g.covered[i] && !near_background[i] && !border;
      if (!g.covered[i]) continue;
      const auto differs = [&](int qx, int qy) {
        if (qx < 0 || qy < 0 || qx >= w || qy >= h) return false;
        const std::uint8_t q = ref[std::size_t(qy) * w + qx];
        return q != kLabelBackground && q != ref[i];
      };
      g.boundary[i] = differs(x - 1, y) || differs(x + 1, y) || differs(x, y - 1) ||
                      differs(x, y + 1);
    }
  }
  return g;
}

struct ProfileResult {
  bool matched = false;
  double displacement_px = 0;
  int transition_px = 0;
};

// Share of colour a in c ≈ w·a + (1 − w)·b, least squares, clamped to [0, 1].
double share_of(Rgb8 c, Rgb8 a, Rgb8 b) {
  const double d[3] = {double(a.r) - b.r, double(a.g) - b.g, double(a.b) - b.b};
  const double e[3] = {double(c.r) - b.r, double(c.g) - b.g, double(c.b) - b.b};
  const double dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
  if (dd == 0) return 0;
  return std::clamp((d[0] * e[0] + d[1] * e[1] + d[2] * e[2]) / dd, 0.0, 1.0);
}

// The profile through boundary pixel (x, y): its pixel indices, or empty when it is not valid in
// the reference (see the header).
std::vector<std::size_t> profile_pixels(const std::vector<std::uint8_t>& ref, const Geometry& g,
                                        int x, int y, int length) {
  const std::uint8_t a = ref[std::size_t(y) * g.w + x];
  double nx = 0, ny = 0;
  for (int dy = -kDirectionRadius; dy <= kDirectionRadius; ++dy) {
    for (int dx = -kDirectionRadius; dx <= kDirectionRadius; ++dx) {
      const int qx = x + dx, qy = y + dy;
      if (qx < 0 || qy < 0 || qx >= g.w || qy >= g.h) continue;
      const std::uint8_t q = ref[std::size_t(qy) * g.w + qx];
      if (q != kLabelBackground && q != a) nx += dx, ny += dy;
    }
  }
  const double norm = std::hypot(nx, ny);
  if (norm == 0) return {};
  nx /= norm, ny /= norm;
  std::vector<std::size_t> pixels(static_cast<std::size_t>(length));
  for (int k = 0; k < length; ++k) {
    const int t = k - length / 2;
    const long px = std::lround(x + t * nx), py = std::lround(y + t * ny);
    if (px < 0 || py < 0 || px >= g.w || py >= g.h) return {};
    pixels[std::size_t(k)] = std::size_t(py) * std::size_t(g.w) + std::size_t(px);
    if (!g.covered[pixels[std::size_t(k)]]) return {};
  }
  // a…a b…b: the labels along it start with a (p's own side lies at negative t) and switch once.
  if (ref[pixels.front()] != a) return {};
  int switches = 0;
  for (int k = 1; k < length; ++k) switches += ref[pixels[k]] != ref[pixels[k - 1]] ? 1 : 0;
  if (switches != 1) return {};
  return pixels;
}

ProfileResult measure_profile(const std::vector<std::size_t>& pixels,
                              const std::vector<std::uint8_t>& ref,
                              const std::vector<std::uint8_t>& test, ImageRgb8View test_image,
                              std::span<const Rgb8> palette) {
  const int n = int(pixels.size());
  const std::uint8_t a = ref[pixels.front()], b = ref[pixels.back()];
  ProfileResult r;
  bool has_a = false, has_b = false;
  for (std::size_t p : pixels) has_a |= test[p] == a, has_b |= test[p] == b;
  if (!has_a || !has_b) return r;
  r.matched = true;
  // Split j (0..n): samples < j should be a, samples >= j should be b; samples lie 1 px apart,
  // so splits j and j' lie |j − j'| px apart.
  int reference_split = 0;
  while (ref[pixels[reference_split]] == a) ++reference_split;
  int cost = 0;
  for (std::size_t p : pixels) cost += test[p] != b ? 1 : 0;  // j = 0: all should be b
  int best = cost, tie_count = 1;
  double tie_sum = 0;
  for (int j = 1; j <= n; ++j) {
    const std::uint8_t l = test[pixels[j - 1]];
    cost += (l != a ? 1 : 0) - (l != b ? 1 : 0);
    if (cost < best) best = cost, tie_count = 1, tie_sum = j;
    else if (cost == best) ++tie_count, tie_sum += j;
  }
  r.displacement_px = std::abs(tie_sum / tie_count - reference_split);
  for (std::size_t p : pixels) {
    if (test[p] != kLabelMixed) continue;
    const double w = share_of(test_image.pixels[p], palette[a], palette[b]);
    if (w > 0.1 && w < 0.9) ++r.transition_px;
  }
  return r;
}

void measure_profiles(const std::vector<std::uint8_t>& ref, const std::vector<std::uint8_t>& test,
                      const Geometry& g, ImageRgb8View test_image,
                      const LabelCompareOptions& o, LabelComparison& out) {
  std::vector<std::pair<int, int>> valid;  // boundary pixels whose profile is valid
  for (int y = 0; y < g.h; ++y) {
    for (int x = 0; x < g.w; ++x) {
      if (!g.boundary[std::size_t(y) * g.w + x]) continue;
      if (!profile_pixels(ref, g, x, y, o.profile_length_px).empty()) valid.emplace_back(x, y);
    }
  }
  const std::size_t count = std::min(valid.size(), std::size_t(o.max_profiles));
  double displacement_sum = 0, transition_sum = 0;
  for (std::size_t i = 0; i < count; ++i) {
    const auto [x, y] = valid[i * valid.size() / count];
    const ProfileResult r = measure_profile(profile_pixels(ref, g, x, y, o.profile_length_px),
                                            ref, test, test_image, o.palette);
    if (!r.matched) {
      ++out.unmatched_profile_count;
      continue;
    }
    ++out.profile_count;
    displacement_sum += r.displacement_px;
    transition_sum += r.transition_px;
    out.displacement_max_px = std::max(out.displacement_max_px, r.displacement_px);
    out.transition_max_px = std::max(out.transition_max_px, double(r.transition_px));
  }
  if (out.profile_count > 0) {
    out.displacement_mean_px = displacement_sum / double(out.profile_count);
    out.transition_mean_px = transition_sum / double(out.profile_count);
  }
}

double ratio(std::uint64_t a, std::uint64_t b) { return b == 0 ? 0.0 : double(a) / double(b); }

// The angle between two decoded normals in degrees; 90 when either is the zero vector (a colour
// no unit normal encodes to).
double angle_degrees(Vec3f a, Vec3f b) {
  if (dot(a, a) == 0.0f || dot(b, b) == 0.0f) return 90.0;
  const double c = std::clamp(static_cast<double>(dot(a, b)), -1.0, 1.0);
  return std::acos(c) * (180.0 / 3.14159265358979323846);
}

}  // namespace

std::vector<std::uint8_t> label_image(ImageRgb8View image, std::span<const Rgb8> palette,
                                      Rgb8 background, int tolerance) {
  assert(image.pixels.size() == std::size_t(image.width) * std::size_t(image.height));
  if (palette.empty() || palette.size() > kMaxPalette) {
    throw Error("label image: the palette has " + std::to_string(palette.size()) +
                " colours; give 1 to " + std::to_string(kMaxPalette));
  }
  std::vector<std::uint8_t> labels(image.pixels.size());
  for (std::size_t i = 0; i < labels.size(); ++i) {
    const Rgb8 c = image.pixels[i];
    std::uint8_t l = c == background ? kLabelBackground : kLabelMixed;
    int best = tolerance + 1;  // the nearest palette colour within the tolerance
    for (std::size_t k = 0; k < palette.size() && l != kLabelBackground; ++k) {
      const int d = channel_distance(c, palette[k]);
      if (d < best) best = d, l = std::uint8_t(k);
    }
    labels[i] = l;
  }
  return labels;
}

std::vector<std::uint8_t> reference_label_image(ImageRgb8View reference,
                                                const LabelCompareOptions& o, Rgb8 background) {
  std::vector<std::uint8_t> labels =
      label_image(reference, o.palette, background, o.tolerance);
  for (std::size_t i = 0; i < labels.size(); ++i) {
    if (labels[i] != kLabelMixed) continue;
    const std::size_t x = i % std::size_t(reference.width), y = i / std::size_t(reference.width);
    throw Error(o.reference_name + ": pixel (" + std::to_string(x) + ", " + std::to_string(y) +
                ") is " + rgb_text(reference.pixels[i]) + ", neither the background " +
                rgb_text(background) + " nor a label colour of the palette; give the exact "
                "label reference (generate --reference) and its background");
  }
  return labels;
}

LabelComparison compare_labels(ImageRgb8View reference, ImageRgb8View test,
                               const LabelCompareOptions& o) {
  assert(reference.pixels.size() == std::size_t(reference.width) * std::size_t(reference.height));
  assert(test.pixels.size() == std::size_t(test.width) * std::size_t(test.height));
  if (reference.width != test.width || reference.height != test.height || reference.width <= 0 ||
      reference.height <= 0) {
    throw Error("cannot compare labels of a " + std::to_string(test.width) + "x" +
                std::to_string(test.height) + " test image against a " +
                std::to_string(reference.width) + "x" + std::to_string(reference.height) +
                " reference; render the test image at the reference's size");
  }
  LabelComparison out;
  out.background = o.background.value_or(reference.pixels[0]);
  check_options(o, out.background);
  out.depth_compared = !o.reference_depth.empty() || !o.test_depth.empty();
  if (out.depth_compared) {
    const std::size_t pixels = reference.pixels.size();
    if (o.reference_depth.size() != pixels || o.test_depth.size() != pixels) {
      throw Error("label comparison: depth images of " + std::to_string(o.reference_depth.size()) +
                  " and " + std::to_string(o.test_depth.size()) + " pixels for " +
                  std::to_string(pixels) + "-pixel images; give both depth images, of the "
                  "colour images' size");
    }
    if (!(o.see_through_gap > 0) || !std::isfinite(o.see_through_gap)) {
      throw Error("label comparison: the see-through gap must be a positive depth (2 mean splat "
                  "radii in the spec), not " + std::to_string(o.see_through_gap));
    }
  }
  out.normals_compared = !o.reference_normals.empty() || !o.test_normals.empty();
  if (out.normals_compared && (o.reference_normals.size() != reference.pixels.size() ||
                               o.test_normals.size() != reference.pixels.size())) {
    throw Error("label comparison: normal images of " + std::to_string(o.reference_normals.size()) +
                " and " + std::to_string(o.test_normals.size()) + " pixels for " +
                std::to_string(reference.pixels.size()) + "-pixel images; give both normal "
                "images, of the colour images' size");
  }
  const int w = reference.width, h = reference.height;
  const std::vector<std::uint8_t> ref = reference_label_image(reference, o, out.background);
  const std::vector<std::uint8_t> got = label_image(test, o.palette, out.background, o.tolerance);
  const Geometry g = geometry(ref, w, h);

  Mask test_foreground(got.size());
  for (std::size_t i = 0; i < got.size(); ++i) test_foreground[i] = got[i] != kLabelBackground;
  const HoleCount holes = count_holes(w, h, g.covered, test_foreground);
  out.hole_count = holes.hole_count;

  const Mask near_covered = dilate(g.covered, w, h, 1);
  const Mask band = dilate(g.boundary, w, h, o.band_px);
  const Mask mix_band = dilate(g.boundary, w, h, o.mix_band_px);
  double band_squared = 0;
  std::uint64_t band_pixels = 0;
  double band_degrees = 0, covered_degrees = 0;
  for (std::size_t i = 0; i < ref.size(); ++i) {
    const bool mixed = got[i] == kLabelMixed;
    if (!g.covered[i]) {
      if (near_covered[i]) {
        out.mixed_outside_count += mixed;
        continue;
      }
      ++out.far_background_count;
      out.overshoot_count += test_foreground[i];
      out.mixed_outside_count += mixed;
      continue;
    }
    const bool error = got[i] != ref[i];
    ++out.covered_count;
    if (mix_band[i]) {
      const Rgb8 a = reference.pixels[i], b = test.pixels[i];
      const auto sq = [](int x) { return static_cast<double>(x * x); };
      band_squared += sq(a.r - b.r) + sq(a.g - b.g) + sq(a.b - b.b);
      ++band_pixels;
    }
    if (out.normals_compared && test_foreground[i]) {
      const double degrees = angle_degrees(decode_normal_color(o.reference_normals[i]),
                                           decode_normal_color(o.test_normals[i]));
      const bool over = degrees > kNormalErrorDegrees;
      ++out.normal_covered_count, covered_degrees += degrees, out.normal_covered_over += over;
      if (mix_band[i]) {
        ++out.normal_band_count, band_degrees += degrees, out.normal_band_over += over;
      }
    }
    out.covered_error_count += error;
    out.wrong_count += error && got[i] < kLabelBackground;
    out.boundary_count += g.boundary[i];
    if (band[i]) ++out.band_count, out.band_error_count += error;
    if (!g.interior[i]) {
      out.mixed_outside_count += mixed;
      continue;
    }
    ++out.interior_count;
    out.mixed_count += mixed;
    if (out.depth_compared && error && got[i] != kLabelBackground) {
      // Nothing drawn (+inf) or NaN is no farther surface: only finite test depths count.
      out.see_through_count += o.test_depth[i] > o.reference_depth[i] + o.see_through_gap &&
                               std::isfinite(o.test_depth[i]);
    }
    if (mix_band[i]) ++out.mix_band_count, out.mixed_band_count += mixed;
  }
  assert(out.interior_count == holes.interior_count);
  out.ler_band = ratio(out.band_error_count, out.band_count);
  if (band_pixels > 0) {
    const double mse = band_squared / (3.0 * static_cast<double>(band_pixels));
    out.psnr_band_db = mse == 0 ? std::numeric_limits<double>::infinity()
                                : 10.0 * std::log10(255.0 * 255.0 / mse);
  }
  out.ler_covered = ratio(out.covered_error_count, out.covered_count);
  if (out.normal_band_count > 0) {
    out.normal_band_mean_deg = band_degrees / static_cast<double>(out.normal_band_count);
  }
  if (out.normal_covered_count > 0) {
    out.normal_covered_mean_deg = covered_degrees / static_cast<double>(out.normal_covered_count);
  }
  out.mixed_per_boundary_px = ratio(out.mixed_band_count, out.boundary_count);
  measure_profiles(ref, got, g, test, o, out);
  return out;
}

}  // namespace pointillist
