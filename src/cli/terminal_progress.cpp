#include "terminal_progress.hpp"

#include <unistd.h>

#include <cstdio>

namespace pointillist::cli {
namespace {

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

}  // namespace

TerminalProgress::TerminalProgress(bool enabled) : enabled_(enabled) {}

TerminalProgress::~TerminalProgress() = default;

bool TerminalProgress::stderr_is_terminal() { return ::isatty(STDERR_FILENO) == 1; }

void TerminalProgress::begin_phase(std::string_view name, std::uint64_t total) {
  // Nested phases (a phase begun inside another) are shown as the innermost one.
  std::lock_guard lock(draw_mutex_);
  ++depth_;
  phase_ = std::string(name);
  total_ = total;
  done_ = 0;
  phase_start_ = std::chrono::steady_clock::now();
  next_draw_ns_ = 0;
}

void TerminalProgress::advance(std::uint64_t units) {
  done_ += units;
  if (!enabled_) return;
  const std::int64_t now = now_ns();
  std::int64_t due = next_draw_ns_.load(std::memory_order_relaxed);
  // Only the thread that wins the exchange draws; the others return at once.
  if (now >= due && next_draw_ns_.compare_exchange_strong(due, now + 66'000'000)) {
    std::unique_lock lock(draw_mutex_, std::try_to_lock);
    if (lock.owns_lock()) draw(false);
  }
}

void TerminalProgress::end_phase() {
  std::lock_guard lock(draw_mutex_);
  if (enabled_ && depth_ > 0) draw(true);
  if (depth_ > 0) --depth_;
}

void TerminalProgress::draw(bool final_line) {
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - phase_start_).count();
  const std::uint64_t done = done_.load();
  constexpr int kWidth = 30;
  char bar[kWidth + 1];
  double fraction = total_ > 0 ? double(done) / double(total_) : 0.0;
  if (final_line) fraction = 1.0;
  if (fraction > 1.0) fraction = 1.0;
  const int filled = int(fraction * kWidth + 0.5);
  for (int i = 0; i < kWidth; ++i) bar[i] = i < filled ? '#' : '.';
  bar[kWidth] = '\0';
  if (total_ > 0 || final_line) {
    std::fprintf(stderr, "\r  %-12s [%s] %3d%%  %6.2f s%s", phase_.c_str(), bar,
                 int(fraction * 100.0 + 0.5), seconds, final_line ? "\n" : "");
  } else {
    std::fprintf(stderr, "\r  %-12s %6.2f s", phase_.c_str(), seconds);
  }
  std::fflush(stderr);
}

}  // namespace pointillist::cli
