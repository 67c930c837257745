// The overall progress of a chunked conversion (private to pipeline; see chunked_convert.cpp).
#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "pointillist/core/progress.hpp"

namespace pointillist::chunking {

// The phases of a chunked conversion, each with its share of the whole job's time (estimates
// from the profile of a 10 M-point run, where preparing the chunks, their neighbours, normals
// and radii, is most of it), as one overall figure in points: phase names and totals go to
// `inner` as they are.
// The outlier pass of --drop-outliers: its scan, plan and distribute, and the outliers phase.
constexpr double kOutlierPassShare = 0.03 + 0.03 + 0.05 + 0.10;
// --features: found after the rest, part by part (measured about 4 times the rest's time).
constexpr double kFeaturePassShare = 4.0;

class OverallProgress final : public Progress {
 public:
  // `extra_share`: phases that run on top of the usual ones (the outlier pass: its scan, plan,
  // distribute and outliers phases), as a share of the usual whole.
  OverallProgress(Progress& inner, std::uint64_t points, double extra_share = 0.0)
      : inner_(inner), points_(points), whole_(1.0 + extra_share) {}
  void begin_phase(std::string_view name, std::uint64_t total) override {
    inner_.begin_phase(name, total);
    phase_ = kPhases.size();
    for (std::size_t i = 0; i < kPhases.size(); ++i) {
      if (name == kPhases[i].name) phase_ = i;
    }
    if (depth_++ == 0) {
      top_ = phase_;
      started_ = std::chrono::steady_clock::now();
    }
    total_ = total;
    done_ = 0;
    report();
  }
  void advance(std::uint64_t units) override {
    inner_.advance(units);
    done_ += units;
    report();
  }
  void end_phase() override {
    if (depth_ == 1 && top_ < kPhases.size()) {
      const std::chrono::duration<double> took = std::chrono::steady_clock::now() - started_;
      seconds_.emplace_back(std::string(kPhases[top_].name), took.count());
    }
    depth_ = depth_ > 0 ? depth_ - 1 : 0;
    if (phase_ < kPhases.size()) finished_ += kPhases[phase_].share;
    phase_ = kPhases.size();
    inner_.end_phase();
    report();
  }
  void detail(std::string_view text) override { inner_.detail(text); }
  // The wall time of each top-level phase that ended, in order.
  const std::vector<std::pair<std::string, double>>& phase_seconds() const { return seconds_; }

 private:
  struct Phase {
    std::string_view name;
    double share;
  };
  static constexpr std::array<Phase, 9> kPhases = {{{"outliers", 0.10},
                                                    {"scan", 0.03},
                                                    {"plan", 0.03},
                                                    {"distribute", 0.05},
                                                    {"prepare", 0.55},
                                                    {"orientation", 0.02},
                                                    {"hierarchy", 0.12},
                                                    {"write", 0.20},
                                                    {"features", kFeaturePassShare}}};
  void report() {
    double f = finished_;
    if (phase_ < kPhases.size() && total_ > 0) {
      f += kPhases[phase_].share * std::min(1.0, double(done_.load()) / double(total_));
    }
    inner_.overall(std::uint64_t(std::min(1.0, f / whole_) * double(points_)), points_);
  }
  Progress& inner_;
  std::uint64_t points_;
  double whole_;
  std::size_t phase_ = kPhases.size();
  std::uint64_t total_ = 0;
  std::atomic<std::uint64_t> done_{0};
  double finished_ = 0;
  int depth_ = 0;             // nesting of phases (a plan on disk has its own)
  std::size_t top_ = kPhases.size();  // the outermost phase
  std::chrono::steady_clock::time_point started_;
  std::vector<std::pair<std::string, double>> seconds_;
};

}  // namespace pointillist::chunking
