// A progress bar on stderr for long work: one line per phase, redrawn at most ~15 times a second,
// only when stderr is a terminal (nothing in pipes, CI logs or with --quiet).
#pragma once

#include <atomic>
#include <chrono>
#include <mutex>
#include <string>

#include "pointillist/core/progress.hpp"

namespace pointillist::cli {

class TerminalProgress final : public Progress {
 public:
  // enabled = false makes it silent (use for --quiet and non-terminals).
  explicit TerminalProgress(bool enabled);
  ~TerminalProgress() override;

  void begin_phase(std::string_view name, std::uint64_t total) override;
  void advance(std::uint64_t units) override;
  void end_phase() override;

  // True when stderr is a terminal.
  static bool stderr_is_terminal();

 private:
  void draw(bool final_line);

  bool enabled_;
  std::mutex draw_mutex_;
  std::string phase_;
  std::uint64_t total_ = 0;
  std::atomic<std::uint64_t> done_{0};
  std::atomic<std::int64_t> next_draw_ns_{0};
  std::chrono::steady_clock::time_point phase_start_;
  int depth_ = 0;
};

}  // namespace pointillist::cli
