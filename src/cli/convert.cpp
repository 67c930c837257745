// `pointillist convert`: pipeline::convert with a progress bar and a summary line.
#include <chrono>
#include <cstdio>
#include <filesystem>

#include "commands.hpp"
#include "terminal_progress.hpp"
#include "util.hpp"
#include "pointillist/pipeline/convert.hpp"

namespace pointillist::cli {

int run_convert(const ConvertCommandOptions& o) {
  const auto start = std::chrono::steady_clock::now();
  ThreadPool pool(o.threads);
  TerminalProgress progress(!o.quiet && TerminalProgress::stderr_is_terminal());
  const ConvertResult r = convert(o.inputs, o.output, o.convert, pool, progress);
  for (const auto& w : r.warnings) {
    std::fprintf(stderr, "pointillist convert: warning: %s\n", w.c_str());
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!o.quiet) {
    if (o.convert.prepare.drop_outliers) {
      std::printf("dropped %zu outliers of %zu points\n", r.input_points - r.output_points,
                  r.input_points);
    }
    const double size = double(std::filesystem::file_size(o.output));
    const std::size_t n = r.input_points;
    std::printf("converted %zu points in %.2f s (%.2f M points/s) -> %s, %s, %.1f bytes/point\n",
                n, seconds, n / seconds / 1e6, o.output.c_str(), human_bytes(size).c_str(),
                n ? size / double(n) : 0.0);
  }
  return 0;
}

}  // namespace pointillist::cli
