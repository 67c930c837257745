#include "terminal_progress.hpp"

#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
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

TerminalProgress::TerminalProgress(bool enabled, std::FILE* out, int width)
    : enabled_(enabled), out_(out), width_(width) {}

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
  detail_.clear();
}

void TerminalProgress::overall(std::uint64_t done, std::uint64_t total) {
  overall_done_ = done;
  overall_total_ = total;
}

void TerminalProgress::detail(std::string_view text) {
  std::lock_guard lock(draw_mutex_);
  detail_ = std::string(text);
}

void TerminalProgress::draw(bool final_line) {
  const auto now = std::chrono::steady_clock::now();
  const double seconds = std::chrono::duration<double>(now - phase_start_).count();
  const std::uint64_t done = done_.load();
  const auto bar = [](double fraction, int width) {
    std::string b(std::size_t(width), '.');
    const int filled = int(std::min(1.0, fraction) * width + 0.5);
    for (int i = 0; i < filled; ++i) b[std::size_t(i)] = '#';
    return b;
  };
  double fraction = total_ > 0 ? double(done) / double(total_) : 0.0;
  if (final_line) fraction = 1.0;
  fraction = std::min(fraction, 1.0);
  char text[256];
  std::string line;
  if (total_ > 0 || final_line) {
    std::snprintf(text, sizeof text, "  %-12s [%s] %3d%%  %6.2f s", phase_.c_str(),
                  bar(fraction, 30).c_str(), int(fraction * 100.0 + 0.5), seconds);
  } else {
    std::snprintf(text, sizeof text, "  %-12s %6.2f s", phase_.c_str(), seconds);
  }
  line = text;
  const std::uint64_t all = overall_total_.load(), all_done = overall_done_.load();
  if (all > 0 && !final_line) {
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    const double f = std::min(1.0, double(all_done) / double(all));
    const double rate = elapsed > 0 ? double(all_done) / elapsed : 0.0;
    std::string eta = "--";
    if (f > 0.001) {
      const auto left = static_cast<long long>(elapsed * (1.0 - f) / f + 0.5);
      std::snprintf(text, sizeof text, left >= 3600 ? "%lld h %02lld min" : "%lld min %02lld s",
                    left >= 3600 ? left / 3600 : left / 60,
                    left >= 3600 ? (left % 3600) / 60 : left % 60);
      eta = text;
    }
    std::snprintf(text, sizeof text, "  | all [%s] %3d%%  %.2f M points/s  %s left",
                  bar(f, 15).c_str(), int(f * 100.0 + 0.5), rate / 1e6, eta.c_str());
    line += text;
  }
  if (!detail_.empty() && !final_line) line += "  " + detail_;
  // Cut to the terminal's width (a wrapped line would not be redrawn in place).
  int width = width_;
  if (width <= 0) {
    struct winsize ws {};
    width = ::ioctl(STDERR_FILENO, TIOCGWINSZ, &ws) == 0 && ws.ws_col > 0 ? ws.ws_col : 80;
  }
  if (int(line.size()) > width - 1) line.resize(std::size_t(std::max(width - 1, 0)));
  std::fprintf(out_, "\r%s\033[K%s", line.c_str(), final_line ? "\n" : "");
  std::fflush(out_);
}

}  // namespace pointillist::cli
