// Frame-time control and idle refinement (QSplat, Rusinkiewicz & Levoy 2000, section 4.3).
#include "pointillist/render/frame_control.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "pointillist/core/error.hpp"

namespace pointillist {
namespace {

void check(bool ok, const std::string& what) {
  if (!ok) throw OptionError("frame-time control: " + what);
}

}  // namespace

FrameTimeController::FrameTimeController(const FrameControlOptions& o, float initial)
    : options_(o) {
  check(std::isfinite(o.target_ms) && o.target_ms > 0,
        "target frame time " + std::to_string(o.target_ms) + " ms is invalid; give a positive number of milliseconds");
  check(std::isfinite(o.finest) && o.finest > 0,
        "finest level of detail " + std::to_string(o.finest) + " is invalid; give a positive value (1 px is full detail)");
  check(std::isfinite(o.coarsest) && o.coarsest >= o.finest,
        "coarsest level of detail " + std::to_string(o.coarsest) + " is below the finest " +
            std::to_string(o.finest) + "; give coarsest >= finest");
  check(o.gain > 0 && o.gain <= 1, "gain " + std::to_string(o.gain) + " must be in (0, 1]");
  check(o.spike_gain > 0 && o.spike_gain <= 1,
        "spike gain " + std::to_string(o.spike_gain) + " must be in (0, 1]");
  check(o.spike_ratio > 1 && std::isfinite(o.spike_ratio),
        "spike ratio " + std::to_string(o.spike_ratio) + " must be a finite factor > 1");
  check(o.deadband >= 0 && o.deadband < 1,
        "deadband " + std::to_string(o.deadband) + " must be in [0, 1)");
  check(o.max_step > 1 && std::isfinite(o.max_step),
        "max_step " + std::to_string(o.max_step) + " must be a finite factor > 1");
  check(o.cost_exponent > 0 && std::isfinite(o.cost_exponent),
        "cost exponent " + std::to_string(o.cost_exponent) + " must be positive");
  check(o.min_exponent > 0 && o.max_exponent >= o.min_exponent && std::isfinite(o.max_exponent),
        "exponent bounds [" + std::to_string(o.min_exponent) + ", " +
            std::to_string(o.max_exponent) + "] are invalid; give 0 < min <= max");
  check(std::isfinite(initial), "initial level of detail is not finite");
  parameter_ = std::clamp(initial, o.finest, o.coarsest);
  exponent_ = std::clamp(o.cost_exponent, o.min_exponent, o.max_exponent);
}

void FrameTimeController::report(double frame_ms) {
  if (!std::isfinite(frame_ms) || frame_ms < 0) return;
  const double log_ms = std::log(std::max(frame_ms, 1e-6));
  const double log_p = std::log(static_cast<double>(parameter_));
  const bool spike = has_last_ && std::abs(log_p - last_log_p_) <= 0.02 &&
                     log_ms - last_log_ms_ > std::log(options_.spike_ratio);
  if (has_last_ && std::abs(log_p - last_log_p_) > 0.02) {
    const double observed = -(log_ms - last_log_ms_) / (log_p - last_log_p_);
    exponent_ = 0.5 * (exponent_ + std::clamp(observed, options_.min_exponent, options_.max_exponent));
  }
  last_log_ms_ = log_ms;
  last_log_p_ = log_p;
  has_last_ = true;
  const double log_ratio = log_ms - std::log(options_.target_ms);  // > 0: too slow
  if (std::abs(std::exp(log_ratio) - 1) <= options_.deadband) return;
  const double gain = spike ? options_.spike_gain : options_.gain;
  const double log_step = std::clamp(gain * log_ratio / exponent_,
                                     -std::log(options_.max_step), std::log(options_.max_step));
  const double next = static_cast<double>(parameter_) * std::exp(log_step);
  parameter_ = static_cast<float>(
      std::clamp(next, static_cast<double>(options_.finest), static_cast<double>(options_.coarsest)));
}

std::vector<float> refinement_sequence(float start, float finest, unsigned count) {
  check(count > 0, "refinement needs at least one frame");
  check(std::isfinite(finest) && finest > 0,
        "finest level of detail " + std::to_string(finest) + " is invalid; give a positive value");
  check(std::isfinite(start), "refinement start is not finite");
  std::vector<float> out(count, finest);
  if (start <= finest || count == 1) return out;
  // Geometric steps: equal ratios between frames, so each frame adds a similar share of detail.
  const double ratio = std::log(double(start) / finest);
  for (unsigned k = 0; k + 1 < count; ++k) {
    out[k] = static_cast<float>(finest * std::exp(ratio * double(count - 1 - k) / double(count - 1)));
  }
  return out;
}

}  // namespace pointillist
