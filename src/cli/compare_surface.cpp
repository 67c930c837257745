// `pointillist compare-surface`: how far a set of splats lies from a reference surface (a mesh,
// the original points' local planes, or an analytic scene of `generate`): forward and backward
// distances, Hausdorff, holes and normal error (eval/surface_error.hpp).
#include <CLI/CLI.hpp>

#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "options.hpp"
#include "terminal_progress.hpp"
#include "util.hpp"
#include "pointillist/core/atomic_file.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/eval/surface_error.hpp"
#include "pointillist/io/merge.hpp"
#include "pointillist/prep/radii.hpp"

namespace pointillist::cli {
namespace {

struct CompareSurfaceOptions {
  std::string splats;
  std::string reference;        // a file
  std::string reference_scene;  // or sphere|torus|cube|demo
  std::size_t samples = 2'000'000;
  std::uint32_t k = 16;
  double hole_tolerance = 0.01;
  std::string json;  // also write the figures here ("-": standard output, instead of the table)
  unsigned threads = 0;
};

// The figures as JSON, distances in units of 1e-3 of the diagonal as in the table.
void write_json(const SurfaceError& e, const std::string& path) {
  const double unit = e.diagonal / 1000.0;
  const auto stats = [&](const DistanceStats& d) {
    return nlohmann::json{{"max", d.max / unit}, {"mean", d.mean / unit}, {"rms", d.rms / unit}};
  };
  const nlohmann::json j = {{"splats", e.splats},
                            {"samples", e.samples},
                            {"diagonal", e.diagonal},
                            {"forward", stats(e.forward)},
                            {"backward", stats(e.backward)},
                            {"hausdorff", e.hausdorff / unit},
                            {"hole_fraction", e.hole_fraction},
                            {"normal_mean_deg", e.normal_mean_deg},
                            {"normal_p95_deg", e.normal_p95_deg}};
  if (path == "-") {
    std::printf("%s\n", j.dump(2).c_str());
    return;
  }
  AtomicFile out(path);
  out.write(j.dump(2) + "\n");
  out.commit();
}

SurfaceReference load_reference(const CompareSurfaceOptions& o, ThreadPool& pool,
                                Progress& progress, std::string& described) {
  if (!o.reference_scene.empty()) {
    const std::string& s = o.reference_scene;
    described = "the analytic " + s + " of generate --scene " + s;
    if (s == "sphere") return SurfaceReference::analytic(sphere_scene());
    if (s == "torus") return SurfaceReference::analytic(torus_scene());
    if (s == "cube") return SurfaceReference::analytic(cube_scene());
    if (s == "demo") return SurfaceReference::analytic(demo_scene());
    throw OptionError("compare-surface: unknown --reference-scene '" + s +
                      "'; use sphere, torus, cube or demo");
  }
  const std::vector<std::string> paths = {o.reference};
  const PointSet ref = merge_inputs(paths, pool, progress, {});
  if (ref.is_mesh()) {
    described = o.reference + " (" + std::to_string(ref.triangles.size()) + " triangles)";
    return SurfaceReference::mesh(ref.positions, ref.triangles, pool);
  }
  described = o.reference + " (" + std::to_string(ref.size()) + " points, local planes of " +
              std::to_string(o.k) + " neighbours)";
  return SurfaceReference::points(ref.positions, pool, o.k);
}

int run_compare_surface(const CompareSurfaceOptions& o) {
  if (o.reference.empty() == o.reference_scene.empty()) {
    throw OptionError("compare-surface: give the reference with one of --reference FILE or "
                      "--reference-scene sphere|torus|cube|demo");
  }
  if (o.samples == 0) throw OptionError("compare-surface: --samples must be at least 1");
  ThreadPool pool(o.threads);
  TerminalProgress progress(TerminalProgress::stderr_is_terminal());
  const std::vector<std::string> paths = {o.splats};
  PointSet splats = merge_inputs(paths, pool, progress, {});
  if (!splats.has_normals()) {
    throw Error(o.splats + " has no normals: compare the output of `simplify` or `convert -o "
                "X.ply`, which carry normals and radii");
  }
  const bool own_radii = splats.has_radii();
  if (!own_radii) splats.radii = cloud_radii(splats.positions, pool, progress);
  std::string described;
  const SurfaceReference reference = load_reference(o, pool, progress, described);
  SurfaceErrorOptions options;
  options.backward_samples = o.samples;
  options.hole_tolerance = o.hole_tolerance;
  const SurfaceError e =
      surface_error(reference, splats.positions, splats.normals, splats.radii, pool, options);
  if (!o.json.empty()) write_json(e, o.json);
  if (o.json == "-") return 0;
  const double unit = e.diagonal / 1000.0;
  std::printf("%s: %zu splats (%s) against %s, %zu reference samples; distances in 1e-3 of the "
              "reference's diagonal (%g)\n",
              o.splats.c_str(), e.splats, own_radii ? "their own radii" : "radii from spacing",
              described.c_str(), e.samples, e.diagonal);
  std::printf("  forward:   max %.4f  mean %.4f  rms %.4f\n", e.forward.max / unit,
              e.forward.mean / unit, e.forward.rms / unit);
  std::printf("  backward:  max %.4f  mean %.4f  rms %.4f\n", e.backward.max / unit,
              e.backward.mean / unit, e.backward.rms / unit);
  std::printf("  hausdorff: %.4f\n", e.hausdorff / unit);
  std::printf("  holes:     %.4f %% of the samples (no disc within %g of the diagonal)\n",
              100.0 * e.hole_fraction, o.hole_tolerance);
  std::printf("  normals:   mean %.2f deg, 95th percentile %.2f deg\n", e.normal_mean_deg,
              e.normal_p95_deg);
  return 0;
}

}  // namespace

Command add_compare_surface_command(CLI::App& app) {
  auto o = std::make_shared<CompareSurfaceOptions>();
  auto* cmd = app.add_subcommand(
      "compare-surface",
      "Measure how far splats (a .ply with normals and radii, e.g. from simplify) lie from a "
      "reference surface: forward and backward distances, Hausdorff, holes, normal error");
  cmd->add_option("splats", o->splats, "Points with normals (and radii) to measure")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--reference", o->reference,
                  "The reference: a mesh (its triangles) or a point cloud (its points' local "
                  "planes)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--reference-scene", o->reference_scene,
                  "Or an analytic scene of generate --scene: sphere, torus, cube or demo (exact "
                  "distances)");
  cmd->add_option("--samples", o->samples,
                  "Reference samples for the backward distance and the holes")
      ->default_val(2'000'000);
  cmd->add_option("--neighbours", o->k, "Point-cloud reference: neighbours of each local plane")
      ->default_val(16);
  cmd->add_option("--hole-tolerance", o->hole_tolerance,
                  "A disc covers a sample within this share of the diagonal from its plane")
      ->default_val(0.01);
  cmd->add_option("--json", o->json,
                  "Also write the figures as JSON to this file (- : to standard output, instead "
                  "of the table)");
  add_threads(cmd, o->threads);
  return {cmd, [o] { return run_compare_surface(*o); }};
}

}  // namespace pointillist::cli
