// `pointillist convert`: pipeline::convert with a progress bar and a summary line.
#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>

#include "commands.hpp"
#include "options.hpp"
#include "terminal_progress.hpp"
#include "util.hpp"
#include "pointillist/pipeline/chunk_jobs.hpp"
#include "pointillist/pipeline/convert.hpp"

namespace pointillist::cli {

ChunkJobs*& mpi_job() {
  static ChunkJobs* job = nullptr;
  return job;
}

int run_convert(const ConvertCommandOptions& o) {
  keep_freed_memory();
  const auto start = std::chrono::steady_clock::now();
  ThreadPool pool(o.threads);
  ConvertOptions options = o.convert;
  options.jobs = mpi_job();
  options.prefault = true;  // freed memory is kept (above)
  // Under mpirun, rank 0 speaks for the job.
  const bool lead = options.jobs == nullptr || options.jobs->rank() == 0;
  const bool quiet = o.quiet || !lead;
  TerminalProgress progress(!quiet && TerminalProgress::stderr_is_terminal());
  const ConvertResult r = convert(o.inputs, o.output, options, pool, progress);
  for (const auto& w : r.warnings) {
    if (lead) std::fprintf(stderr, "pointillist convert: warning: %s\n", w.c_str());
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!quiet) {
    if (o.convert.prepare.drop_outliers) {
      std::printf("dropped %zu outliers of %zu points\n", r.input_points - r.output_points,
                  r.input_points);
    }
    const double size = double(std::filesystem::file_size(o.output));
    const std::size_t n = r.input_points;
    std::printf("converted %zu points in %.2f s (%.2f M points/s) -> %s, %s, %.1f bytes/point\n",
                n, seconds, n / seconds / 1e6, o.output.c_str(), human_bytes(size).c_str(),
                n ? size / double(n) : 0.0);
    struct rusage usage {};
    ::getrusage(RUSAGE_SELF, &usage);
    const double peak = double(usage.ru_maxrss) * 1024.0;
    if (r.chunks > 0 && options.jobs != nullptr && options.jobs->size() > 1) {
      std::printf("in %zu chunks (%.1f%% halo points) on %d MPI ranks, peak memory of rank 0 %s "
                  "(%.0f bytes/point)\n",
                  r.chunks, n ? 100.0 * double(r.halo_points) / double(n) : 0.0,
                  options.jobs->size(), human_bytes(peak).c_str(), n ? peak / double(n) : 0.0);
    } else if (r.chunks > 0) {
      std::printf("in %zu chunks (%.1f%% halo points), peak memory %s (%.0f bytes/point)\n",
                  r.chunks, n ? 100.0 * double(r.halo_points) / double(n) : 0.0,
                  human_bytes(peak).c_str(), n ? peak / double(n) : 0.0);
    } else {
      std::printf("in one piece, peak memory %s (%.0f bytes/point)\n", human_bytes(peak).c_str(),
                  n ? peak / double(n) : 0.0);
    }
    if (!r.phase_seconds.empty()) {
      std::string line = "phases:";
      for (std::size_t i = 0; i < r.phase_seconds.size(); ++i) {
        char part[64];
        const double t = r.phase_seconds[i].second;
        std::snprintf(part, sizeof part, t < 10 ? "%s %s %.2f s" : "%s %s %.1f s", i ? "," : "",
                      r.phase_seconds[i].first.c_str(), t);
        line += part;
      }
      std::printf("%s\n", line.c_str());
    }
  }
  return 0;
}

Command add_convert_command(CLI::App& app) {
  auto o = std::make_shared<ConvertCommandOptions>();
  auto* cmd = app.add_subcommand(
      "convert", "Convert scans (PLY, XYZ/PTS/CSV, OBJ, LAS; .gz too) into a splat model (.ptl, "
                 ".qs) or points with normals and radii (.ply)");
  cmd->add_option("inputs", o->inputs, "Input files (several are merged)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("-o,--output", o->output,
                  "Output file: .ptl (Pointillist model), .qs (QSplat 1.1 model) or .ply")
      ->required()
      ->group(kGroupOutput);
  cmd->add_option("--ptl-version", o->convert.ptl_version,
                  ".ptl version to write: 2 (quantized, paged; the default) or 1 (float nodes, 40 "
                  "bytes each)")
      ->default_val(2)
      ->group(kGroupOutput);
  auto trim = std::make_shared<quant::LeafTrim>();
  CLI::Option* trim_option = add_enum<quant::LeafTrim>(cmd, "--leaf-trim", *trim,
                            {{"sixteenths", quant::LeafTrim::Sixteenths},
                             {"eighths", quant::LeafTrim::Eighths}},
                            ".ptl v2: steps in which leaves keep their radius trim: sixteenths "
                            "(the default, tighter splats) or eighths (files that Pointillist "
                            "before 2026-11-24 reads)");
  trim_option->group(kGroupOutput);
  cmd->add_flag("--ascii", o->convert.ascii, "Write .ply output as ascii")->group(kGroupOutput);
  cmd->add_flag("--no-faces{false}", o->convert.keep_faces,
                ".ptl v2 of a mesh: leave out its faces (kept by default, about 5 bytes a "
                "triangle, for render --lod spt --hybrid)")
      ->group(kGroupOutput);
  auto features = std::make_shared<FeatureOptions>();
  auto with_features = std::make_shared<bool>(false);
  cmd->add_flag("--features", *with_features,
                    ".ptl v2: find the sharp edges, corners and intersecting surfaces and store "
                    "them (render draws them)")
          ->group(kGroupOutput);
  CLI::Option* threshold = add_sharp_threshold(cmd, *features)->group(kGroupOutput);
  add_enum<EdgeTest>(cmd, "--edge-test", features->edge_test,
                     {{"side", EdgeTest::Side}, {"linsen", EdgeTest::Linsen}},
                     "With --features: side (per pair) or linsen (angular gap)", "side")
      ->group(kGroupOutput);
  auto memory = std::make_shared<std::string>();
  cmd->add_option("--memory", *memory,
                  "Memory the conversion may use (e.g. 8G, 500M; at least 40M; default: half "
                  "of the physical memory). Scans that need more are converted to .ptl in "
                  "chunks (a mesh over the budget at 56 bytes a vertex streams its faces)");
  cmd->add_option("--chunk-points", o->convert.chunk_points,
                  ".ptl: convert in chunks of at most this many points, whatever the memory");
  add_columns(cmd, o->convert.columns);
  add_prepare_options(cmd, o->convert.prepare);
  add_threads(cmd, o->threads);
  cmd->add_flag("-q,--quiet", o->quiet, "No progress bars and no summary");
  return {cmd, [o, trim, trim_option, features, with_features, memory, threshold] {
            if (trim_option->count() > 0) o->convert.leaf_trim = *trim;
            features->adapt_threshold = threshold->count() == 0;
            if (*with_features) o->convert.features = *features;
            if (!memory->empty()) {
              o->convert.memory_budget = parse_bytes(*memory, "--memory");
              if (o->convert.memory_budget < kLeastMemoryBudget) {
                const std::string least = std::to_string(kLeastMemoryBudget >> 20) + "M";
                throw OptionError("convert: --memory " + *memory + " is below " + least +
                                  ", the least a conversion can hold itself to (the program and "
                                  "its smallest buffers take 30-35 MB); give --memory " + least +
                                  " or more");
              }
            }
            return run_convert(*o);
          }};
}

}  // namespace pointillist::cli
