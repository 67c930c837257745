// `pointillist simplify`: fewer points for the same surface (prep/simplify.hpp), written as
// points with normals and radii (.ply) or straight into a model (.ptl, .qs) in one command.
#include <CLI/CLI.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>

#include "commands.hpp"
#include "options.hpp"
#include "terminal_progress.hpp"
#include "util.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/io/merge.hpp"
#include "pointillist/lod/sphere_tree.hpp"
#include "pointillist/pipeline/convert.hpp"
#include "pointillist/prep/simplify.hpp"

namespace pointillist::cli {
namespace {

struct SimplifyCommandOptions {
  std::vector<std::string> inputs;
  std::string output;
  std::size_t points = 0;
  double ratio = 0;
  std::string method = "quadric";
  SimplifyOptions simplify;
  ConvertOptions convert;
  unsigned threads = 0;
  bool quiet = false;
};

int run_simplify(SimplifyCommandOptions& o) {
  const auto start = std::chrono::steady_clock::now();
  const std::string ext = lowercase_extension(o.output);
  if (ext != ".ply" && ext != ".ptl" && ext != ".qs") {
    throw OptionError("simplify: the output '" + o.output +
                      "' must end in .ply (points with normals and radii), .ptl or .qs");
  }
  const bool by_cell_size = o.simplify.voxel_size > 0 && o.points == 0 && o.ratio == 0;
  if (by_cell_size && o.method != "voxel" && o.method != "voxel-nearest") {
    throw OptionError("simplify: --voxel-size sets the size of the result for --method voxel or "
                      "voxel-nearest only; give --points N or --ratio R");
  }
  if (!by_cell_size && (o.points > 0) == (o.ratio > 0)) {
    throw OptionError("simplify: give the size of the result with one of --points N or --ratio R "
                      "(or, for the voxel methods, --voxel-size S)");
  }
  if (o.ratio > 0 && !(o.ratio <= 1)) {
    throw OptionError("simplify: --ratio must be in (0, 1], the share of the points to keep");
  }
  // The hierarchy's own interior nodes, as a simplification to measure the others against.
  const bool tree_cut = o.method == "qsplat-cut";
  if (!tree_cut) o.simplify.method = parse_simplify_method(o.method);
  ThreadPool pool(o.threads);
  TerminalProgress progress(!o.quiet && TerminalProgress::stderr_is_terminal());
  std::vector<std::string> warnings;
  PointSet points = merge_inputs(o.inputs, pool, progress, {.columns = o.convert.columns}, &warnings);
  for (const auto& w : warnings) std::fprintf(stderr, "pointillist simplify: warning: %s\n", w.c_str());
  const std::size_t input_points = points.size();
  o.simplify.target =
      by_cell_size ? input_points  // not used: the cell size decides
      : o.points > 0 ? o.points
                     : std::max<std::size_t>(1, static_cast<std::size_t>(
                                                    std::llround(o.ratio * double(input_points))));
  PrepareOptions prepare = o.convert.prepare;
  prepare.input_name = input_names(o.inputs);
  prepare_splats(points, pool, progress, prepare);  // normals (the radii are not kept)
  SimplifyReport report;
  PointSet simplified;
  if (tree_cut) {
    simplified = sphere_tree_cut(build_sphere_tree(points, pool, progress), o.simplify.target);
    simplified.comments = points.comments;
    simplified.origin = points.origin;
    simplified.up = points.up;
    report.output = simplified.size();
  } else {
    simplified = simplify_points(points, o.simplify, pool, progress, &report, prepare.input_name);
  }
  points = PointSet{};
  const double simplify_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // The new points keep the normals and radii simplify_points gave them (the hierarchy's nodes
  // their spheres'); --radius-scale scales the radii as it does a file's.
  ConvertOptions convert = o.convert;
  convert.prepare.normals = NormalSource::Keep;
  const ConvertResult r = convert_points(std::move(simplified), o.inputs, o.output, convert, pool,
                                         progress);
  for (const auto& w : r.warnings) std::fprintf(stderr, "pointillist simplify: warning: %s\n", w.c_str());
  if (!o.quiet) {
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("simplified %zu points to %zu (%s", input_points, report.output,
                tree_cut ? "qsplat-cut" : std::string(simplify_method_name(o.simplify.method)).c_str());
    if (report.voxel_size > 0) std::printf(", cells of %g", double(report.voxel_size));
    std::printf(") in %.2f s, written in %.2f s -> %s\n", simplify_seconds,
                seconds - simplify_seconds, o.output.c_str());
  }
  return 0;
}

}  // namespace

Command add_simplify_command(CLI::App& app) {
  auto o = std::make_shared<SimplifyCommandOptions>();
  auto* cmd = app.add_subcommand(
      "simplify",
      "Reduce a scan to fewer points that describe the same surface, written as points with "
      "normals and radii (.ply) or as a model (.ptl, .qs)");
  cmd->add_option("inputs", o->inputs, "Input files (several are merged)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("-o,--output", o->output, "Output file: .ply, .ptl or .qs")
      ->required()
      ->group(kGroupOutput);
  cmd->add_option("--points", o->points, "Points to keep")->check(CLI::PositiveNumber);
  cmd->add_option("--ratio", o->ratio, "Share of the points to keep, in (0, 1]");
  cmd->add_option("--method", o->method,
                  "quadric (pairs contracted by quadric error: the least error, the default), "
                  "voxel (a centroid per grid cell, as PCL and Open3D), voxel-nearest (the "
                  "point nearest each cell's centroid), hierarchical or incremental "
                  "(clustering), random; or qsplat-cut (the nodes the QSplat hierarchy draws at "
                  "one sphere size, to compare)")
      ->default_val("quadric");
  cmd->add_option("--voxel-size", o->simplify.voxel_size,
                  "voxel methods: the cell side in model units (default: the size that gives "
                  "--points cells)");
  cmd->add_option("--seed", o->simplify.seed, "random: the seed")->default_val(1);
  cmd->add_option("--neighbours", o->simplify.neighbours,
                  "quadric, incremental: nearest neighbours joined in the graph")
      ->default_val(8);
  cmd->add_flag("--ascii", o->convert.ascii, "Write .ply output as ascii")->group(kGroupOutput);
  add_columns(cmd, o->convert.columns);
  add_prepare_options(cmd, o->convert.prepare);
  add_threads(cmd, o->threads);
  cmd->add_flag("-q,--quiet", o->quiet, "No progress bars and no summary");
  return {cmd, [o] { return run_simplify(*o); }};
}

}  // namespace pointillist::cli
