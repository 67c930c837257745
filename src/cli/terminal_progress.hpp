// A progress bar on stderr for long work: one line per phase, redrawn at most ~15 times a second,
// only when stderr is a terminal (nothing in pipes, CI logs or with --quiet). With overall
// progress (a chunked conversion), the line also shows the whole job's bar, its throughput in
// points/s and the time left; a phase's detail (the file being read) follows. Lines are cut to
// the terminal's width.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdio>
#include <mutex>
#include <string>

#include "pointillist/core/progress.hpp"

namespace pointillist::cli {

class TerminalProgress final : public Progress {
 public:
  // enabled = false makes it silent (use for --quiet and non-terminals).
  explicit TerminalProgress(bool enabled);
  // Draws to `out`, lines cut to `width` columns (tests).
  TerminalProgress(bool enabled, std::FILE* out, int width);
  ~TerminalProgress() override;

  void begin_phase(std::string_view name, std::uint64_t total) override;
  void advance(std::uint64_t units) override;
  void end_phase() override;
  void overall(std::uint64_t done, std::uint64_t total) override;
  void detail(std::string_view text) override;

  // True when stderr is a terminal.
  static bool stderr_is_terminal();

 private:
  void draw(bool final_line);

  bool enabled_;
  std::FILE* out_ = stderr;
  int width_ = 0;  // columns; 0: the terminal's, asked at each draw
  std::string detail_;
  std::atomic<std::uint64_t> overall_done_{0}, overall_total_{0};
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  std::mutex draw_mutex_;
  std::string phase_;
  std::uint64_t total_ = 0;
  std::atomic<std::uint64_t> done_{0};
  std::atomic<std::int64_t> next_draw_ns_{0};
  std::chrono::steady_clock::time_point phase_start_;
  int depth_ = 0;
};

}  // namespace pointillist::cli
