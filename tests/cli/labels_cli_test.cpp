// End to end: `generate --scene T1 --reference` writes the exact label image, `render --unlit`
// draws the generated samples with the same camera, and `compare --labels` measures them.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli/cli_run.hpp"
#include "pointillist/core/normal_color.hpp"
#include "pointillist/io/pfm.hpp"
#include "pointillist/io/png.hpp"
#include "testing/testing.hpp"

using namespace pointillist;
using pointillist::testing::run_cli;
using ::testing::HasSubstr;

namespace {

// The face colours of generate's test scenes (kLabelPalette of src/cli/util.hpp).
constexpr Rgb8 kPalette[8] = {{230, 25, 75},  {60, 180, 75},  {0, 130, 200}, {255, 225, 25},
                              {245, 130, 48}, {145, 30, 180}, {70, 240, 240}, {240, 50, 230}};

nlohmann::json label_metrics(const std::string& reference, const std::string& test) {
  const auto r = run_cli("compare " + reference + " " + test + " --labels --json -");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  return nlohmann::json::parse(r.output)["labels"];
}

}  // namespace

TEST(LabelsCli, CubeWithFeaturesHasNoHolesOrBlendsAndWithoutBlends) {
  pointillist::testing::TempDir dir;
  const std::string ply = dir.file("cube.ply");
  // V1, the overview, by orbit; V2, 1.5 from the corner (1, 1, 1), by eye and target.
  const std::vector<std::string> cameras = {"--size 256x256 --view 35,25",
                                            "--size 256x256 --eye 2,2.1,1.9 --target 1,1,1"};
  for (std::size_t v = 0; v < cameras.size(); ++v) {
    SCOPED_TRACE(cameras[v]);
    const std::string ref = dir.file("ref" + std::to_string(v) + ".png");
    const std::string with = dir.file("with" + std::to_string(v) + ".png");
    const std::string without = dir.file("without" + std::to_string(v) + ".png");
    const auto g =
        run_cli("generate --scene T1 -o " + ply + " --reference " + ref + " " + cameras[v]);
    ASSERT_EQ(g.exit_code, 0) << g.output;
    EXPECT_THAT(g.output, HasSubstr("exact label reference"));
    // The reference holds only the background and palette colours; both views show three faces.
    const ImageRgb8 image = read_png_rgb8(ref);
    ASSERT_EQ(image.width, 256);
    std::vector<int> seen(8, 0);
    for (const Rgb8 p : image.pixels) {
      bool known = p == Rgb8{0, 0, 0};
      for (int k = 0; k < 8; ++k) {
        if (p == kPalette[k]) known = true, seen[k] = 1;
      }
      ASSERT_TRUE(known) << int(p.r) << "," << int(p.g) << "," << int(p.b);
    }
    EXPECT_EQ(seen[0] + seen[1] + seen[2] + seen[3] + seen[4] + seen[5], 3);

    const std::string render = "render " + ply + " --mode quality --unlit --quiet " + cameras[v];
    auto r = run_cli(render + " --features -o " + with);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    r = run_cli(render + " --no-features -o " + without);
    ASSERT_EQ(r.exit_code, 0) << r.output;

    const nlohmann::json a = label_metrics(ref, with);
    const nlohmann::json b = label_metrics(ref, without);
    std::cout << "with features: " << a.dump() << "\nwithout: " << b.dump() << "\n";
    EXPECT_GT(a["covered_pixels"].get<int>(), 5000);
    EXPECT_GT(a["profiles"].get<int>(), 10);
    EXPECT_EQ(a["hole_pixels"].get<int>(), 0);
    EXPECT_EQ(a["overshoot_pixels"].get<int>(), 0);
    // Spec bar A2 (label errors <= 0.2 %): also what a camera turned by 0.2 degrees would miss.
    EXPECT_LE(a["wrong_label_pixels"].get<int>(), a["covered_pixels"].get<int>() / 500);
    EXPECT_EQ(a["mixed_pixels"].get<int>(), 0);  // off the silhouette
    EXPECT_GT(b["mixed_pixels"].get<int>(), 0);
    EXPECT_GT(b["transition_width_mean_px"].get<double>(), 0.0);
    EXPECT_EQ(a["transition_width_max_px"].get<double>(), 0.0);
    // The camera is render's: the creases land within a pixel of the reference's.
    EXPECT_LT(a["edge_displacement_mean_px"].get<double>(), 1.0);
  }
}

TEST(LabelsCli, TextOutputNamesEveryLabelMetric) {
  pointillist::testing::TempDir dir;
  const std::string ply = dir.file("cube.ply"), ref = dir.file("ref.png");
  ASSERT_EQ(run_cli("generate --scene T1 -q -o " + ply + " --reference " + ref +
                    " --size 96x96 --view 35,25")
                .exit_code,
            0);
  const auto r = run_cli("compare " + ref + " " + ref + " --labels");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const char* line : {"PSNR:           inf dB", "labels:", "HOLE:         0 of",
                           "OVERSHOOT:    0 of", "LER:          0.000% in B_4",
                           "MIX:          0 interior pixels", "edge displacement: mean 0.00 px",
                           "transition width:  mean 0.00 px"}) {
    EXPECT_THAT(r.output, HasSubstr(line));
  }
}

TEST(LabelsCli, ReferenceWithForeignColourNamesFileAndPixel) {
  pointillist::testing::TempDir dir;
  const std::string ref = dir.file("ref.png");
  std::vector<Rgb8> pixels(32 * 32, Rgb8{0, 0, 0});
  pixels[5 * 32 + 7] = {100, 100, 100};
  write_png_rgb8(ref, 32, 32, pixels);
  const auto r = run_cli("compare " + ref + " " + ref + " --labels");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_THAT(r.output, HasSubstr(ref + ": pixel (7, 5) is 100,100,100"));
  EXPECT_THAT(r.output, HasSubstr("generate --reference"));
}

TEST(LabelsCli, ReferenceNeedsATestSceneAndAPng) {
  pointillist::testing::TempDir dir;
  auto r = run_cli("generate --scene sphere --points 100 -o " + dir.file("s.ply") +
                   " --reference " + dir.file("ref.png"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("--reference writes the exact label image"));
  EXPECT_THAT(r.output, HasSubstr("give --scene T1"));
  r = run_cli("generate --scene T1 -o " + dir.file("c.ply") + " --reference " +
              dir.file("ref.jpg"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("give a path ending in .png"));
  r = run_cli("generate --scene T1 -o " + dir.file("c.ply") + " --view 10,10");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("--view is ignored: it applies to the --reference image"));
}

TEST(LabelsCli, DepthImagesGiveTheSeeThroughCount) {
  // The reference's depth (exact ray cast) and the render's (--depth D.pfm, blended splat
  // depth) agree where the labels do; the cube with features shows no farther surface, and a
  // test depth pushed behind where the labels were swapped counts as see-through.
  pointillist::testing::TempDir dir;
  const std::string ply = dir.file("cube.ply"), ref = dir.file("ref.png"),
                    ref_depth = dir.file("ref.pfm"), img = dir.file("t.png"),
                    depth = dir.file("t.pfm");
  const std::string camera = " --size 128x128 --eye 2,2.1,1.9 --target 1,1,1";
  auto r = run_cli("generate --scene T1 -q -o " + ply + " --reference " + ref +
                   " --reference-depth " + ref_depth + camera);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = run_cli("render " + ply + " -q --mode quality --unlit --features -o " + img + " --depth " +
              depth + camera);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const ImageFloat rd = read_pfm(ref_depth), td = read_pfm(depth);
  ASSERT_EQ(rd.pixels.size(), 128u * 128u);
  ASSERT_EQ(td.pixels.size(), rd.pixels.size());
  std::size_t both = 0, close = 0;
  for (std::size_t i = 0; i < rd.pixels.size(); ++i) {
    if (!std::isfinite(rd.pixels[i]) || !std::isfinite(td.pixels[i])) continue;
    ++both;
    close += std::fabs(rd.pixels[i] - td.pixels[i]) < 0.01f;  // the cube's side is 2
  }
  EXPECT_GT(both, 5000u);
  EXPECT_GT(close, both * 99 / 100);
  const auto json = [&](const std::string& test, const std::string& test_depth) {
    const auto c = run_cli("compare " + ref + " " + test + " --labels --json - --depth " +
                           ref_depth + " " + test_depth + " --see-through-gap 0.05");
    EXPECT_EQ(c.exit_code, 0) << c.output;
    return nlohmann::json::parse(c.output)["labels"];
  };
  EXPECT_EQ(json(img, depth)["see_through_pixels"].get<int>(), 0);
  // The reference itself with a block of one face shown in another face's colour, 1 behind.
  ImageRgb8 swapped = read_png_rgb8(ref);
  std::vector<float> behind = rd.pixels;
  const Rgb8 face = swapped.pixels[45 * 128 + 45];
  Rgb8 other = face;
  for (const Rgb8 p : swapped.pixels) {
    if (!(p == face) && !(p == Rgb8{0, 0, 0})) other = p;
  }
  ASSERT_FALSE(other == face);
  int changed = 0;
  for (int y = 40; y < 50; ++y) {
    for (int x = 40; x < 50; ++x) {
      Rgb8& p = swapped.pixels[y * 128 + x];
      if (!(p == face)) continue;
      p = other;
      behind[y * 128 + x] += 1.0f;
      ++changed;
    }
  }
  ASSERT_GT(changed, 10);
  write_png_rgb8(dir.file("s.png"), 128, 128, swapped.pixels);
  write_pfm(dir.file("s.pfm"), 128, 128, behind);
  EXPECT_EQ(json(dir.file("s.png"), dir.file("s.pfm"))["see_through_pixels"].get<int>(), changed);
  // Without depth images the field is null; half the options are refused.
  EXPECT_TRUE(label_metrics(ref, img)["see_through_pixels"].is_null());
  r = run_cli("compare " + ref + " " + img + " --labels --depth " + ref_depth + " " + depth);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("--see-through-gap"));
  r = run_cli("generate --scene T1 -q -o " + ply + " --reference-depth " + ref_depth);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("give --reference R.png too"));
  r = run_cli("render " + ply + " -q -o " + img + " --depth " + dir.file("d.tif"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr(".png or .pfm"));
}

TEST(LabelsCli, NormalImagesGiveTheNormalError) {
  // The reference's normals are the ray cast's exact face normals. Seen at the cube's corner, the
  // faces' discs with features carry their face's exact normal up to the crease (no error in
  // B_8), in both modes; without features discs of one face reach over the crease and show
  // their normal there (90° off), and the quality mode blends the faces' normals.
  pointillist::testing::TempDir dir;
  const std::string ply = dir.file("cube.ply"), ref = dir.file("ref.png"),
                    ref_normals = dir.file("ref_n.png"), img = dir.file("t.png"),
                    normals = dir.file("t_n.png");
  const std::string camera = " --size 128x128 --eye 2,2.1,1.9 --target 1,1,1";
  auto r = run_cli("generate --scene T1 --sampling r -q -o " + ply + " --reference " + ref +
                   " --reference-normals " + ref_normals + camera);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // The reference shows three faces, so three normal colours, and their decoded normals are
  // the cube's: orthogonal to each other (within the encoding's 0.4° each).
  const ImageRgb8 exact = read_png_rgb8(ref_normals);
  const ImageRgb8 labels = read_png_rgb8(ref);
  ASSERT_EQ(exact.pixels.size(), labels.pixels.size());
  std::size_t covered = 0;
  std::vector<Rgb8> colours;
  for (std::size_t i = 0; i < exact.pixels.size(); ++i) {
    if (labels.pixels[i] == Rgb8{0, 0, 0}) continue;
    ++covered;
    if (std::find(colours.begin(), colours.end(), exact.pixels[i]) == colours.end()) {
      colours.push_back(exact.pixels[i]);
    }
  }
  ASSERT_EQ(colours.size(), 3u);
  for (int a = 0; a < 3; ++a) {
    const Vec3f u = decode_normal_color(colours[a]), v = decode_normal_color(colours[(a + 1) % 3]);
    EXPECT_NEAR(dot(u, v), 0.0f, 0.014f);  // sin(0.8°)
    EXPECT_GT(u.z, 0.0f);                  // facing the eye
  }
  ASSERT_GT(covered, 5000u);
  const auto metrics = [&](const std::string& mode, const std::string& features) {
    auto rr = run_cli("render " + ply + " -q --mode " + mode + " --unlit " + features + " -o " +
                      img + camera);
    EXPECT_EQ(rr.exit_code, 0) << rr.output;
    rr = run_cli("render " + ply + " -q --mode " + mode + " --normal-colors " + features +
                 " -o " + normals + camera);
    EXPECT_EQ(rr.exit_code, 0) << rr.output;
    rr = run_cli("compare " + ref + " " + img + " --labels --json - --normals " + ref_normals +
                 " " + normals);
    EXPECT_EQ(rr.exit_code, 0) << rr.output;
    return nlohmann::json::parse(rr.output)["labels"]["normal_error"];
  };
  for (const std::string mode : {"fast", "quality"}) {
    const auto with = metrics(mode, "--features");
    EXPECT_GT(with["band_pixels"].get<int>(), 1000) << mode;
    EXPECT_LT(with["band_mean_deg"].get<double>(), 0.5) << mode;
    EXPECT_LT(with["band_over_5deg"].get<double>(), 0.002) << mode;
    const auto without = metrics(mode, "--no-features");
    EXPECT_GT(without["band_mean_deg"].get<double>(), 5.0) << mode;
    EXPECT_GT(without["band_over_5deg"].get<double>(), 0.1) << mode;
  }
  // Both normal images are needed, of the label images' size, and only with --labels.
  EXPECT_TRUE(label_metrics(ref, img)["normal_error"].is_null());
  r = run_cli("compare " + ref + " " + img + " --normals " + ref_normals + " " + normals);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("--normals applies with --labels"));
  r = run_cli("render " + ply + " -q --normal-colors -o " + dir.file("small.png") +
              " --size 64x64");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = run_cli("compare " + ref + " " + img + " --labels --normals " + ref_normals + " " +
              dir.file("small.png"));
  EXPECT_NE(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("64x64 but the label images are 128x128"));
  r = run_cli("generate --scene T1 -q -o " + ply + " --reference-normals " + ref_normals);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("give --reference R.png too"));
  r = run_cli("generate --scene T1 -q -o " + ply + " --reference " + ref +
              " --reference-normals " + dir.file("n.pfm"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("ending in .png"));
  r = run_cli("render " + ply + " -q --normal-colors --edl -o " + img);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("leave out --edl"));
}

TEST(LabelsCli, SmoothSphereNormalsMatchTheExactOnes) {
  // T13, the smooth control: the quality mode's blended normals follow the exact sphere within
  // a fraction of a degree everywhere (exact sample normals, jittered samples); the fast mode's
  // flat discs each show their centre's normal, off by up to the angle a disc subtends.
  pointillist::testing::TempDir dir;
  const std::string ply = dir.file("s.ply"), ref = dir.file("ref.png"),
                    ref_normals = dir.file("ref_n.png"), img = dir.file("t.png"),
                    normals = dir.file("t_n.png");
  const std::string camera = " --size 128x128 --view 30,20";
  auto r = run_cli("generate --scene T13 -q -o " + ply + " --reference " + ref +
                   " --reference-normals " + ref_normals + camera);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::vector<double> mean;
  for (const std::string mode : {"quality", "fast"}) {
    r = run_cli("render " + ply + " -q --unlit --mode " + mode + " -o " + img + camera);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    r = run_cli("render " + ply + " -q --normal-colors --mode " + mode + " -o " + normals + camera);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    r = run_cli("compare " + ref + " " + img + " --labels --json - --normals " + ref_normals +
                " " + normals);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const auto n = nlohmann::json::parse(r.output)["labels"]["normal_error"];
    EXPECT_GT(n["covered_pixels"].get<int>(), 8000) << mode;
    mean.push_back(n["covered_mean_deg"].get<double>());
  }
  EXPECT_LT(mean[0], 0.6);
  EXPECT_GT(mean[1], 2 * mean[0]);
  EXPECT_LT(mean[1], 5.0);
}
