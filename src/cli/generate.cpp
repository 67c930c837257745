#include <cstdio>
#include <memory>

#include "commands.hpp"
#include "options.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/io/ply.hpp"
#include "pointillist/prep/radii.hpp"
#include "pointillist/scene/analytic.hpp"
#include "pointillist/scene/csg.hpp"

namespace pointillist::cli {

namespace {

// Eight well-separated face colours (spec §4.1), so that any blending of two faces shows.
constexpr Rgb8 kPalette[8] = {{230, 25, 75},  {60, 180, 75},  {0, 130, 200}, {255, 225, 25},
                              {245, 130, 48}, {145, 30, 180}, {70, 240, 240}, {240, 50, 230}};

// A CSG test scene of the sharp-features spec: exact normals, a colour per face; J-mode samples
// also get the dissertation's radius (the mean distance to the 5 nearest), R-mode ones none
// (scan preparation gives them Pointillist's default).
int generate_csg(const GenerateOptions& o) {
  const CsgScene scene = csg_scene(o.scene);
  const bool jittered = o.sampling == "j";
  CsgSamples s = sample_csg(scene, jittered ? SamplingMode::Jittered : SamplingMode::Random, o.seed);
  for (std::uint32_t label : s.labels) s.points.colors.push_back(kPalette[label % 8]);
  if (jittered) {
    ThreadPool pool(o.threads);
    CloudRadiusOptions radius;
    radius.coverage = 1.0f;
    s.points.radii = cloud_radii(s.points.positions, pool, Progress::none(), radius);
  }
  write_ply(o.output, s.points);
  if (!o.quiet) {
    std::printf("generated %zu samples of test scene %s (%s sampling, exact normals, a colour "
                "per face) -> %s\n",
                s.points.size(), o.scene.c_str(), jittered ? "jittered grid" : "random",
                o.output.c_str());
  }
  return 0;
}

}  // namespace

int run_generate(const GenerateOptions& o) {
  if (!o.scene.empty() && o.scene[0] == 'T') return generate_csg(o);
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
  std::vector<std::string> scenes = {"demo", "sphere", "torus", "cube"};
  for (const std::string& id : csg_scene_ids()) scenes.push_back(id);
  cmd->add_option("--scene", o->scene,
                  "demo, sphere, torus or cube; or a sharp-features test scene T1 (cube), T3 "
                  "(cylinder), T4 (plate with a hole), T5/T6 (union/intersection of two "
                  "spheres), T7 (bitten cube), T8 (step), T9 (two interpenetrating spheres), "
                  "T10 (crossed cylinders), T11 (thin slab), T13 (sphere)")
      ->default_val("demo")
      ->check(CLI::IsMember(scenes));
  cmd->add_option("--sampling", o->sampling,
                  "Test scenes T*: j (jittered grid at the scene's spacing, radius = mean "
                  "distance to 5 nearest) or r (as many random samples, default radii)")
      ->default_val("j")
      ->check(CLI::IsMember({"j", "r"}));
  cmd->add_option("--points", o->points, "Number of samples (test scenes T*: set by the scene)")
      ->default_val(1000000)
      ->check(CLI::Range(std::size_t{1}, std::size_t{2'000'000'000}));
  cmd->add_option("--seed", o->seed, "Random seed")->default_val(1);
  cmd->add_flag("--with-normals", o->with_normals, "Also write exact normals");
  add_threads(cmd, o->threads);
  cmd->add_flag("-q,--quiet", o->quiet, "No summary line");
  return {cmd, [o] { return run_generate(*o); }};
}

}  // namespace pointillist::cli
