#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "commands.hpp"
#include "options.hpp"
#include "util.hpp"
#include "terminal_progress.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/core/model_cache.hpp"
#include "pointillist/io/ply.hpp"
#include "pointillist/pipeline/convert.hpp"
#include "pointillist/pipeline/model.hpp"
#include "pointillist/io/png.hpp"
#include "pointillist/scene/analytic.hpp"

namespace pointillist::cli {

namespace {

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

struct DemoView {
  const char* name;
  float azimuth_deg, elevation_deg;
};

// Converts `input` to `output` (.ptl) and prints one summary row.
void convert_for_demo(const std::string& input, const std::string& output, ThreadPool& pool,
                      Progress& progress) {
  const auto start = std::chrono::steady_clock::now();
  const std::string inputs[] = {input};
  const std::size_t points = convert(inputs, output, {}, pool, progress).output_points;
  const double s = seconds_since(start);
  std::printf("  convert %-28s %9zu points  %7.3f s  %6.2f M points/s  %5.1f bytes/point\n",
              std::filesystem::path(input).filename().c_str(), points, s, points / s / 1e6,
              double(std::filesystem::file_size(output)) / double(points));
}

void render_views(const std::string& model_path, const std::string& stem,
                  const std::filesystem::path& dir, const std::vector<DemoView>& views,
                  const std::vector<SplatShape>& shapes, ThreadPool& pool) {
  OpenModelOptions open;
  open.paging = Paging::Never;
  const Model model = open_model(model_path, open, pool, Progress::none());
  Frame frame;
  for (const DemoView& v : views) {
    const Camera camera = orbit_camera(
        model.tree().view_sphere,
        {.azimuth_deg = v.azimuth_deg, .elevation_deg = v.elevation_deg, .width = 1280,
         .height = 720});
    for (SplatShape shape : shapes) {
      RenderSettings settings;
      settings.shape = shape;
      settings.background = {24, 26, 32};
      render(model.tree(), camera, settings, pool, frame);
      const std::string file = stem + "_" + v.name + "_" + name(shape) + ".png";
      write_png_rgb8((dir / file).string(), frame.width, frame.height, frame.color);
      std::printf("  render  %-38s %9llu splats  %7.2f ms  %6.1f M splats/s\n", file.c_str(),
                  static_cast<unsigned long long>(frame.stats.splats), frame.stats.ms_total,
                  frame.stats.splats / frame.stats.ms_total / 1e3);
    }
  }
}

}  // namespace

int run_demo(const DemoOptions& o) {
  const std::filesystem::path dir(o.out_dir);
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) {
    throw IoError(o.out_dir + ": cannot create the demo output folder (" + ec.message() +
                  "); choose another with --out");
  }
  ThreadPool pool(o.threads);
  TerminalProgress progress(!o.quiet && TerminalProgress::stderr_is_terminal());
  std::printf("Pointillist demo -> %s (%u threads)\n", o.out_dir.c_str(), pool.thread_count());

  // The built-in scene: analytic sphere, torus and sharp-edged cube sampled without normals, so
  // the whole pipeline runs (PCA normals, orientation, radii, hierarchy, rendering).
  const auto scene_ply = (dir / "demo-scene.ply").string();
  const auto scene_ptl = (dir / "demo-scene.ptl").string();
  {
    const SurfaceSamples samples = sample_scene(demo_scene(), o.points, 2024);
    write_ply(scene_ply, samples.points);
  }
  convert_for_demo(scene_ply, scene_ptl, pool, progress);
  const std::vector<DemoView> scene_views{{"front", 0, 15}, {"left", -50, 25}, {"top", 30, 60}};
  render_views(scene_ptl, "scene", dir, scene_views,
               {SplatShape::Square, SplatShape::Circle, SplatShape::Ellipse}, pool);

  const auto dragon = cached_model_path("dragon_vrip.ply.gz");
  if (!dragon.empty()) {
    const auto dragon_ptl = (dir / "dragon.ptl").string();
    convert_for_demo(dragon, dragon_ptl, pool, progress);
    render_views(dragon_ptl, "dragon", dir, {{"front", 0, 10}, {"side", 90, 10}, {"back", 200, 30}},
                 {SplatShape::Circle, SplatShape::Ellipse}, pool);
  } else {
    std::printf("  (run scripts/fetch-models.sh to include the Stanford dragon)\n");
  }
  std::printf("images written to %s\n", o.out_dir.c_str());
  return 0;
}

Command add_demo_command(CLI::App& app) {
  auto o = std::make_shared<DemoOptions>();
  auto* cmd = app.add_subcommand(
      "demo", "Generate the built-in analytic scene, convert it, render views with every kernel "
              "(and the Stanford dragon when fetched)");
  cmd->add_option("--out", o->out_dir, "Output folder")->default_val("demo-out");
  cmd->add_option("--points", o->points, "Samples in the generated scene")
      ->default_val(400000)
      ->check(CLI::Range(std::size_t{100}, std::size_t{200'000'000}));
  add_threads(cmd, o->threads);
  cmd->add_flag("-q,--quiet", o->quiet, "No progress bars");
  return {cmd, [o] { return run_demo(*o); }};
}

}  // namespace pointillist::cli
