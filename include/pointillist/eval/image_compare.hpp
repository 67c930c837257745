// Image-quality yardstick: how close a rendered image is to a reference image of the same view.
// PSNR over RGB, SSIM on luma, and silhouette metrics (IoU of the foreground masks, hole pixels).
//
// SSIM follows Wang, Bovik, Sheikh, Simoncelli, "Image quality assessment: from error
// visibility to structural similarity", IEEE TIP 13(4), 2004, with the paper's choices:
// luma Y = 0.299 R + 0.587 G + 0.114 B (Rec. 601, 0..255), an 11×11 Gaussian window with
// σ = 1.5 px (weights normalised to sum 1), C1 = (0.01·255)², C2 = (0.03·255)², and the mean of
// the SSIM map over every window position that lies fully inside the image ("valid" windows, no
// padding, no downsampling).
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "pointillist/core/math.hpp"

namespace pointillist {

// A borrowed 8-bit RGB image, rows top to bottom. Precondition everywhere it is passed:
// pixels.size() == width * height.
struct ImageRgb8View {
  int width = 0, height = 0;
  std::span<const Rgb8> pixels;
};

struct ImageCompareOptions {
  // The color that marks background pixels in both images (a pixel is background when it is
  // exactly this color). Unset: the reference image's top-left pixel, which is right for renders
  // on a plain background whose corner is empty; set it when the corner is covered.
  std::optional<Rgb8> background;
};

struct ImageComparison {
  double mse = 0;             // mean squared error over all R, G, B samples, in levels²
  double psnr_db = 0;         // 10·log10(255² / mse); +infinity when the images are identical
  double ssim = 0;            // mean SSIM (see the top of this file); 1 for identical images
  Rgb8 background;            // the background color used for the masks
  std::uint64_t reference_foreground_count = 0;  // pixels of the reference that are not background
  std::uint64_t test_foreground_count = 0;       // pixels of the test image that are not background
  double silhouette_iou = 0;  // |A ∩ B| / |A ∪ B| of the foreground masks; 1 when both are empty
  std::uint64_t interior_count = 0;  // reference foreground pixels with 8 foreground neighbours
  std::uint64_t hole_count = 0;      // interior reference pixels that are background in the test
};

// Mean squared error over all R, G, B samples (levels², 0..65025). Throws Error when the sizes
// differ or an image is empty.
double mse_rgb(ImageRgb8View reference, ImageRgb8View test);

// PSNR in dB over all R, G, B samples with peak 255: 10·log10(255² / MSE), +infinity for
// identical images. Throws Error when the sizes differ or an image is empty.
double psnr_rgb(ImageRgb8View reference, ImageRgb8View test);

// Mean SSIM of the luma of the two images (window and constants at the top of this file); in
// [-1, 1], 1 for identical images. Throws Error when the sizes differ or either side is shorter
// than the 11-pixel window.
double ssim_luma(ImageRgb8View reference, ImageRgb8View test);

// Foreground mask: 1 where the pixel differs from `background`, 0 where it equals it.
std::vector<std::uint8_t> foreground_mask(ImageRgb8View image, Rgb8 background);

// |A ∩ B| / |A ∪ B| of two masks of equal size (nonzero = foreground); 1 when both are empty.
// Asserts the sizes are equal.
double mask_iou(std::span<const std::uint8_t> a, std::span<const std::uint8_t> b);

struct HoleCount {
  std::uint64_t interior_count = 0;  // pixels of A whose 8 neighbours are all foreground in A
  std::uint64_t hole_count = 0;      // of those, the ones that are background in B
};

// Holes: pixels that are foreground in the reference mask A and whose 8 neighbours are all
// foreground in A (so pixels on the image border never count: outside the image is background),
// but that are background in B. Misses along the silhouette's edge are not holes. Masks are
// width × height, nonzero = foreground; asserts their sizes.
HoleCount count_holes(int width, int height, std::span<const std::uint8_t> a,
                      std::span<const std::uint8_t> b);

// Every metric above for a test image against a reference of the same size. Throws Error when
// the sizes differ, an image is empty, or it is smaller than 11×11 (the SSIM window).
ImageComparison compare_images(ImageRgb8View reference, ImageRgb8View test,
                               const ImageCompareOptions& options = {});

}  // namespace pointillist
