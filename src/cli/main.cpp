// The `pointillist` command: convert scans to splat models, render them, inspect files, demo.
#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <sstream>
#include <string>
#include <vector>

#include "commands.hpp"
#include "pointillist/core/error.hpp"

namespace pc = pointillist::cli;
using pointillist::OptionError;
using pointillist::Vec3f;

namespace {

std::vector<float> parse_floats(const std::string& text, std::size_t count, const char sep,
                                const std::string& option) {
  std::vector<float> values;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, sep)) {
    try {
      std::size_t used = 0;
      const float v = std::stof(item, &used);
      if (used != item.size()) throw std::invalid_argument(item);
      values.push_back(v);
    } catch (const std::exception&) {
      values.clear();
      break;
    }
  }
  if (values.size() != count) {
    throw OptionError(option + " '" + text + "': expected " + std::to_string(count) +
                      " numbers separated by '" + sep + "'");
  }
  return values;
}

// --size WxH and --view AZ,EL (may be empty) into `v`.
void parse_size_and_view(const std::string& size, const std::string& view, pc::ViewOptions& v) {
  const auto wh = parse_floats(size, 2, 'x', "--size");
  v.width = static_cast<int>(wh[0]);
  v.height = static_cast<int>(wh[1]);
  if (wh[0] < 1 || wh[1] < 1 || wh[0] > 32768 || wh[1] > 32768 || wh[0] != v.width ||
      wh[1] != v.height) {
    throw pointillist::OptionError("--size '" + size +
                                   "': width and height must be whole numbers from 1 to 32768");
  }
  if (!view.empty()) {
    const auto ae = parse_floats(view, 2, ',', "--view");
    v.azimuth_deg = ae[0];
    v.elevation_deg = ae[1];
  }
}

// "500000", "64K", "512M", "1.5G" (powers of 1024) -> bytes.
std::uint64_t parse_bytes(const std::string& text, const std::string& option) {
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  double scale = 1;
  const std::string unit = end ? std::string(end) : std::string();
  if (unit == "K" || unit == "k" || unit == "KB" || unit == "KiB") scale = 1024.0;
  else if (unit == "M" || unit == "MB" || unit == "MiB") scale = 1024.0 * 1024;
  else if (unit == "G" || unit == "GB" || unit == "GiB") scale = 1024.0 * 1024 * 1024;
  else if (!unit.empty()) scale = -1;
  const double bytes = value * scale;
  if (text.empty() || end == text.c_str() || scale < 0 || !(bytes >= 1) || bytes > 1e18) {
    throw OptionError(option + " '" + text +
                      "': give a size in bytes, optionally with K, M or G (e.g. 512M)");
  }
  return static_cast<std::uint64_t>(bytes);
}

// "orbit:N" (1 <= N <= 100000) -> N.
unsigned parse_orbit_path(const std::string& text) {
  const std::string prefix = "orbit:";
  if (text.rfind(prefix, 0) == 0) {
    const std::string count = text.substr(prefix.size());
    char* end = nullptr;
    const unsigned long n = std::strtoul(count.c_str(), &end, 10);
    if (!count.empty() && *end == '\0' && n >= 1 && n <= 100000 && count[0] != '-') {
      return static_cast<unsigned>(n);
    }
  }
  throw pointillist::OptionError("--path '" + text +
                                 "' is not a camera path; give orbit:N with N frames from 1 to 100000 "
                                 "(e.g. --path orbit:120)");
}

Vec3f parse_vec3(const std::string& text, const std::string& option) {
  const auto v = parse_floats(text, 3, ',', option);
  return {v[0], v[1], v[2]};
}

// "R,G,B" with each component a whole number 0-255.
pointillist::Rgb8 parse_rgb8(const std::string& text, const std::string& option) {
  const Vec3f c = parse_vec3(text, option);
  for (float v : {c.x, c.y, c.z}) {
    if (v < 0 || v > 255 || v != std::floor(v)) {
      throw OptionError(option + " '" + text + "': components must be whole numbers 0-255");
    }
  }
  return {static_cast<std::uint8_t>(c.x), static_cast<std::uint8_t>(c.y),
          static_cast<std::uint8_t>(c.z)};
}

void add_columns(CLI::App* app, std::string& columns) {
  app->add_option("--columns", columns,
                  "Text inputs (.xyz .pts .csv .txt): what each column holds, e.g. "
                  "x,y,z,skip,r,g,b (names: x y z nx ny nz r g b skip; default: detect)");
}

void add_threads(CLI::App* app, unsigned& threads) {
  app->add_option("--threads", threads, "Worker threads (0 = one per core)")->default_val(0);
}

void add_prepare_options(CLI::App* app, pointillist::PrepareOptions& p) {
  const std::map<std::string, pointillist::NormalSource> normal_sources{
      {"auto", pointillist::NormalSource::Auto},
      {"keep", pointillist::NormalSource::Keep},
      {"mesh", pointillist::NormalSource::Mesh},
      {"pca", pointillist::NormalSource::Pca}};
  app->add_option("--normals", p.normals,
                  "Normal source: auto (file, else mesh faces, else PCA), keep, mesh, pca")
      ->transform(CLI::CheckedTransformer(normal_sources, CLI::ignore_case))
      ->default_str("auto");
  app->add_option("--k", p.k, "Neighbours for PCA normals")->default_val(16)->check(
      CLI::Range(3u, 256u));
  app->add_option("--radius-scale", p.radius_scale, "Multiply every splat radius by S")
      ->default_val(1.0f)
      ->check(CLI::PositiveNumber);
  app->add_flag("--drop-outliers", p.drop_outliers,
                "Point clouds: drop stray points, whose neighbours are much farther than usual");
  app->add_option("--outlier-ratio", p.outlier_ratio_drop,
                  "With --drop-outliers: how many times farther than its neighbours' a point's "
                  "neighbours must be (lower drops more)")
      ->default_val(3.0f)
      ->check(CLI::Range(1.0001f, 1e6f));
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Pointillist: multiresolution splat models from 3D scans, rendered fast on the CPU"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "pointillist 0.1.0");

  // convert
  pc::ConvertCommandOptions convert;
  auto* convert_cmd = app.add_subcommand(
      "convert", "Convert scans (PLY, XYZ/PTS/CSV, OBJ, LAS; .gz too) into a splat model (.ptl, "
                 ".qs) or points with normals and radii (.ply)");
  convert_cmd->add_option("inputs", convert.inputs, "Input files (several are merged)")
      ->required()
      ->check(CLI::ExistingFile);
  convert_cmd->add_option("-o,--output", convert.output,
                          "Output file: .ptl (Pointillist model), .qs (QSplat 1.1 model) or .ply")
      ->required();
  add_columns(convert_cmd, convert.convert.columns);
  add_prepare_options(convert_cmd, convert.convert.prepare);
  convert_cmd->add_flag("--ascii", convert.convert.ascii, "Write .ply output as ascii");
  convert_cmd->add_option("--ptl-version", convert.convert.ptl_version,
                          ".ptl version to write: 2 (quantized, paged; the default) or 1 (float "
                          "nodes, 40 bytes each)")
      ->default_val(2);
  const std::map<std::string, pointillist::quant::LeafTrim> trims{
      {"sixteenths", pointillist::quant::LeafTrim::Sixteenths},
      {"eighths", pointillist::quant::LeafTrim::Eighths}};
  convert_cmd
      ->add_option("--leaf-trim", convert.convert.leaf_trim,
                   ".ptl v2: steps in which leaves keep their radius trim: sixteenths (the "
                   "default, tighter splats) or eighths (files that Pointillist before "
                   "2026-11-24 reads)")
      ->transform(CLI::CheckedTransformer(trims, CLI::ignore_case));
  add_threads(convert_cmd, convert.threads);
  convert_cmd->add_flag("-q,--quiet", convert.quiet, "No progress bars and no summary");

  // render
  pc::RenderOptions render;
  std::string size = "1280x720", view, eye, target, up, background = "0,0,0";
  auto* render_cmd =
      app.add_subcommand("render", "Render a model (.ptl, .qs, or a scan built in memory) to PNG");
  render_cmd
      ->add_option("inputs", render.inputs,
                   "Models or scans (several are drawn together), or one scene file (.json)")
      ->required()
      ->check(CLI::ExistingFile);
  render_cmd->add_option("-o,--output", render.output, "Output PNG")->required();
  render_cmd->add_option("--size", size, "Image size WxH")->default_str("1280x720");
  render_cmd->add_option("--view", view, "Orbit view AZ,EL in degrees (default 0,0)");
  render_cmd->add_option("--distance", render.view.distance,
                         "Eye distance in model radii (default: whole model in view)");
  render_cmd->add_option("--fov", render.view.fov_deg, "Vertical field of view, degrees")
      ->default_val(30.0f);
  render_cmd->add_option("--eye", eye, "Explicit eye X,Y,Z (with --target)");
  render_cmd->add_option("--target", target, "Explicit target X,Y,Z (with --eye)");
  render_cmd->add_option("--up", up,
                         "Up vector X,Y,Z (default 0,1,0): with --eye/--target the camera's; "
                         "otherwise the model's up axis for --view and --path (0,0,1 for most "
                         "LAS scans)");
  render_cmd->add_option("--threshold", render.settings.threshold_px,
                         "Stop refining at this projected splat diameter, pixels")
      ->default_val(1.0f)
      ->check(CLI::Range(0.01f, 1000.0f));
  const std::map<std::string, pointillist::SplatShape> shapes{
      {"square", pointillist::SplatShape::Square},
      {"circle", pointillist::SplatShape::Circle},
      {"ellipse", pointillist::SplatShape::Ellipse}};
  render_cmd->add_option("--splat", render.settings.shape, "Splat kernel: square, circle, ellipse")
      ->transform(CLI::CheckedTransformer(shapes, CLI::ignore_case))
      ->default_str("circle");
  render_cmd->add_option("--background", background, "Background color R,G,B (0-255)")
      ->default_str("0,0,0");
  render_cmd->add_option("--depth", render.depth_output, "Also write a 16-bit depth PNG");
  render_cmd->add_option("--stats", render.stats_output, "Write statistics as JSON (- = stdout)");
  const std::map<std::string, pointillist::LodScheme> lods{
      {"qsplat", pointillist::LodScheme::QSplat}, {"spt", pointillist::LodScheme::Spt}};
  render_cmd->add_option("--lod", render.frame.lod,
                         "Level-of-detail scheme: qsplat (hierarchy traversal) or spt (Sequential "
                         "Point Tree, one sequential pass)")
      ->transform(CLI::CheckedTransformer(lods, CLI::ignore_case))
      ->default_str("qsplat");
  render_cmd->add_option("--epsilon", render.frame.epsilon_px,
                         "With --lod spt: allowed geometric error in pixels (1 = full detail)")
      ->default_val(1.0f)
      ->check(CLI::Range(0.001f, 1000.0f));
  render_cmd->add_flag("--no-chunk-culling{false}", render.frame.spt_chunk_culling,
                       "With --lod spt: scan every chunk's list even when the chunk is outside "
                       "the view (to measure what chunk culling saves)");
  std::string path;
  render_cmd->add_option("--path", path,
                         "Render a sequence of frames along a camera path: orbit:N = N frames "
                         "around the model (azimuth +0..360 degrees from --view)");
  render_cmd->add_option("--frame-ms", render.frame_ms,
                         "With --path: adjust the threshold frame to frame to hold T ms per frame")
      ->check(CLI::Range(0.1, 100000.0));
  render_cmd->add_option("--refine", render.refine_frames,
                         "Then render K frames refining to full detail, as a viewer does when the "
                         "camera stops")
      ->check(CLI::Range(1u, 100000u));
  std::string memory;
  render_cmd->add_option("--memory", memory,
                         "Render page by page keeping at most this much of the model in memory "
                         "(e.g. 512M); coarser where the cap bites");
  render_cmd->add_option("--progressive", render.progressive_frames,
                         "Render N frames at the view while the model's pages load, as a viewer "
                         "shows a model streaming in")
      ->check(CLI::Range(1u, 100000u));
  std::string read_per_frame;
  render_cmd->add_option("--read-per-frame", read_per_frame,
                         "With --progressive: bytes of the model read between two frames "
                         "(default 1M, a disk at 30 MB/s shown at 30 frames/s)");
  render_cmd->add_option("--frames-out", render.frames_out,
                         "Write every frame of a sequence to DIR/frame_NNNNN.png");
  const std::map<std::string, pointillist::Rasterizer> modes{
      {"fast", pointillist::Rasterizer::Fast},
      {"quality", pointillist::Rasterizer::Quality},
      {"reference", pointillist::Rasterizer::Reference}};
  render_cmd->add_option("--mode", render.frame.rasterizer,
                         "fast (opaque splats, the default), quality (perspective-correct "
                         "Gaussian surface splatting with per-pixel shading), or reference (a "
                         "mesh input's triangles, z-buffered, same camera and shading)")
      ->transform(CLI::CheckedTransformer(modes, CLI::ignore_case))
      ->default_str("fast");
  const std::map<std::string, pointillist::Reconstruction> reconstructions{
      {"zthreshold", pointillist::Reconstruction::ZThreshold},
      {"zrange", pointillist::Reconstruction::ZRange}};
  render_cmd->add_option("--reconstruction", render.frame.quality.reconstruction,
                         "With --mode quality: which fragments of a pixel blend, zrange (depth "
                         "intervals overlap) or zthreshold (within a fixed depth of the front)")
      ->transform(CLI::CheckedTransformer(reconstructions, CLI::ignore_case))
      ->default_str("zrange");
  render_cmd->add_option("--opacity", render.frame.quality.opacity,
                         "With --mode quality: opacity of every surface, composited front to back "
                         "(1 = opaque)")
      ->default_val(1.0f)
      ->check(CLI::Range(0.001f, 1.0f));
  add_prepare_options(render_cmd, render.prepare);
  add_columns(render_cmd, render.columns);
  add_threads(render_cmd, render.threads);
  render_cmd->add_flag("-q,--quiet", render.quiet, "No progress bars and no summary");

  // info
  pc::InfoOptions info;
  auto* info_cmd = app.add_subcommand("info", "Describe a model or scan file");
  info_cmd->add_option("input", info.input, "Model or scan file")->required()->check(
      CLI::ExistingFile);
  add_threads(info_cmd, info.threads);
  add_columns(info_cmd, info.columns);
  std::string info_view, info_size = "1280x720";
  info_cmd->add_flag("--spt", info.spt,
                     "Also build the Sequential Point Tree and report its list and the share of "
                     "it one view scans");
  info_cmd->add_option("--view", info_view, "With --spt: orbit view AZ,EL (default 0,0)");
  info_cmd->add_option("--size", info_size, "With --spt: image size WxH")->default_str("1280x720");
  info_cmd->add_option("--distance", info.view.distance,
                       "With --spt: eye distance in model radii (default: whole model in view)");
  info_cmd->add_option("--epsilon", info.epsilon_px, "With --spt: error bound, pixels")
      ->default_val(1.0f)
      ->check(CLI::Range(0.001f, 1000.0f));

  // demo
  pc::DemoOptions demo;
  auto* demo_cmd = app.add_subcommand(
      "demo", "Generate the built-in analytic scene, convert it, render views with every kernel "
              "(and the Stanford dragon when fetched)");
  demo_cmd->add_option("--out", demo.out_dir, "Output folder")->default_val("demo-out");
  demo_cmd->add_option("--points", demo.points, "Samples in the generated scene")
      ->default_val(400000)
      ->check(CLI::Range(std::size_t{100}, std::size_t{200'000'000}));
  add_threads(demo_cmd, demo.threads);
  demo_cmd->add_flag("-q,--quiet", demo.quiet, "No progress bars");

  // generate
  pc::GenerateOptions generate;
  auto* generate_cmd = app.add_subcommand(
      "generate", "Write a point cloud sampled from an analytic scene (for tests and benchmarks)");
  generate_cmd->add_option("-o,--output", generate.output, "Output .ply")->required();
  generate_cmd->add_option("--scene", generate.scene, "demo, sphere, torus or cube")
      ->default_val("demo");
  generate_cmd->add_option("--points", generate.points, "Number of samples")
      ->default_val(1000000)
      ->check(CLI::Range(std::size_t{1}, std::size_t{2'000'000'000}));
  generate_cmd->add_option("--seed", generate.seed, "Random seed")->default_val(1);
  generate_cmd->add_flag("--with-normals", generate.with_normals, "Also write exact normals");
  generate_cmd->add_flag("-q,--quiet", generate.quiet, "No summary line");

  // compare
  pc::CompareOptions compare;
  std::string compare_background;
  auto* compare_cmd = app.add_subcommand(
      "compare", "Compare a render with a reference image of the same size: PSNR, SSIM, hole "
                 "pixels, silhouette IoU");
  compare_cmd->add_option("reference", compare.reference, "Reference PNG")
      ->required()
      ->check(CLI::ExistingFile);
  compare_cmd->add_option("test", compare.test, "PNG to measure against the reference")
      ->required()
      ->check(CLI::ExistingFile);
  compare_cmd->add_option("--background", compare_background,
                          "Background color R,G,B (0-255) for the silhouette masks (default: the "
                          "reference's top-left pixel)");
  compare_cmd->add_option("--json", compare.json_output,
                          "Also write the metrics as JSON to FILE (- = stdout, instead of text)");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }

  try {
    if (*convert_cmd) return pc::run_convert(convert);
    if (*render_cmd) {
      parse_size_and_view(size, view, render.view);
      if (!eye.empty()) render.view.eye = parse_vec3(eye, "--eye");
      if (!target.empty()) render.view.target = parse_vec3(target, "--target");
      if (!up.empty()) render.view.up = parse_vec3(up, "--up");
      render.settings.background = parse_rgb8(background, "--background");
      if (!path.empty()) render.orbit_frames = parse_orbit_path(path);
      if (!memory.empty()) render.memory_cap = parse_bytes(memory, "--memory");
      if (!read_per_frame.empty()) {
        render.read_per_frame = parse_bytes(read_per_frame, "--read-per-frame");
      }
      return pc::run_render(render);
    }
    if (*info_cmd) {
      parse_size_and_view(info_size, info_view, info.view);
      return pc::run_info(info);
    }
    if (*demo_cmd) return pc::run_demo(demo);
    if (*generate_cmd) return pc::run_generate(generate);
    if (*compare_cmd) {
      if (!compare_background.empty()) {
        compare.background = parse_rgb8(compare_background, "--background");
      }
      return pc::run_compare(compare);
    }
  } catch (const pointillist::Error& e) {
    std::fprintf(stderr, "pointillist: error: %s\n", e.what());
    return 1;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr,
                 "pointillist: error: out of memory; the model is too large for this machine's "
                 "memory (try fewer input files or a machine with more memory)\n");
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pointillist: internal error: %s (please report this)\n", e.what());
    return 2;
  }
  return 0;
}
