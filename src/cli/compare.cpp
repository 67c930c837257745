// `pointillist compare REFERENCE.png TEST.png`: image-quality metrics of a render against a
// reference render of the same view.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <string>

#include "commands.hpp"
#include "options.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/io/png.hpp"
#include "pointillist/eval/image_compare.hpp"

namespace pointillist::cli {
namespace {

std::string comparison_to_json(const ImageComparison& c, int width, int height) {
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
                "  \"test_foreground_pixels\": %llu\n"
                "}\n",
                width, height, c.background.r, c.background.g, c.background.b, c.mse, psnr, c.ssim,
                static_cast<unsigned long long>(c.hole_count),
                static_cast<unsigned long long>(c.interior_count), c.silhouette_iou,
                static_cast<unsigned long long>(c.reference_foreground_count),
                static_cast<unsigned long long>(c.test_foreground_count));
  return buf;
}

void print_text(const CompareOptions& o, const ImageComparison& c, int width, int height) {
  std::printf("reference:      %s\n", o.reference.c_str());
  std::printf("test:           %s\n", o.test.c_str());
  std::printf("size:           %dx%d\n", width, height);
  std::printf("background:     %d,%d,%d (%s)\n", c.background.r, c.background.g, c.background.b,
              o.background ? "--background" : "top-left pixel of the reference");
  if (std::isinf(c.psnr_db)) {
    std::printf("PSNR:           inf dB (identical images)\n");
  } else {
    std::printf("PSNR:           %.2f dB (MSE %.3f)\n", c.psnr_db, c.mse);
  }
  std::printf("SSIM:           %.5f\n", c.ssim);
  const double hole_percent =
      c.interior_count > 0 ? 100.0 * double(c.hole_count) / double(c.interior_count) : 0.0;
  std::printf("hole pixels:    %llu of %llu interior reference pixels (%.3f%%)\n",
              static_cast<unsigned long long>(c.hole_count),
              static_cast<unsigned long long>(c.interior_count), hole_percent);
  std::printf("silhouette IoU: %.5f (foreground: reference %llu px, test %llu px)\n",
              c.silhouette_iou, static_cast<unsigned long long>(c.reference_foreground_count),
              static_cast<unsigned long long>(c.test_foreground_count));
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
  const ImageComparison c =
      compare_images({reference.width, reference.height, reference.pixels},
                     {test.width, test.height, test.pixels}, {.background = o.background});

  if (!o.json_output.empty()) {
    const std::string json = comparison_to_json(c, reference.width, reference.height);
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
  return 0;
}

Command add_compare_command(CLI::App& app) {
  auto o = std::make_shared<CompareOptions>();
  auto background = std::make_shared<std::string>();
  auto* cmd = app.add_subcommand(
      "compare", "Compare a render with a reference image of the same size: PSNR, SSIM, hole "
                 "pixels, silhouette IoU");
  cmd->add_option("reference", o->reference, "Reference PNG")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("test", o->test, "PNG to measure against the reference")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--background", *background,
                  "Background color R,G,B (0-255) for the silhouette masks (default: the "
                  "reference's top-left pixel)");
  cmd->add_option("--json", o->json_output,
                  "Also write the metrics as JSON to FILE (- = stdout, instead of text)");
  return {cmd, [o, background] {
            if (!background->empty()) o->background = parse_rgb8(*background, "--background");
            return run_compare(*o);
          }};
}

}  // namespace pointillist::cli
