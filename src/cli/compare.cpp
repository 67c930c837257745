// `pointillist compare REFERENCE.png TEST.png`: image-quality metrics of a render against a
// reference render of the same view; with --labels also the label metrics of the sharp-features
// spec against an exact label reference (generate --reference).
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "commands.hpp"
#include "options.hpp"
#include "util.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/io/pfm.hpp"
#include "pointillist/io/png.hpp"
#include "pointillist/eval/image_compare.hpp"
#include "pointillist/eval/label_metrics.hpp"

namespace pointillist::cli {
namespace {

using ull = unsigned long long;

double percent(std::uint64_t a, std::uint64_t b) {
  return b > 0 ? 100.0 * double(a) / double(b) : 0.0;
}

std::string labels_to_json(const LabelComparison& l, int tolerance) {
  std::string normals = "null";
  if (l.normals_compared) {
    char n[512];
    std::snprintf(n, sizeof n,
                  "{\"band_pixels\": %llu, \"band_mean_deg\": %.4f, \"band_over_5deg\": %.6f, "
                  "\"covered_pixels\": %llu, \"covered_mean_deg\": %.4f, "
                  "\"covered_over_5deg\": %.6f}",
                  ull(l.normal_band_count), l.normal_band_mean_deg,
                  percent(l.normal_band_over, l.normal_band_count) / 100.0,
                  ull(l.normal_covered_count), l.normal_covered_mean_deg,
                  percent(l.normal_covered_over, l.normal_covered_count) / 100.0);
    normals = n;
  }
  char buf[2560];
  std::snprintf(buf, sizeof buf,
                ",\n"
                "  \"labels\": {\n"
                "    \"tolerance\": %d,\n"
                "    \"covered_pixels\": %llu,\n"
                "    \"interior_pixels\": %llu,\n"
                "    \"boundary_pixels\": %llu,\n"
                "    \"hole_pixels\": %llu,\n"
                "    \"far_background_pixels\": %llu,\n"
                "    \"overshoot_pixels\": %llu,\n"
                "    \"band_pixels\": %llu,\n"
                "    \"band_error_pixels\": %llu,\n"
                "    \"ler_band\": %.6f,\n"
                "    \"covered_error_pixels\": %llu,\n"
                "    \"ler_covered\": %.6f,\n"
                "    \"wrong_label_pixels\": %llu,\n"
                "    \"mixed_pixels\": %llu,\n"
                "    \"mix_band_pixels\": %llu,\n"
                "    \"mixed_band_pixels\": %llu,\n"
                "    \"mixed_per_boundary_pixel\": %.6f,\n"
                "    \"mixed_outside_pixels\": %llu,\n"
                "    \"profiles\": %llu,\n"
                "    \"unmatched_profiles\": %llu,\n"
                "    \"edge_displacement_mean_px\": %.6f,\n"
                "    \"edge_displacement_max_px\": %.6f,\n"
                "    \"transition_width_mean_px\": %.6f,\n"
                "    \"transition_width_max_px\": %.6f,\n"
                "    \"see_through_pixels\": %s,\n"
                "    \"psnr_band_db\": %s,\n"
                "    \"normal_error\": %s\n"
                "  }",
                tolerance, ull(l.covered_count), ull(l.interior_count), ull(l.boundary_count),
                ull(l.hole_count), ull(l.far_background_count), ull(l.overshoot_count),
                ull(l.band_count), ull(l.band_error_count), l.ler_band,
                ull(l.covered_error_count), l.ler_covered, ull(l.wrong_count),
                ull(l.mixed_count), ull(l.mix_band_count), ull(l.mixed_band_count),
                l.mixed_per_boundary_px, ull(l.mixed_outside_count), ull(l.profile_count),
                ull(l.unmatched_profile_count), l.displacement_mean_px, l.displacement_max_px,
                l.transition_mean_px, l.transition_max_px,
                l.depth_compared ? std::to_string(l.see_through_count).c_str() : "null",
                std::isfinite(l.psnr_band_db) ? std::to_string(l.psnr_band_db).c_str() : "null",
                normals.c_str());
  return buf;
}

std::string comparison_to_json(const ImageComparison& c, int width, int height,
                               const std::string& labels) {
  char psnr[64];
  if (std::isinf(c.psnr_db)) {
    std::snprintf(psnr, sizeof psnr, "null");  // JSON has no infinity: identical images
  } else {
    std::snprintf(psnr, sizeof psnr, "%.6f", c.psnr_db);
  }
  char buf[1024];
  std::snprintf(buf, sizeof buf,
                "{\n"
                "  \"width\": %d,\n"
                "  \"height\": %d,\n"
                "  \"background\": [%d, %d, %d],\n"
                "  \"mse\": %.6f,\n"
                "  \"psnr_db\": %s,\n"
                "  \"ssim\": %.6f,\n"
                "  \"hole_pixels\": %llu,\n"
                "  \"interior_pixels\": %llu,\n"
                "  \"silhouette_iou\": %.6f,\n"
                "  \"reference_foreground_pixels\": %llu,\n"
                "  \"test_foreground_pixels\": %llu",
                width, height, c.background.r, c.background.g, c.background.b, c.mse, psnr, c.ssim,
                ull(c.hole_count), ull(c.interior_count), c.silhouette_iou,
                ull(c.reference_foreground_count), ull(c.test_foreground_count));
  return buf + labels + "\n}\n";
}


void print_labels(const LabelComparison& l, int tolerance) {
  std::printf("labels:         palette of generate --scene T*, tolerance %d levels; reference "
              "%llu covered px, %llu interior, %llu on label boundaries\n",
              tolerance, ull(l.covered_count), ull(l.interior_count), ull(l.boundary_count));
  std::printf("  HOLE:         %llu of %llu interior pixels\n", ull(l.hole_count),
              ull(l.interior_count));
  if (l.depth_compared) {
    std::printf("  SEE-THROUGH:  %llu interior pixels show another surface behind the "
                "reference's (by more than the gap)\n",
                ull(l.see_through_count));
  }
  std::printf("  OVERSHOOT:    %llu of %llu background pixels more than 1 px from the reference\n",
              ull(l.overshoot_count), ull(l.far_background_count));
  std::printf("  LER:          %.3f%% in B_4 (%llu of %llu), %.3f%% of covered (%llu of %llu); "
              "%llu show another label\n",
              100.0 * l.ler_band, ull(l.band_error_count), ull(l.band_count),
              100.0 * l.ler_covered, ull(l.covered_error_count), ull(l.covered_count),
              ull(l.wrong_count));
  std::printf("  MIX:          %llu interior pixels (%.3f%%); %llu in B_8 (of %llu, %.4f per "
              "boundary pixel); %llu more on or beyond the silhouette\n",
              ull(l.mixed_count), percent(l.mixed_count, l.interior_count),
              ull(l.mixed_band_count), ull(l.mix_band_count), l.mixed_per_boundary_px,
              ull(l.mixed_outside_count));
  std::printf("  edge displacement: mean %.2f px, max %.2f px over %llu profiles (%llu without "
              "both labels in the test)\n",
              l.displacement_mean_px, l.displacement_max_px, ull(l.profile_count),
              ull(l.unmatched_profile_count));
  std::printf("  transition width:  mean %.2f px, max %.0f px\n", l.transition_mean_px,
              l.transition_max_px);
  if (std::isnan(l.psnr_band_db)) {
    std::printf("  PSNR in B_8:  - (no label boundary)\n");
  } else if (std::isinf(l.psnr_band_db)) {
    std::printf("  PSNR in B_8:  inf dB (identical there)\n");
  } else {
    std::printf("  PSNR in B_8:  %.2f dB\n", l.psnr_band_db);
  }
  if (l.normals_compared) {
    std::printf("  NORMAL ERROR: mean %.2f deg in B_8, %.3f%% over 5 deg (%llu px); all covered: "
                "mean %.2f deg, %.3f%% over 5 deg (%llu px)\n",
                l.normal_band_mean_deg, percent(l.normal_band_over, l.normal_band_count),
                ull(l.normal_band_count), l.normal_covered_mean_deg,
                percent(l.normal_covered_over, l.normal_covered_count),
                ull(l.normal_covered_count));
  }
}

void print_text(const CompareOptions& o, const ImageComparison& c, int width, int height) {
  std::printf("reference:      %s\n", o.reference.c_str());
  std::printf("test:           %s\n", o.test.c_str());
  std::printf("size:           %dx%d\n", width, height);
  std::printf("background:     %d,%d,%d (%s)\n", c.background.r, c.background.g, c.background.b,
              o.background ? "--background"
              : o.labels   ? "--labels: the default of generate --reference and render"
                           : "top-left pixel of the reference");
  if (std::isinf(c.psnr_db)) {
    std::printf("PSNR:           inf dB (identical images)\n");
  } else {
    std::printf("PSNR:           %.2f dB (MSE %.3f)\n", c.psnr_db, c.mse);
  }
  std::printf("SSIM:           %.5f\n", c.ssim);
  std::printf("hole pixels:    %llu of %llu interior reference pixels (%.3f%%)\n",
              ull(c.hole_count), ull(c.interior_count), percent(c.hole_count, c.interior_count));
  std::printf("silhouette IoU: %.5f (foreground: reference %llu px, test %llu px)\n",
              c.silhouette_iou, ull(c.reference_foreground_count), ull(c.test_foreground_count));
}

}  // namespace

int run_compare(const CompareOptions& o) {
  const ImageRgb8 reference = read_png_rgb8(o.reference);
  const ImageRgb8 test = read_png_rgb8(o.test);
  if (reference.width != test.width || reference.height != test.height) {
    throw Error(o.test + " is " + std::to_string(test.width) + "x" + std::to_string(test.height) +
                " but the reference " + o.reference + " is " + std::to_string(reference.width) +
                "x" + std::to_string(reference.height) +
                "; render the test image at the reference's size (--size " +
                std::to_string(reference.width) + "x" + std::to_string(reference.height) + ")");
  }
  const ImageRgb8View ref_view{reference.width, reference.height, reference.pixels};
  const ImageRgb8View test_view{test.width, test.height, test.pixels};
  // A close-up label reference covers its corner, so --labels takes the background the label
  // images are drawn on by default rather than the top-left pixel.
  const std::optional<Rgb8> background =
      o.background || !o.labels ? o.background : std::optional<Rgb8>(Rgb8{0, 0, 0});
  const ImageComparison c = compare_images(ref_view, test_view, {.background = background});
  std::optional<LabelComparison> labels;
  if (o.labels) {
    ImageFloat ref_depth, test_depth;
    if (!o.depth_images.empty()) {
      // The colour images' size, checked before the depth images' bodies are read.
      ref_depth = read_pfm(o.depth_images[0], reference.width, reference.height);
      test_depth = read_pfm(o.depth_images[1], reference.width, reference.height);
    }
    ImageRgb8 ref_normals, test_normals;
    if (!o.normal_images.empty()) {
      ref_normals = read_png_rgb8(o.normal_images[0]);
      test_normals = read_png_rgb8(o.normal_images[1]);
      for (const auto& [path, image] : {std::pair{o.normal_images[0], &ref_normals},
                                        std::pair{o.normal_images[1], &test_normals}}) {
        if (image->width != reference.width || image->height != reference.height) {
          throw Error(path + " is " + std::to_string(image->width) + "x" +
                      std::to_string(image->height) + " but the label images are " +
                      std::to_string(reference.width) + "x" + std::to_string(reference.height) +
                      "; render the normal image with the same camera options");
        }
      }
    }
    labels = compare_labels(ref_view, test_view,
                            {.palette = kLabelPalette,
                             .background = background,
                             .tolerance = o.label_tolerance,
                             .reference_name = o.reference,
                             .reference_depth = ref_depth.pixels,
                             .test_depth = test_depth.pixels,
                             .see_through_gap = o.see_through_gap,
                             .reference_normals = ref_normals.pixels,
                             .test_normals = test_normals.pixels});
  }

  if (!o.json_output.empty()) {
    const std::string json =
        comparison_to_json(c, reference.width, reference.height,
                           labels ? labels_to_json(*labels, o.label_tolerance) : std::string());
    if (o.json_output == "-") {
      std::fputs(json.c_str(), stdout);
      return 0;
    }
    std::ofstream out(o.json_output, std::ios::binary | std::ios::trunc);
    if (!out || !(out << json) || !out.flush()) {
      throw IoError(o.json_output +
                    ": cannot write the comparison JSON; check that the folder exists and is "
                    "writable");
    }
  }
  print_text(o, c, reference.width, reference.height);
  if (labels) print_labels(*labels, o.label_tolerance);
  return 0;
}

Command add_compare_command(CLI::App& app) {
  auto o = std::make_shared<CompareOptions>();
  auto background = std::make_shared<std::string>();
  auto* cmd = app.add_subcommand(
      "compare", "Compare a render with a reference image of the same size: PSNR, SSIM, hole "
                 "pixels, silhouette IoU; --labels: face-label metrics");
  cmd->add_option("reference", o->reference, "Reference PNG")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("test", o->test, "PNG to measure against the reference")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--background", *background,
                  "Background color R,G,B (0-255) for the silhouette masks (default: the "
                  "reference's top-left pixel; with --labels 0,0,0)");
  cmd->add_option("--json", o->json_output,
                  "Also write the metrics as JSON to FILE (- = stdout, instead of text)");
  cmd->add_flag("--labels", o->labels,
                "Also the label metrics (hole, overshoot, label error rate, mixed pixels, edge "
                "displacement, transition width) of an unlit render of a test scene against "
                "its exact label image (generate --scene T* --reference)");
  cmd->add_option("--label-tolerance", o->label_tolerance,
                  "With --labels: a pixel within this many levels (each channel) of a face "
                  "colour shows that face; farther, it blends faces")
      ->default_val(2)
      ->check(CLI::Range(0, 64));
  cmd->add_option("--depth", o->depth_images,
                  "With --labels: the depth images of the reference and the test (PFM: "
                  "generate --reference-depth, render --depth D.pfm) for the SEE-THROUGH count")
      ->expected(2)
      ->check(CLI::ExistingFile);
  cmd->add_option("--normals", o->normal_images,
                  "With --labels: the normal images of the reference and the test (PNG: "
                  "generate --reference-normals, render --normal-colors) for the NORMAL ERROR")
      ->expected(2)
      ->check(CLI::ExistingFile);
  cmd->add_option("--see-through-gap", o->see_through_gap,
                  "With --depth: how far (scene units) behind the reference a test pixel of "
                  "another surface must lie to count as see-through (the spec: 2 mean splat "
                  "radii; info prints the radii)");
  return {cmd, [o, background, cmd] {
            if (!o->depth_images.empty() && !o->labels) {
              throw OptionError("--depth applies with --labels (the SEE-THROUGH count)");
            }
            if (!o->normal_images.empty() && !o->labels) {
              throw OptionError("--normals applies with --labels (the NORMAL ERROR in the "
                                "label band)");
            }
            if (!o->depth_images.empty() && !(o->see_through_gap > 0)) {
              throw OptionError("--depth needs --see-through-gap G, a depth in scene units > 0 "
                                "(the spec takes 2 mean splat radii)");
            }
            if (o->depth_images.empty() && cmd->count("--see-through-gap") > 0) {
              throw OptionError("--see-through-gap applies with --depth REF.pfm TEST.pfm");
            }
            if (!background->empty()) o->background = parse_rgb8(*background, "--background");
            if (!o->labels && cmd->count("--label-tolerance") > 0) {
              std::fprintf(stderr, "pointillist compare: warning: --label-tolerance is ignored: "
                                   "it applies with --labels\n");
            }
            return run_compare(*o);
          }};
}

}  // namespace pointillist::cli
