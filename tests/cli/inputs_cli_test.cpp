// End-to-end tests of the inputs and model formats added to the command line: QSplat .qs files
// (rendered, described, written byte for byte as qsplat_make does), XYZ/LAS/OBJ inputs merged
// by `convert`, the model's up axis, and the quality mode.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "cli/cli_run.hpp"
#include "io/las_builder.hpp"
#include "pointillist/io/png.hpp"
#include "testing/testing.hpp"

using namespace pointillist;
using pointillist::testing::CliResult;
using pointillist::testing::run_cli;
using pointillist::testing::TempDir;
using pointillist::testing::write_text_file;
using ::testing::HasSubstr;
namespace fs = std::filesystem;

namespace {

std::string qsplat_sample(const std::string& name) {
  return (pointillist::testing::shared_testdata_dir() / "qsplat" / name).string();
}

std::string file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Pixels that differ from the background (black).
std::size_t drawn_pixels(const ImageRgb8& img) {
  std::size_t n = 0;
  for (const Rgb8& p : img.pixels) n += (p.r | p.g | p.b) != 0;
  return n;
}

// Values after "label" in `info` output: "bounds:      min (a, b, c)  max (d, e, f)".
std::vector<double> info_bounds(const std::string& info) {
  const auto at = info.find("bounds:");
  std::vector<double> v(6, NAN);
  if (at == std::string::npos) return v;
  std::sscanf(info.c_str() + at, "bounds: min (%lf, %lf, %lf) max (%lf, %lf, %lf)", &v[0], &v[1],
              &v[2], &v[3], &v[4], &v[5]);
  return v;
}

}  // namespace

TEST(QsCli, InfoAndRenderOpenTheFilesQsplatMakeWrote) {
  POINTILLIST_REQUIRE_SHARED_TESTDATA();
  TempDir dir;
  const CliResult info = run_cli("info " + qsplat_sample("dragon_vrip_res4_color.strict.qs"));
  ASSERT_EQ(info.exit_code, 0) << info.output;
  // Leaf count and structure from the sample folder's README (made by QSplat 1.0's tool).
  EXPECT_THAT(info.output, HasSubstr("QSplat model (.qs 1.1)"));
  EXPECT_THAT(info.output, HasSubstr("points:      5203 (leaves)"));
  EXPECT_THAT(info.output, HasSubstr("nodes:       7753"));  // 7752 records + the root
  EXPECT_THAT(info.output, HasSubstr("depth:       9 levels"));
  EXPECT_THAT(info.output, HasSubstr("color"));

  const std::string png = dir.file("qs.png");
  const CliResult ren = run_cli("render " + qsplat_sample("dragon_vrip_res4_color.strict.qs") +
                                " -o " + png + " --size 320x240 --view 20,10");
  ASSERT_EQ(ren.exit_code, 0) << ren.output;
  const ImageRgb8 img = read_png_rgb8(png);
  EXPECT_GT(drawn_pixels(img), 320u * 240u / 10) << "the dragon should fill part of the frame";
  // The synthetic colours run red with x, green with y, blue with z: the picture is not grey.
  std::size_t coloured = 0;
  for (const Rgb8& p : img.pixels) coloured += std::abs(int(p.r) - int(p.b)) > 40;
  EXPECT_GT(coloured, 500u);
}

TEST(QsCli, ConvertToQsWritesTheBytesQsplatMakeWrote) {
  POINTILLIST_REQUIRE_SHARED_TESTDATA();
  TempDir dir;
  for (const std::string base : {"dragon_vrip_res4", "dragon_vrip_res4_color"}) {
    const std::string out = dir.file(base + ".qs");
    const CliResult conv = run_cli("convert " + qsplat_sample(base + ".bbe.ply") + " -o " + out);
    ASSERT_EQ(conv.exit_code, 0) << conv.output;
    EXPECT_EQ(file_bytes(out), file_bytes(qsplat_sample(base + ".strict.qs"))) << base;
  }
}

TEST(QsCli, SplatOptionsAreIgnoredWithAWarningForAMeshWrittenAsQs) {
  POINTILLIST_REQUIRE_SHARED_TESTDATA();
  TempDir dir;
  const std::string out = dir.file("scaled.qs");
  const CliResult conv = run_cli("convert -q " + qsplat_sample("dragon_vrip_res4.bbe.ply") +
                                 " -o " + out + " --radius-scale 2");
  ASSERT_EQ(conv.exit_code, 0) << conv.output;
  EXPECT_THAT(conv.output, HasSubstr("are ignored for .qs output of a mesh"));
  EXPECT_EQ(file_bytes(out), file_bytes(qsplat_sample("dragon_vrip_res4.strict.qs")));
}

TEST(QsCli, AQsModelIsNotAnInputToConvert) {
  POINTILLIST_REQUIRE_SHARED_TESTDATA();
  TempDir dir;
  const CliResult r =
      run_cli("convert " + qsplat_sample("dragon_vrip_res4.qs") + " -o " + dir.file("x.ptl"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_THAT(r.output, HasSubstr("already a splat model (.qs)"));
  EXPECT_FALSE(fs::exists(dir.file("x.ptl")));
}

TEST(InputsCli, ConvertMergesSeveralTextFiles) {
  TempDir dir;
  // Two halves of a 40 × 40 grid in the plane z = 0, one with a header and commas.
  std::string a = "x y z\n", b;
  for (int j = 0; j < 40; ++j) {
    for (int i = 0; i < 40; ++i) {
      std::string& out = i < 20 ? a : b;
      char line[64];
      std::snprintf(line, sizeof line, i < 20 ? "%g %g 0\n" : "%g,%g,0\n", i * 0.1, j * 0.1);
      out += line;
    }
  }
  write_text_file(dir.file("a.xyz"), a);
  write_text_file(dir.file("b.csv"), b);
  const std::string ptl = dir.file("grid.ptl");
  const CliResult conv =
      run_cli("convert " + dir.file("a.xyz") + " " + dir.file("b.csv") + " -o " + ptl);
  ASSERT_EQ(conv.exit_code, 0) << conv.output;
  EXPECT_THAT(conv.output, HasSubstr("converted 1600 points"));
  const CliResult info = run_cli("info " + ptl);
  ASSERT_EQ(info.exit_code, 0) << info.output;
  EXPECT_THAT(info.output, HasSubstr("points:      1600"));
  const std::vector<double> box = info_bounds(info.output);
  EXPECT_NEAR(box[0], 0.0, 1e-5);
  EXPECT_NEAR(box[3], 3.9, 1e-5);
  EXPECT_NEAR(box[4], 3.9, 1e-5);
}

TEST(InputsCli, RenderMergesSeveralScansIntoOneModelAsConvertDoes) {
  TempDir dir;
  // A 40 × 40 grid split into a large tile and a tile of one point, which alone is too small
  // to estimate a normal: merged, it is prepared with its neighbours.
  std::string a, b;
  for (int j = 0; j < 40; ++j) {
    for (int i = 0; i < 40; ++i) {
      char line[64];
      std::snprintf(line, sizeof line, "%g %g 0\n", i * 0.1, j * 0.1);
      (i == 39 && j == 39 ? b : a) += line;
    }
  }
  write_text_file(dir.file("a.xyz"), a);
  write_text_file(dir.file("b.xyz"), b);
  const std::string both = dir.file("a.xyz") + " " + dir.file("b.xyz");
  // Two-sided: the plane's PCA normals may face either way.
  const CliResult r = run_cli("render " + both + " " + dir.file("a.xyz") + " -q --two-sided --size 64x64 -o " +
                              dir.file("x.png") + " --stats " + dir.file("s.json"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream in(dir.file("s.json"));
  const std::string stats{std::istreambuf_iterator<char>(in), {}};
  // One model (a.xyz named twice is read once), the first file's name and the count of others.
  EXPECT_THAT(stats, HasSubstr("a.xyz (+1 more)"));
  EXPECT_EQ(stats.find("b.xyz"), std::string::npos) << stats;
  // The image of the points convert prepares from the same two files (written as PLY with
  // their normals and radii, read back as one scan).
  ASSERT_EQ(run_cli("convert " + both + " -q -o " + dir.file("m.ply")).exit_code, 0);
  const CliResult one = run_cli("render " + dir.file("m.ply") +
                                " -q --two-sided --size 64x64 -o " + dir.file("y.png"));
  ASSERT_EQ(one.exit_code, 0) << one.output;
  const ImageRgb8 x = read_png_rgb8(dir.file("x.png")), y = read_png_rgb8(dir.file("y.png"));
  int drawn = 0;
  for (const Rgb8& p : x.pixels) drawn += !(p == Rgb8{0, 0, 0});
  EXPECT_GT(drawn, 1000);
  EXPECT_TRUE(x.pixels == y.pixels);
}

TEST(InputsCli, DropOutliersRemovesStraysAboveAGridAndKeepsTheGrid) {
  TempDir dir;
  // A 60 × 60 grid in z = 0 (spacing 0.1) and 4 strays 1 to 2.5 above it, far apart.
  std::string text;
  char line[64];
  for (int j = 0; j < 60; ++j) {
    for (int i = 0; i < 60; ++i) {
      std::snprintf(line, sizeof line, "%g %g 0\n", i * 0.1, j * 0.1);
      text += line;
    }
  }
  for (int k = 0; k < 4; ++k) {
    std::snprintf(line, sizeof line, "%g %g %g\n", 1.0 + 4.0 * (k % 2), 1.0 + 4.0 * (k / 2),
                  1.0 + 0.5 * k);
    text += line;
  }
  write_text_file(dir.file("scan.xyz"), text);
  const std::string ptl = dir.file("scan.ptl");
  const CliResult conv =
      run_cli("convert " + dir.file("scan.xyz") + " -o " + ptl + " --drop-outliers");
  ASSERT_EQ(conv.exit_code, 0) << conv.output;
  EXPECT_THAT(conv.output, HasSubstr("dropped 4 outliers of 3604 points"));
  const CliResult info = run_cli("info " + ptl);
  EXPECT_THAT(info.output, HasSubstr("points:      3600"));
  EXPECT_NEAR(info_bounds(info.output)[5], 0.0, 1e-6) << "nothing above the grid is left";
  // Without the option every point stays; a mesh refuses the option and writes nothing.
  ASSERT_EQ(run_cli("convert -q " + dir.file("scan.xyz") + " -o " + ptl).exit_code, 0);
  EXPECT_THAT(run_cli("info " + ptl).output, HasSubstr("points:      3604"));
  write_text_file(dir.file("tri.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const CliResult mesh = run_cli("convert " + dir.file("tri.obj") + " -o " +
                                 dir.file("tri.ptl") + " --drop-outliers");
  EXPECT_NE(mesh.exit_code, 0);
  EXPECT_THAT(mesh.output, HasSubstr("outlier removal applies to point clouds"));
  EXPECT_FALSE(fs::exists(dir.file("tri.ptl")));
}

TEST(InputsCli, GeoreferencedLasTilesLineUpWhenMerged) {
  // Two tiles of one survey at UTM-like coordinates (x ≈ 500 km, y ≈ 4000 km), 1 mm steps: each
  // tile is shifted to its own local origin by the reader (the coordinates are too large for
  // float steps of 1 mm), so merging must bring the second into the first one's frame. Tile A
  // covers x = 0..9.5 m, tile B x = 10..19.5 m of the same 0.5 m grid: merged, the model spans
  // 19.5 m; overlaid in the wrong frame it would span 9.5 m.
  TempDir dir;
  using pointillist::testing::LasPoint;
  using pointillist::testing::LasSpec;
  LasSpec spec;
  spec.format = 0;
  spec.scale[0] = spec.scale[1] = spec.scale[2] = 0.001;
  spec.offset[0] = 500000.0;
  spec.offset[1] = 4000000.0;
  spec.offset[2] = 0.0;
  for (int tile = 0; tile < 2; ++tile) {
    std::vector<LasPoint> points;
    for (int j = 0; j < 20; ++j) {
      for (int i = 0; i < 20; ++i) {
        points.push_back({(tile * 20 + i) * 500, j * 500, 100000});
      }
    }
    pointillist::testing::write_file(dir.file("tile" + std::to_string(tile) + ".las"),
                                     pointillist::testing::build_las(spec, points));
  }
  const std::string ptl = dir.file("survey.ptl");
  const CliResult conv = run_cli("convert " + dir.file("tile0.las") + " " + dir.file("tile1.las") +
                                 " -o " + ptl + " --normals pca");
  ASSERT_EQ(conv.exit_code, 0) << conv.output;
  const CliResult info = run_cli("info " + ptl);
  ASSERT_EQ(info.exit_code, 0) << info.output;
  EXPECT_THAT(info.output, HasSubstr("points:      800"));
  const std::vector<double> box = info_bounds(info.output);
  EXPECT_NEAR(box[3] - box[0], 19.5, 1e-3) << info.output;
  EXPECT_NEAR(box[4] - box[1], 9.5, 1e-3) << info.output;
  EXPECT_NEAR(box[5] - box[2], 0.0, 1e-3) << info.output;
  // The frame: world bounds (the first tile's absolute coordinates) and LAS's Z-up axis.
  EXPECT_THAT(info.output, HasSubstr("(world)"));
  EXPECT_THAT(info.output, HasSubstr("min (500000.000, 4000000.000, 100.000)"));
  EXPECT_THAT(info.output, HasSubstr("up axis:     (0, 0, 1)"));
  // Rendered upright by default: the same image as asking for Z up, not the Y-up one. (The
  // flat survey faces one way: of the views from above and below, one shows it.)
  const auto lit = [](const ImageRgb8& img) {
    int n = 0;
    for (const Rgb8& p : img.pixels) n += p.r + p.g + p.b > 0;
    return n;
  };
  int shown = 0;
  for (const char* view : {"30,40", "30,-40"}) {
    const std::string base = "render " + ptl + " --size 96x64 -q --view " + view + " -o ";
    ASSERT_EQ(run_cli(base + dir.file("default.png")).exit_code, 0);
    ASSERT_EQ(run_cli(base + dir.file("z.png") + " --up 0,0,1").exit_code, 0);
    ASSERT_EQ(run_cli(base + dir.file("y.png") + " --up 0,1,0").exit_code, 0);
    const ImageRgb8 d = read_png_rgb8(dir.file("default.png"));
    EXPECT_EQ(d.pixels, read_png_rgb8(dir.file("z.png")).pixels) << view;
    if (lit(d) > 100) {
      ++shown;
      EXPECT_NE(d.pixels, read_png_rgb8(dir.file("y.png")).pixels) << view;
    }
  }
  EXPECT_EQ(shown, 1);
}

TEST(InputsCli, CompressedLasIsRefusedWithAdviceAndNoOutput) {
  TempDir dir;
  write_text_file(dir.file("scan.laz"), "LASF not really compressed");
  const CliResult r = run_cli("convert " + dir.file("scan.laz") + " -o " + dir.file("scan.ptl"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_THAT(r.output, HasSubstr("scan.laz"));
  EXPECT_THAT(r.output, HasSubstr("compressed LAS (LAZ) is not supported yet"));
  EXPECT_FALSE(fs::exists(dir.file("scan.ptl")));
}

TEST(InputsCli, BadTextLineIsNamedAndNothingIsWritten) {
  TempDir dir;
  write_text_file(dir.file("bad.xyz"), "1 2 3\n4 5 6\n7 eight 9\n");
  const CliResult r = run_cli("convert " + dir.file("bad.xyz") + " -o " + dir.file("bad.ptl"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_THAT(r.output, HasSubstr("bad.xyz"));
  EXPECT_THAT(r.output, HasSubstr("line 3"));
  EXPECT_FALSE(fs::exists(dir.file("bad.ptl")));
}

namespace {

// A unit square in the plane z = 0 as a 30 × 30 grid of triangle pairs, facing +z.
void write_square_obj(const std::string& path) {
  std::string obj = "# square\n";
  const int n = 30;
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) obj += "v " + std::to_string(double(i) / n) + " " +
                                          std::to_string(double(j) / n) + " 0\n";
  }
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i + 1, b = a + 1, c = a + n + 1, d = c + 1;
      obj += "f " + std::to_string(a) + " " + std::to_string(b) + " " + std::to_string(d) + "\n";
      obj += "f " + std::to_string(a) + " " + std::to_string(d) + " " + std::to_string(c) + "\n";
    }
  }
  write_text_file(path, obj);
}

}  // namespace

TEST(InputsCli, ObjMeshRendersDirectly) {
  // The square seen from the front: the middle of the image is drawn, the corners are not.
  TempDir dir;
  write_square_obj(dir.file("square.obj"));
  const std::string png = dir.file("square.png");
  const CliResult r = run_cli("render " + dir.file("square.obj") + " -o " + png + " --size 100x100");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const ImageRgb8 img = read_png_rgb8(png);
  const Rgb8 centre = img.pixels[50 * 100 + 50];
  EXPECT_GT(int(centre.r) + centre.g + centre.b, 150);
  EXPECT_EQ(img.pixels[0], (Rgb8{0, 0, 0}));
}

TEST(ViewCli, UpAxisOrbitsAZUpModelUpright) {
  // A tall thin column along +z (a z-up scan): with --up 0,0,1 it stands upright in the image
  // (taller than wide); with the default +y up it lies across it.
  TempDir dir;
  std::string xyz;
  for (int k = 0; k < 200; ++k) {
    for (int a = 0; a < 24; ++a) {
      const double t = 2 * M_PI * a / 24;
      char line[96];
      std::snprintf(line, sizeof line, "%g %g %g\n", 0.1 * std::cos(t), 0.1 * std::sin(t),
                    k * 0.01);
      xyz += line;
    }
  }
  write_text_file(dir.file("column.xyz"), xyz);
  const auto extent = [&](const std::string& extra) {
    const std::string png = dir.file("column.png");
    const CliResult r =
        run_cli("render " + dir.file("column.xyz") + " -o " + png + " --size 200x200 " + extra);
    EXPECT_EQ(r.exit_code, 0) << r.output;
    const ImageRgb8 img = read_png_rgb8(png);
    int x0 = 200, x1 = -1, y0 = 200, y1 = -1;
    for (int y = 0; y < 200; ++y) {
      for (int x = 0; x < 200; ++x) {
        const Rgb8 p = img.pixels[std::size_t(y) * 200 + x];
        if ((p.r | p.g | p.b) == 0) continue;
        x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
      }
    }
    return std::pair{x1 - x0, y1 - y0};
  };
  const auto [w_up, h_up] = extent("--view 0,10 --up 0,0,1");
  EXPECT_GT(h_up, 3 * w_up) << "upright with --up 0,0,1";
  const auto [w_y, h_y] = extent("--view 90,10");
  EXPECT_GT(w_y, 3 * h_y) << "lying across with the default +y up";
  const CliResult bad = run_cli("render " + dir.file("column.xyz") + " -o " +
                                dir.file("x.png") + " --up 0,0,0");
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_THAT(bad.output, HasSubstr("not a direction"));
}

TEST(QualityCli, QualityModeRendersAndReportsItsSettings) {
  TempDir dir;
  const std::string ply = dir.file("sphere.ply"), ptl = dir.file("sphere.ptl");
  ASSERT_EQ(run_cli("generate --scene sphere --points 20000 -o " + ply).exit_code, 0);
  ASSERT_EQ(run_cli("convert -q " + ply + " -o " + ptl).exit_code, 0);
  for (const std::string rule : {"zrange", "zthreshold"}) {
    const std::string png = dir.file(rule + ".png");
    const CliResult r = run_cli("render " + ptl + " -o " + png +
                                " --size 160x120 --mode quality --reconstruction " + rule +
                                " --stats -");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_THAT(r.output, HasSubstr("\"mode\": \"quality\""));
    EXPECT_THAT(r.output, HasSubstr("\"reconstruction\": \"" + rule + "\""));
    EXPECT_THAT(r.output, HasSubstr("\"splats\""));
    const ImageRgb8 img = read_png_rgb8(png);
    const Rgb8 centre = img.pixels[60 * 160 + 80];
    EXPECT_GT(int(centre.r) + centre.g + centre.b, 100) << rule;
    EXPECT_EQ(img.pixels[0], (Rgb8{0, 0, 0})) << rule;
  }
  // The Sequential Point Tree feeds the quality rasterizer too (the stream carries the discs).
  const CliResult spt = run_cli("render " + ptl + " -o " + dir.file("x.png") +
                                " --size 160x120 --mode quality --lod spt --stats -");
  ASSERT_EQ(spt.exit_code, 0) << spt.output;
  EXPECT_THAT(spt.output, HasSubstr("\"lod\": \"spt\""));
  EXPECT_THAT(spt.output, HasSubstr("\"mode\": \"quality\""));
  const CliResult opacity = run_cli("render " + ptl + " -o " + dir.file("x.png") +
                                    " --mode quality --opacity 0");
  EXPECT_NE(opacity.exit_code, 0);
  EXPECT_THAT(opacity.output, HasSubstr("--opacity"));
}

TEST(InputsCliData, LionLasTilesConvertTogetherAndRenderInColour) {
  const fs::path dir_in = pointillist::testing::model_cache_dir() / "lion_takanawa_las";
  if (!fs::is_directory(dir_in)) GTEST_SKIP() << "run scripts/fetch-models.sh for the lion scan";
  std::vector<std::string> tiles;
  for (const auto& e : fs::directory_iterator(dir_in)) {
    if (e.path().extension() == ".las") tiles.push_back(e.path().string());
  }
  ASSERT_GT(tiles.size(), 10u);
  // The expected count from the headers (legacy point count, byte 107 of a LAS header).
  std::uint64_t expected = 0;
  std::string args;
  for (const std::string& t : tiles) {
    const std::string bytes = file_bytes(t);
    ASSERT_GE(bytes.size(), 111u) << t;
    std::uint32_t count = 0;
    std::memcpy(&count, bytes.data() + 107, 4);
    expected += count;
    args += " " + t;
  }
  TempDir dir;
  const std::string ptl = dir.file("lion.ptl"), png = dir.file("lion.png");
  const CliResult conv = run_cli("convert -q" + args + " -o " + ptl);
  ASSERT_EQ(conv.exit_code, 0) << conv.output;
  const CliResult info = run_cli("info " + ptl);
  EXPECT_THAT(info.output, HasSubstr("points:      " + std::to_string(expected) + " (leaves)"));
  EXPECT_THAT(info.output, HasSubstr("color"));
  const CliResult ren =
      run_cli("render " + ptl + " -o " + png + " --size 400x300 --view 30,15 --up 0,0,1");
  ASSERT_EQ(ren.exit_code, 0) << ren.output;
  const ImageRgb8 img = read_png_rgb8(png);
  // The stone lion is grey; the foliage around it is green.
  std::size_t green = 0, grey = 0;
  for (const Rgb8& p : img.pixels) {
    if ((p.r | p.g | p.b) == 0) continue;
    if (p.g > p.r + 15 && p.g > p.b + 15) ++green;
    if (std::abs(int(p.r) - int(p.g)) < 12 && std::abs(int(p.g) - int(p.b)) < 12 && p.r > 40) ++grey;
  }
  EXPECT_GT(green, 200u);
  EXPECT_GT(grey, 5000u);
}

TEST(QualityCli, ReferenceModeDrawsTheTrianglesAndCompareMeasuresSplatsAgainstThem) {
  // The square seen at an angle: the triangles drawn by --mode reference cover exactly the
  // projected square; the quality-mode splats of the same mesh must cover it without holes and
  // with nearly the same silhouette.
  TempDir dir;
  write_square_obj(dir.file("square.obj"));
  const std::string view = " --size 200x150 --view 25,15";
  const CliResult ref = run_cli("render " + dir.file("square.obj") + " -o " + dir.file("ref.png") +
                                view + " --mode reference --stats -");
  ASSERT_EQ(ref.exit_code, 0) << ref.output;
  EXPECT_THAT(ref.output, HasSubstr("\"mode\": \"reference\""));
  ASSERT_EQ(run_cli("render " + dir.file("square.obj") + " -o " + dir.file("q.png") + view +
                    " --mode quality").exit_code, 0);
  const CliResult cmp =
      run_cli("compare " + dir.file("ref.png") + " " + dir.file("q.png") + " --json -");
  ASSERT_EQ(cmp.exit_code, 0) << cmp.output;
  double iou = 0;
  unsigned long holes = 99;
  const auto at_iou = cmp.output.find("\"silhouette_iou\":");
  const auto at_holes = cmp.output.find("\"hole_pixels\":");
  ASSERT_NE(at_iou, std::string::npos) << cmp.output;
  ASSERT_NE(at_holes, std::string::npos) << cmp.output;
  std::sscanf(cmp.output.c_str() + at_iou, "\"silhouette_iou\": %lf", &iou);
  std::sscanf(cmp.output.c_str() + at_holes, "\"hole_pixels\": %lu", &holes);
  // Splats on the square's border overhang it by their radius: cells are 1/30 of the square,
  // about 3.2 px here, and a splat's radius is 1.1 × the circumradius of its right triangles
  // (0.71 cells), about 2.5 px, along a perimeter of about 340 px: some 850 extra pixels on a
  // square of 8,500, IoU about 0.91. 0.88 leaves room for rounding, and catches a silhouette
  // off by a pixel more all around.
  EXPECT_GE(iou, 0.88) << cmp.output;
  EXPECT_EQ(holes, 0u) << cmp.output;
  // A splat model has no triangles to draw.
  ASSERT_EQ(run_cli("convert -q " + dir.file("square.obj") + " -o " + dir.file("sq.ptl")).exit_code, 0);
  const CliResult bad = run_cli("render " + dir.file("sq.ptl") + " -o " + dir.file("x.png") +
                                " --mode reference");
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_THAT(bad.output, HasSubstr("is a splat model"));
}

// The demo scene sampled with `points` points and converted to .ptl in `dir`.
std::string demo_model(const TempDir& dir, int points) {
  const std::string ply = dir.file("scene.ply"), ptl = dir.file("scene.ptl");
  EXPECT_EQ(run_cli("generate --points " + std::to_string(points) + " -o " + ply).exit_code, 0);
  EXPECT_EQ(run_cli("convert -q " + ply + " -o " + ptl).exit_code, 0);
  return ptl;
}

TEST(PagedCli, ProgressiveFramesReadMoreEachFrameAndEndAtTheFullImage) {
  TempDir dir;
  const std::string ptl = demo_model(dir, 100000);
  const std::string common = " --size 200x150 --view 30,20";
  ASSERT_EQ(run_cli("render " + ptl + " -o " + dir.file("full.png") + common).exit_code, 0);
  const CliResult r = run_cli("render " + ptl + " -o " + dir.file("last.png") + common +
                              " --progressive 40 --read-per-frame 200K --frames-out " +
                              dir.file("frames") + " --stats -");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("\"paged\": true"));
  EXPECT_THAT(r.output, HasSubstr("\"complete\": true"));
  // bytes_read of each frame: non-decreasing, the first a small part of the model.
  std::vector<long long> read;
  const std::size_t frames_at = r.output.find("\"frames\"");
  ASSERT_NE(frames_at, std::string::npos);
  for (std::size_t at = frames_at;
       (at = r.output.find("\"bytes_read\": ", at)) != std::string::npos;) {
    at += 14;
    read.push_back(std::atoll(r.output.c_str() + at));
  }
  ASSERT_EQ(read.size(), 40u);
  for (std::size_t i = 1; i < 40; ++i) EXPECT_GE(read[i], read[i - 1]) << "frame " << i;
  const auto model_at = r.output.find("\"model_bytes\": ");
  ASSERT_NE(model_at, std::string::npos);
  const long long model_bytes = std::atoll(r.output.c_str() + model_at + 15);
  EXPECT_LT(read[0] * 100, model_bytes * 2) << "the first frame should need under 2% of the model";
  EXPECT_LT(read[1], read[39]);
  // The last frame is the image rendered from the whole model.
  EXPECT_EQ(read_png_rgb8(dir.file("last.png")).pixels, read_png_rgb8(dir.file("full.png")).pixels);
  EXPECT_TRUE(fs::exists(dir.file("frames") + "/frame_00039.png"));
  // The loader thread reads between frames, and the program waits for it: a second run shows the
  // same frames.
  const CliResult again = run_cli("render " + ptl + " -o " + dir.file("again.png") + common +
                                  " --progressive 6 --read-per-frame 200K --frames-out " +
                                  dir.file("frames2"));
  ASSERT_EQ(again.exit_code, 0) << again.output;
  for (const char* f : {"/frame_00001.png", "/frame_00003.png", "/frame_00005.png"}) {
    EXPECT_EQ(read_png_rgb8(dir.file("frames2") + f).pixels,
              read_png_rgb8(dir.file("frames") + f).pixels)
        << f;
  }
}

TEST(PagedCli, QualityModeRendersPageByPageAndSptIsRefusedWithAReason) {
  TempDir dir;
  const std::string ptl = demo_model(dir, 50000);
  const std::string common = " --size 160x120 --view 30,20 --mode quality";
  ASSERT_EQ(run_cli("render " + ptl + " -o " + dir.file("whole.png") + common).exit_code, 0);
  const CliResult paged = run_cli("render " + ptl + " -o " + dir.file("paged.png") + common +
                                  " --memory 1G --stats -");
  ASSERT_EQ(paged.exit_code, 0) << paged.output;
  EXPECT_THAT(paged.output, HasSubstr("\"mode\": \"quality\""));
  EXPECT_THAT(paged.output, HasSubstr("\"complete\": true"));
  // With every page the view needs, the paged quality image is the whole model's.
  EXPECT_EQ(read_png_rgb8(dir.file("paged.png")).pixels,
            read_png_rgb8(dir.file("whole.png")).pixels);
  const CliResult spt =
      run_cli("render " + ptl + " -o " + dir.file("spt.png") + " --lod spt --memory 1G");
  EXPECT_NE(spt.exit_code, 0);
  EXPECT_THAT(spt.output, HasSubstr("drop --lod spt"));
  EXPECT_FALSE(fs::exists(dir.file("spt.png")));
}

TEST(PagedCli, MemoryCapIsHeldAndReported) {
  TempDir dir;
  const std::string ptl = demo_model(dir, 100000);
  const CliResult r = run_cli("render " + ptl + " -o " + dir.file("capped.png") +
                              " --size 200x150 --memory 600K --stats -");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto peak_at = r.output.find("\"resident_bytes_peak\": ");
  ASSERT_NE(peak_at, std::string::npos) << r.output;
  EXPECT_LE(std::atoll(r.output.c_str() + peak_at + 23), 600 * 1024);
  const ImageRgb8 img = read_png_rgb8(dir.file("capped.png"));
  EXPECT_GT(drawn_pixels(img), 200u * 150u / 10);
  const CliResult tiny = run_cli("render " + ptl + " -o " + dir.file("x.png") + " --memory 1K");
  EXPECT_NE(tiny.exit_code, 0);
  EXPECT_THAT(tiny.output, HasSubstr("smaller than the model's first page"));
  const CliResult bad = run_cli("render " + ptl + " -o " + dir.file("x.png") + " --memory lots");
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_THAT(bad.output, HasSubstr("--memory 'lots'"));
}

TEST(PtlCli, ConvertWritesVersion2ByDefaultAndVersion1OnRequestAndBothRender) {
  TempDir dir;
  const std::string ply = dir.file("scene.ply");
  ASSERT_EQ(run_cli("generate --scene sphere --points 30000 -o " + ply).exit_code, 0);
  ASSERT_EQ(run_cli("convert -q " + ply + " -o " + dir.file("v2.ptl")).exit_code, 0);
  ASSERT_EQ(run_cli("convert -q " + ply + " -o " + dir.file("v1.ptl") + " --ptl-version 1")
                .exit_code,
            0);
  const CliResult i2 = run_cli("info " + dir.file("v2.ptl"));
  const CliResult i1 = run_cli("info " + dir.file("v1.ptl"));
  EXPECT_THAT(i2.output, HasSubstr("version 2: quantized 4-byte nodes"));
  EXPECT_THAT(i1.output, HasSubstr("version 1"));
  // At most 6 bytes per point without colour (QSplat's figure), 40+ for float nodes.
  const double v2_bytes = double(fs::file_size(dir.file("v2.ptl"))) / 30000.0;
  const double v1_bytes = double(fs::file_size(dir.file("v1.ptl"))) / 30000.0;
  EXPECT_LE(v2_bytes, 6.0);
  EXPECT_GT(v1_bytes, 40.0);
  // Both render the same sphere: the quantized spheres only grow a little.
  const std::string view = " --size 200x150 --view 30,20 --splat ellipse";
  ASSERT_EQ(run_cli("render " + dir.file("v1.ptl") + " -o " + dir.file("v1.png") + view).exit_code, 0);
  ASSERT_EQ(run_cli("render " + dir.file("v2.ptl") + " -o " + dir.file("v2.png") + view).exit_code, 0);
  const CliResult cmp =
      run_cli("compare " + dir.file("v1.png") + " " + dir.file("v2.png") + " --json -");
  const auto at = cmp.output.find("\"silhouette_iou\": ");
  ASSERT_NE(at, std::string::npos) << cmp.output;
  EXPECT_GE(std::atof(cmp.output.c_str() + at + 18), 0.97) << cmp.output;
  const auto holes = cmp.output.find("\"hole_pixels\": ");
  ASSERT_NE(holes, std::string::npos);
  EXPECT_EQ(std::atoi(cmp.output.c_str() + holes + 15), 0) << cmp.output;
  EXPECT_NE(run_cli("convert -q " + ply + " -o " + dir.file("v3.ptl") + " --ptl-version 3")
                .exit_code,
            0);
}

TEST(PtlCli, LeafTrimChoosesTheLayoutAndAppliesOnlyToVersion2) {
  TempDir dir;
  const std::string ply = dir.file("scene.ply");
  ASSERT_EQ(run_cli("generate --scene sphere --points 5000 -o " + ply).exit_code, 0);
  ASSERT_EQ(run_cli("convert -q " + ply + " -o " + dir.file("e.ptl") + " --leaf-trim eighths")
                .exit_code,
            0);
  ASSERT_EQ(run_cli("convert -q " + ply + " -o " + dir.file("s.ptl")).exit_code, 0);
  // The schema's attribute count (header byte 140, docs/ptl-format.md): 4 with eighths, 5 with
  // the leaf-trim attribute.
  const auto attribute_count = [](const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    in.seekg(140);
    unsigned char b[4] = {};
    in.read(reinterpret_cast<char*>(b), 4);
    return b[0] | b[1] << 8 | b[2] << 16 | b[3] << 24;
  };
  EXPECT_EQ(attribute_count(dir.file("e.ptl")), 4);
  EXPECT_EQ(attribute_count(dir.file("s.ptl")), 5);
  EXPECT_THAT(run_cli("info " + dir.file("e.ptl")).output, HasSubstr("leaf trims in eighths"));
  EXPECT_THAT(run_cli("info " + dir.file("s.ptl")).output, HasSubstr("leaf trims in sixteenths"));
  for (const std::string& bad : {std::string(" -o ") + dir.file("x.qs") + " --leaf-trim eighths",
                                 std::string(" -o ") + dir.file("x.ptl") +
                                     " --ptl-version 1 --leaf-trim eighths"}) {
    const CliResult r = run_cli("convert -q " + ply + bad);
    EXPECT_NE(r.exit_code, 0) << bad;
    EXPECT_THAT(r.output, HasSubstr("--leaf-trim applies only to .ptl version 2")) << bad;
  }
  EXPECT_FALSE(fs::exists(dir.file("x.qs")));
  EXPECT_FALSE(fs::exists(dir.file("x.ptl")));
  EXPECT_NE(run_cli("convert -q " + ply + " -o " + dir.file("y.ptl") + " --leaf-trim halves")
                .exit_code,
            0);
}
