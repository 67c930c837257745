// Label metrics of the sharp-features specification (specs/sharp-features.md §4.5) measured from
// two images: an exact reference that shows each pixel's face label as a palette colour (or the
// background), and a test render of the same view drawn UNLIT with the same palette, so that a
// test pixel shows one palette colour unless it blends surfaces.
//
// Labels. A reference pixel's label L*(p) is the palette entry within `tolerance` levels (every
// channel) of its colour, or background when it equals the background colour exactly; any other
// colour is an error. A test pixel's label L(p) is background when it equals the background
// colour, else the palette entry within `tolerance` levels, else MIXED (a blend of surfaces, or
// of a surface and the background). Faces that share a palette colour are one label.
//
// Pixel sets (all Chebyshev distances in pixels, 8-neighbourhoods; outside the image counts as
// background):
//   covered C*      reference pixels with a label;
//   interior I      covered pixels whose 8 neighbours are covered (count_holes' interior): the
//                   pixels "off the silhouette";
//   boundary ∂      covered pixels with a 4-neighbour of another covered label: both sides of a
//                   crease or intersection curve as it projects; silhouettes (label next to
//                   background) are not boundaries;
//   band B_k        covered pixels within k px of a boundary pixel (∂ ⊂ B_k).
//
// Metrics:
//   HOLE        interior pixels that are background in the test (count_holes on the two
//               foreground masks; a MIXED pixel is foreground).
//   OVERSHOOT   test pixels that are not background where the reference is background more than
//               1 px from every covered reference pixel (the 1 px allows the renderer's 0.75 px
//               screen low-pass); out of the reference background pixels that far away.
//   LER         pixels of B_4 (resp. of C*) whose L differs from L* (another label, MIXED or
//               background), over |B_4| (resp. |C*|).
//   WRONG       covered pixels whose L is another palette label (a pure wrong colour).
//   MIX         MIXED test pixels at interior pixels (over all of I, and inside B_8 ∩ I), and
//               the latter per boundary pixel (∂ counts both sides of a crease, so a crease of
//               length ℓ px seen straight has about 2ℓ boundary pixels). MIXED test pixels outside
//               I (on or beyond the reference silhouette) are counted apart.
//   EDGE DISPLACEMENT and TRANSITION WIDTH on profiles across the reference label boundaries:
//     - direction: at boundary pixel p of label a, the normal n is the normalised sum of the
//       offsets q − p to the pixels q of another covered label in the 7×7 window around p (it
//       points across the boundary);
//     - samples: the pixels nearest to p + t·n for t = −⌊L/2⌋, …, L − 1 − ⌊L/2⌋ (L samples
//       1 px apart, p itself among them; L = profile_length_px = 40);
//     - a profile is valid when every sample lies in the image and is covered in the reference,
//       and the reference labels along it are a…a b…b (two labels, one switch); this keeps
//       profiles away from corners, crease ends and silhouettes (the spec's "middle 60 %" of
//       each crease, which two images cannot delimit);
//     - up to max_profiles valid profiles are used, evenly spaced in raster order of the
//       valid boundary pixels;
//     - the reference switch s* lies halfway between the last a and the first b sample; the
//       test switch s is the split of the samples into "a before, b after" that disagrees with
//       the fewest test labels (MIXED and background disagree with both), the mean of all
//       splits that tie; a profile whose test samples show no a or no b is not measured
//       (counted as unmatched);
//     - EDGE DISPLACEMENT |Δ| = |s − s*| in px (mean and max over the measured profiles);
//     - TRANSITION WIDTH: the number of MIXED samples of the profile whose share w of a lies in
//       (0.1, 0.9), w the least-squares fit of the sample's colour c ≈ w·c_a + (1 − w)·c_b
//       clamped to [0, 1] (mean and max over the measured profiles).
//
//   PSNR(B_8)   the PSNR of the colours (R, G, B) over the covered pixels of B_8.
//   SEE-THROUGH (with depth images of both, LabelCompareOptions::reference_depth/test_depth):
//               interior pixels whose test label is neither L* nor background (another label,
//               or MIXED) and whose test depth lies behind the reference depth by more than
//               see_through_gap (the spec's 2 mean splat radii): the render shows a farther
//               surface there. The spec counts them into HOLE; they are reported apart.
//
//   NORMAL ERROR (with normal images of both, LabelCompareOptions::reference_normals/
//               test_normals, in the encoding of core/normal_color.hpp: `generate
//               --reference-normals`, `render --normal-colors`): the angle between the decoded
//               reference and test normals at the covered pixels of B_8 that the test covers
//               (holes are HOLE's), mean and share above kNormalErrorDegrees (5°); also over
//               all covered pixels. 8-bit encoding: each normal is within 0.4° of the true one.
//
// Left out: the weight of a second label (MIX's 2 % threshold) needs the renderer's debug
// output. The
// tolerance decides which blends show: one whose second colour carries weight w moves some
// channel by w·d levels, d the largest channel difference of the two colours, so it is MIXED
// when w·d > tolerance + 0.5.
#pragma once

#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "pointillist/core/math.hpp"
#include "pointillist/eval/image_compare.hpp"

namespace pointillist {

struct LabelCompareOptions {
  // The label colours, index = label. At most 250 entries, no two within 2·tolerance + 1 levels
  // of each other or of the background.
  std::span<const Rgb8> palette;
  // Background colour of both images; unset = the reference's top-left pixel.
  std::optional<Rgb8> background;
  // Largest per-channel difference (levels) at which a pixel still shows a palette colour.
  // 2 absorbs the rounding of a renderer's blend of one colour; raise it for noisier renders,
  // lower it to see fainter blends (see the top of this file).
  int tolerance = 2;
  int band_px = 4;       // k of B_k for LER (the spec's B_4)
  int mix_band_px = 8;   // k of B_k for MIX (the spec's B_8)
  int max_profiles = 64;         // profiles for edge displacement and transition width
  int profile_length_px = 40;    // samples per profile (one a pixel)
  // Names the reference in error messages (e.g. its path).
  std::string reference_name = "the reference";
  // SEE-THROUGH: depth along the view direction of every pixel of each image (row-major, +inf
  // or NaN for none), both given or neither, and the depth gap that counts (> 0, scene units).
  std::span<const float> reference_depth, test_depth;
  float see_through_gap = 0;
  // NORMAL ERROR: the normal images (normal colours, row-major), both given or neither.
  std::span<const Rgb8> reference_normals, test_normals;
};

// The spec's threshold of the NORMAL ERROR's share (§4.5).
constexpr double kNormalErrorDegrees = 5.0;

// Codes of label_image: palette indices are 0 … palette.size() − 1.
constexpr std::uint8_t kLabelBackground = 254;
constexpr std::uint8_t kLabelMixed = 255;

struct LabelComparison {
  Rgb8 background;
  std::uint64_t covered_count = 0;        // |C*|
  std::uint64_t interior_count = 0;       // |I|
  std::uint64_t boundary_count = 0;       // |∂|
  std::uint64_t hole_count = 0;           // HOLE (interior pixels background in the test)
  std::uint64_t far_background_count = 0; // reference background pixels > 1 px from C*
  std::uint64_t overshoot_count = 0;      // OVERSHOOT: of those, not background in the test
  std::uint64_t band_count = 0;           // |B_4|
  std::uint64_t band_error_count = 0;     // pixels of B_4 with L ≠ L*
  double ler_band = 0;                    // band_error_count / band_count (0 when empty)
  std::uint64_t covered_error_count = 0;  // pixels of C* with L ≠ L*
  double ler_covered = 0;                 // covered_error_count / covered_count
  std::uint64_t wrong_count = 0;          // pixels of C* showing another palette label
  std::uint64_t mixed_count = 0;          // MIX: MIXED test pixels at interior pixels
  std::uint64_t mix_band_count = 0;       // |B_8 ∩ I|
  std::uint64_t mixed_band_count = 0;     // MIXED test pixels in B_8 ∩ I
  double mixed_per_boundary_px = 0;       // mixed_band_count / boundary_count
  std::uint64_t mixed_outside_count = 0;  // MIXED test pixels outside I
  std::uint64_t profile_count = 0;        // measured profiles
  std::uint64_t unmatched_profile_count = 0;  // valid profiles whose test lacks a or b
  double displacement_mean_px = 0, displacement_max_px = 0;  // EDGE DISPLACEMENT |Δ|
  double transition_mean_px = 0, transition_max_px = 0;      // TRANSITION WIDTH
  // PSNR inside B_8 (the MSE of R, G, B over covered pixels within mix_band_px of a boundary;
  // +inf when equal there, NaN when there is no boundary).
  double psnr_band_db = std::numeric_limits<double>::quiet_NaN();
  bool depth_compared = false;            // depth images were given
  std::uint64_t see_through_count = 0;    // SEE-THROUGH (0 without depth)
  bool normals_compared = false;          // normal images were given
  // NORMAL ERROR in B_8 (covered by both) and over every pixel covered by both: pixels measured,
  // mean angle (degrees; 0 when none) and pixels above kNormalErrorDegrees.
  std::uint64_t normal_band_count = 0, normal_band_over = 0;
  double normal_band_mean_deg = 0;
  std::uint64_t normal_covered_count = 0, normal_covered_over = 0;
  double normal_covered_mean_deg = 0;
};

// The label of every pixel of `image` (row-major): a palette index, kLabelBackground or
// kLabelMixed, as the test image's labels are defined above. Throws Error when the palette is
// empty or has more than 250 colours.
std::vector<std::uint8_t> label_image(ImageRgb8View image, std::span<const Rgb8> palette,
                                      Rgb8 background, int tolerance);

// The reference's labels: as label_image, but a pixel that is neither background nor a palette
// colour is an Error naming the pixel (x, y), its colour and options.reference_name.
std::vector<std::uint8_t> reference_label_image(ImageRgb8View reference,
                                                const LabelCompareOptions& options,
                                                Rgb8 background);

// Every metric above for `test` against `reference` (same size). Throws Error when the sizes
// differ or are empty, the options are out of range (palette, tolerance, band widths, profile
// length), the palette colours are not told apart at this tolerance (naming the two entries),
// the reference holds a colour that is not background or a palette colour (naming the pixel), or
// the depth images are given alone, at another size, or without a positive gap, or the normal
// images alone or at another size.
LabelComparison compare_labels(ImageRgb8View reference, ImageRgb8View test,
                               const LabelCompareOptions& options);

}  // namespace pointillist
