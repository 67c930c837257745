#include <cstdio>
#include <memory>

#include "commands.hpp"
#include "options.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/io/ply.hpp"
#include "pointillist/scene/analytic.hpp"

namespace pointillist::cli {

int run_generate(const GenerateOptions& o) {
  AnalyticScene scene;
  if (o.scene == "demo") {
    scene = demo_scene();
  } else if (o.scene == "sphere") {
    scene = sphere_scene();
  } else if (o.scene == "torus") {
    scene = torus_scene();
  } else if (o.scene == "cube") {
    scene = cube_scene();
  } else {
    throw OptionError("generate: unknown scene '" + o.scene + "'; use demo, sphere, torus or cube");
  }
  SurfaceSamples samples = sample_scene(scene, o.points, o.seed);
  if (o.with_normals) samples.points.normals = samples.true_normals;
  write_ply(o.output, samples.points);
  if (!o.quiet) {
    std::printf("generated %zu samples of the %s scene%s -> %s\n", samples.points.size(),
                o.scene.c_str(), o.with_normals ? " with exact normals" : "", o.output.c_str());
  }
  return 0;
}

Command add_generate_command(CLI::App& app) {
  auto o = std::make_shared<GenerateOptions>();
  auto* cmd = app.add_subcommand(
      "generate", "Write a point cloud sampled from an analytic scene (for tests and benchmarks)");
  cmd->add_option("-o,--output", o->output, "Output .ply")->required();
  cmd->add_option("--scene", o->scene, "demo, sphere, torus or cube")
      ->default_val("demo")
      ->check(CLI::IsMember({"demo", "sphere", "torus", "cube"}));
  cmd->add_option("--points", o->points, "Number of samples")
      ->default_val(1000000)
      ->check(CLI::Range(std::size_t{1}, std::size_t{2'000'000'000}));
  cmd->add_option("--seed", o->seed, "Random seed")->default_val(1);
  cmd->add_flag("--with-normals", o->with_normals, "Also write exact normals");
  cmd->add_flag("-q,--quiet", o->quiet, "No summary line");
  return {cmd, [o] { return run_generate(*o); }};
}

}  // namespace pointillist::cli
