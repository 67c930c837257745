// Image-quality metrics: PSNR, SSIM (Wang, Bovik, Sheikh, Simoncelli, "Image quality
// assessment: from error visibility to structural similarity", IEEE TIP 13(4), 2004) and
// silhouette masks. Choices are documented in the header.
#include "pointillist/eval/image_compare.hpp"

#include <array>
#include <cassert>
#include <cmath>
#include <limits>
#include <string>

#include "pointillist/core/error.hpp"

namespace pointillist {
namespace {

constexpr int kWindow = 11;            // SSIM window side, pixels
constexpr double kSigma = 1.5;         // SSIM Gaussian σ, pixels
constexpr double kC1 = (0.01 * 255) * (0.01 * 255);
constexpr double kC2 = (0.03 * 255) * (0.03 * 255);

std::string size_text(ImageRgb8View image) {
  return std::to_string(image.width) + "x" + std::to_string(image.height);
}

void check_pair(ImageRgb8View reference, ImageRgb8View test) {
  assert(reference.pixels.size() == std::size_t(reference.width) * std::size_t(reference.height));
  assert(test.pixels.size() == std::size_t(test.width) * std::size_t(test.height));
  if (reference.width != test.width || reference.height != test.height) {
    throw Error("cannot compare images of different sizes: reference is " + size_text(reference) +
                ", test is " + size_text(test) +
                "; render the test image at the reference's size (e.g. --size " +
                size_text(reference) + ")");
  }
  if (reference.width <= 0 || reference.height <= 0) {
    throw Error("cannot compare empty images (" + size_text(reference) +
                "); give images with at least one pixel");
  }
}

std::vector<double> luma(ImageRgb8View image) {
  std::vector<double> y(image.pixels.size());
  for (std::size_t i = 0; i < y.size(); ++i) {
    const Rgb8 p = image.pixels[i];
    y[i] = 0.299 * p.r + 0.587 * p.g + 0.114 * p.b;
  }
  return y;
}

std::array<double, kWindow> gaussian_weights() {
  std::array<double, kWindow> w{};
  double sum = 0;
  for (int i = 0; i < kWindow; ++i) {
    const double d = i - kWindow / 2;
    w[i] = std::exp(-d * d / (2 * kSigma * kSigma));
    sum += w[i];
  }
  for (double& v : w) v /= sum;
  return w;
}

}  // namespace

double mse_rgb(ImageRgb8View reference, ImageRgb8View test) {
  check_pair(reference, test);
  std::uint64_t sum = 0;  // at most 3 · 65025 per pixel: no overflow below 9·10^13 pixels
  for (std::size_t i = 0; i < reference.pixels.size(); ++i) {
    const Rgb8 a = reference.pixels[i], b = test.pixels[i];
    const int dr = int(a.r) - b.r, dg = int(a.g) - b.g, db = int(a.b) - b.b;
    sum += std::uint64_t(dr * dr + dg * dg + db * db);
  }
  return double(sum) / (3.0 * double(reference.pixels.size()));
}

double psnr_rgb(ImageRgb8View reference, ImageRgb8View test) {
  const double mse = mse_rgb(reference, test);
  if (mse == 0) return std::numeric_limits<double>::infinity();
  return 10.0 * std::log10(255.0 * 255.0 / mse);
}

double ssim_luma(ImageRgb8View reference, ImageRgb8View test) {
  check_pair(reference, test);
  const int w = reference.width, h = reference.height;
  if (w < kWindow || h < kWindow) {
    throw Error("SSIM needs images of at least " + std::to_string(kWindow) + "x" +
                std::to_string(kWindow) + " pixels (its Gaussian window); these are " +
                size_text(reference) + "; compare larger renders");
  }
  const std::vector<double> x = luma(reference), y = luma(test);
  const std::array<double, kWindow> g = gaussian_weights();

  // Separable filter, one output row at a time: a vertical pass over the 11 rows into per-column
  // sums, then a horizontal pass, so memory stays at a few rows whatever the image size.
  std::vector<double> mx(w), my(w), mxx(w), myy(w), mxy(w);
  double total = 0;
  for (int y0 = 0; y0 + kWindow <= h; ++y0) {
    for (int c = 0; c < w; ++c) {
      double sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
      for (int k = 0; k < kWindow; ++k) {
        const std::size_t i = std::size_t(y0 + k) * std::size_t(w) + std::size_t(c);
        const double a = x[i], b = y[i];
        sx += g[k] * a;
        sy += g[k] * b;
        sxx += g[k] * a * a;
        syy += g[k] * b * b;
        sxy += g[k] * a * b;
      }
      mx[c] = sx, my[c] = sy, mxx[c] = sxx, myy[c] = syy, mxy[c] = sxy;
    }
    for (int x0 = 0; x0 + kWindow <= w; ++x0) {
      double ux = 0, uy = 0, exx = 0, eyy = 0, exy = 0;
      for (int k = 0; k < kWindow; ++k) {
        ux += g[k] * mx[x0 + k];
        uy += g[k] * my[x0 + k];
        exx += g[k] * mxx[x0 + k];
        eyy += g[k] * myy[x0 + k];
        exy += g[k] * mxy[x0 + k];
      }
      const double vx = exx - ux * ux, vy = eyy - uy * uy, cxy = exy - ux * uy;
      total += ((2 * ux * uy + kC1) * (2 * cxy + kC2)) /
               ((ux * ux + uy * uy + kC1) * (vx + vy + kC2));
    }
  }
  const double windows = double(w - kWindow + 1) * double(h - kWindow + 1);
  return total / windows;
}

std::vector<std::uint8_t> foreground_mask(ImageRgb8View image, Rgb8 background) {
  assert(image.pixels.size() == std::size_t(image.width) * std::size_t(image.height));
  std::vector<std::uint8_t> mask(image.pixels.size());
  for (std::size_t i = 0; i < mask.size(); ++i) mask[i] = image.pixels[i] == background ? 0 : 1;
  return mask;
}

double mask_iou(std::span<const std::uint8_t> a, std::span<const std::uint8_t> b) {
  assert(a.size() == b.size());
  std::uint64_t both = 0, either = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    both += (a[i] && b[i]) ? 1 : 0;
    either += (a[i] || b[i]) ? 1 : 0;
  }
  return either == 0 ? 1.0 : double(both) / double(either);
}

HoleCount count_holes(int width, int height, std::span<const std::uint8_t> a,
                      std::span<const std::uint8_t> b) {
  assert(width >= 0 && height >= 0);
  assert(a.size() == std::size_t(width) * std::size_t(height) && b.size() == a.size());
  HoleCount out;
  const auto at = [&](int px, int py) { return a[std::size_t(py) * std::size_t(width) + px] != 0; };
  for (int py = 1; py + 1 < height; ++py) {
    for (int px = 1; px + 1 < width; ++px) {
      bool interior = true;
      for (int dy = -1; dy <= 1 && interior; ++dy) {
        for (int dx = -1; dx <= 1 && interior; ++dx) interior = at(px + dx, py + dy);
      }
      if (!interior) continue;
      ++out.interior_count;
      if (b[std::size_t(py) * std::size_t(width) + px] == 0) ++out.hole_count;
    }
  }
  return out;
}

ImageComparison compare_images(ImageRgb8View reference, ImageRgb8View test,
                               const ImageCompareOptions& options) {
  check_pair(reference, test);
  ImageComparison out;
  out.mse = mse_rgb(reference, test);
  out.psnr_db = out.mse == 0 ? std::numeric_limits<double>::infinity()
                             : 10.0 * std::log10(255.0 * 255.0 / out.mse);
  out.ssim = ssim_luma(reference, test);
  out.background = options.background.value_or(reference.pixels[0]);
  const std::vector<std::uint8_t> a = foreground_mask(reference, out.background);
  const std::vector<std::uint8_t> b = foreground_mask(test, out.background);
  for (std::size_t i = 0; i < a.size(); ++i) {
    out.reference_foreground_count += a[i];
    out.test_foreground_count += b[i];
  }
  out.silhouette_iou = mask_iou(a, b);
  const HoleCount holes = count_holes(reference.width, reference.height, a, b);
  out.interior_count = holes.interior_count;
  out.hole_count = holes.hole_count;
  return out;
}

}  // namespace pointillist
