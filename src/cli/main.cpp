// The `pointillist` command: each subcommand registers its options (one file each); main parses
// the line, runs the chosen one and turns errors into messages and exit codes: 0 done, 1 the work
// failed (bad input file, I/O), 2 bad usage (options), 3 an internal error.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <memory>
#include <new>
#include <string>
#include <vector>

#include "commands.hpp"
#include "options.hpp"
#include "util.hpp"
#include "pointillist/core/atomic_file.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/pipeline/chunk_jobs.hpp"

namespace pc = pointillist::cli;

int main(int argc, char** argv) {
  pc::use_huge_pages(argv);
  pointillist::remove_temporary_files_on_signals();
  CLI::App app{"Pointillist: multiresolution splat models from 3D scans, rendered fast on the CPU"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "pointillist 0.1.0");
  const std::vector<pc::Command> commands = {
      pc::add_convert_command(app), pc::add_render_command(app),  pc::add_info_command(app),
      pc::add_demo_command(app),    pc::add_generate_command(app), pc::add_compare_command(app),
      pc::add_view_command(app),    pc::add_simplify_command(app), pc::add_compare_surface_command(app)};
  if (const std::string error = pc::unknown_word(app, argc, argv); !error.empty()) {
    std::fprintf(stderr, "pointillist: error: %s\n", error.c_str());
    return 2;
  }
  // Under mpirun with several processes, `convert` shares its chunk jobs among them; the other
  // commands would only repeat each other's work and race on their outputs.
  std::unique_ptr<pointillist::ChunkJobs> job;
  if (pointillist::started_by_mpirun()) {
    if (!pointillist::mpi_built()) {
      std::fprintf(stderr, "pointillist: error: started by mpirun, but this build has no MPI; "
                           "install OpenMPI (scripts/setup.sh) and rebuild, or run without "
                           "mpirun\n");
      return 2;
    }
    if (argc < 2 || std::string(argv[1]) != "convert") {
      std::fprintf(stderr, "pointillist: error: only `convert` runs under mpirun (its chunk "
                           "jobs are shared among the ranks); run the other commands without it\n");
      return 2;
    }
    try {
      job = pointillist::join_mpi_job(&argc, &argv);
    } catch (const pointillist::Error& e) {
      std::fprintf(stderr, "pointillist: error: %s\n", e.what());
      return 1;
    }
    pc::mpi_job() = job.get();
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "pointillist: error: %s\nRun with --help for the options.\n", e.what());
    return 2;
  }
  try {
    for (const pc::Command& c : commands) {
      if (c.app->parsed()) return c.run();
    }
  } catch (const pointillist::PeerFailed&) {
    return 1;  // the rank that failed says why
  } catch (const pointillist::OptionError& e) {
    std::fprintf(stderr, "pointillist: error: %s\n", e.what());
    return 2;
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
    return 3;
  }
  return 0;
}
