// Progress reporting for long operations. Library functions take a `Progress&` parameter and
// report phases and work done; the CLI draws a bar on a terminal, tests pass `Progress::none()`.
#pragma once

#include <atomic>
#include <cstdint>
#include <string_view>

namespace pointillist {

class Progress {
 public:
  virtual ~Progress() = default;

  // A new phase named `name` with `total` units of work (0 = unknown) begins.
  virtual void begin_phase(std::string_view name, std::uint64_t total) = 0;
  // `units` more units of the current phase are done. Safe to call from several threads.
  virtual void advance(std::uint64_t units) = 0;
  // The current phase is finished.
  virtual void end_phase() = 0;

  // The whole job across its phases (a chunked conversion): `done` of `total` points' worth of
  // work, for an overall bar with throughput and time left. Default: ignored.
  virtual void overall(std::uint64_t done, std::uint64_t total) {
    (void)done;
    (void)total;
  }
  // What the current phase works on (an input file's name), shown beside it until the phase ends
  // or another detail comes. Default: ignored.
  virtual void detail(std::string_view text) { (void)text; }

  // A sink that ignores everything (stateless, so sharing it is harmless).
  static Progress& none();
};

// RAII helper: begins a phase on construction and ends it on destruction.
class ProgressPhase {
 public:
  ProgressPhase(Progress& progress, std::string_view name, std::uint64_t total)
      : progress_(progress) {
    progress_.begin_phase(name, total);
  }
  ~ProgressPhase() { progress_.end_phase(); }
  ProgressPhase(const ProgressPhase&) = delete;
  ProgressPhase& operator=(const ProgressPhase&) = delete;
  void advance(std::uint64_t units) { progress_.advance(units); }

 private:
  Progress& progress_;
};

}  // namespace pointillist
