// Frame-time control and idle refinement (QSplat, Rusinkiewicz & Levoy 2000, section 4.3: the
// viewer adjusts its level-of-detail threshold from frame to frame to hold a frame rate, and
// refines when the user stops moving).
//
// Works on any level-of-detail parameter p where larger means coarser and the cost of a frame
// falls as a power of p: the QSplat projected-size threshold (pixels; splat count ∝ p⁻² on a
// surface) or the Sequential Point Tree error bound ε (pixels of error).
#pragma once

#include <vector>

namespace pointillist {

struct FrameControlOptions {
  // Wanted frame time in milliseconds (> 0).
  double target_ms = 33.3;
  // Finest and coarsest allowed parameter. The finest is full detail (1 px for the QSplat
  // threshold); the coarsest bounds how ugly a frame may get when the target is too ambitious.
  float finest = 1.0f;
  float coarsest = 64.0f;
  // Fraction of the predicted correction applied per frame, in (0, 1]. Below 1 the controller
  // approaches the target from one side instead of overshooting on a noisy frame.
  double gain = 0.7;
  // Frames within ±deadband of the target (relative) leave the parameter alone, so timing
  // noise does not make it oscillate. Keep it below the tolerance you judge frames by.
  double deadband = 0.08;
  // The parameter changes by at most this factor per frame (> 1): one slow frame (a page fault,
  // another process) cannot throw the level of detail far off.
  double max_step = 2.0;
  // Cost model: frame time ∝ parameter^(−cost_exponent). 2 for splats covering a surface.
  double cost_exponent = 2.0;
  // Weight of the newest frame in the running estimate of the cost model's constant, in (0, 1].
  // Lower filters timing noise better and follows a change of scene more slowly (about
  // 1 / smoothing frames).
  double smoothing = 0.35;
};

// Feedback controller for one view sequence. Usage per frame: render with parameter(), then
// report(measured_ms). Each report updates a smoothed estimate of the cost model's constant
// k = ms · p^e (in the logarithm); the parameter that would hit the target is (k / target)^(1/e),
// and the controller moves `gain` of the way there (at most max_step), unless the time the
// model predicts for the current parameter is already within the deadband. Deterministic: the
// same measurements give the same parameters.
class FrameTimeController {
 public:
  // Throws OptionError for a non-positive or non-finite target, finest ≤ 0, coarsest < finest,
  // gain outside (0, 1], negative deadband, max_step ≤ 1 or cost_exponent ≤ 0, or an initial
  // value that is not finite (it is clamped to [finest, coarsest]).
  explicit FrameTimeController(const FrameControlOptions& options, float initial);

  float parameter() const { return parameter_; }
  // True when the parameter is at `finest`: there is no more detail to add.
  bool at_full_detail() const { return parameter_ <= options_.finest; }
  // Time of the frame just rendered with parameter(); computes the next parameter. A frame that
  // is at full detail and faster than the target keeps full detail (no work is added that is
  // not there). Non-finite or negative times are ignored.
  void report(double frame_ms);

 private:
  FrameControlOptions options_;
  float parameter_;
  double log_k_ = 0;  // smoothed log(ms) + e·log(p)
  bool has_estimate_ = false;
};

// The parameters of `count` frames a viewer shows after the camera stops: from `start` down to
// `finest` (full detail) in geometric steps, the last frame exactly at `finest`. start ≤ finest
// gives `count` frames at finest. Throws OptionError for count = 0 or a non-positive finest.
std::vector<float> refinement_sequence(float start, float finest, unsigned count);

}  // namespace pointillist
