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
  // Cost model: frame time ∝ parameter^(−exponent) near the current parameter. The exponent is
  // learnt from consecutive frames (it is 2 for splats covering a surface, near 0 where the
  // parameter is below the size of the finest splats and changes nothing, and lower than 2
  // when a fixed cost per frame dominates); this is its starting value.
  double cost_exponent = 2.0;
  // Learnt exponents are clamped to [min_exponent, max_exponent]: a small exponent makes big
  // steps (crossing a flat region quickly), bounded by max_step.
  double min_exponent = 0.25;
  double max_exponent = 4.0;
  // A frame more than spike_ratio times slower than the previous one at (nearly) the same
  // parameter is taken as a spike (a page fault, another process) rather than a change of
  // scene: the correction it asks for is applied with spike_gain instead of gain. A real change
  // of scene is still followed at full gain from the next frame on.
  double spike_ratio = 1.3;
  double spike_gain = 0.2;
};

// Feedback controller for one view sequence. Usage per frame: render with parameter(), then
// report(measured_ms). A frame within the deadband changes nothing; otherwise the parameter that
// would hit the target under the local cost model is p·(ms / target)^(1/e), and the controller
// moves `gain` of the way there in the logarithm (at most max_step). The local exponent e is
// re-estimated from each pair of consecutive frames whose parameters differ by more than 2%
// (e = −Δlog ms / Δlog p, clamped, averaged with the previous estimate). Deterministic: the
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
  double exponent_;         // current estimate of the local cost exponent
  double last_log_ms_ = 0;  // the previous frame, for the exponent estimate
  double last_log_p_ = 0;
  bool has_last_ = false;
};

// The parameters of `count` frames a viewer shows after the camera stops: from `start` down to
// `finest` (full detail) in geometric steps, the last frame exactly at `finest`. start ≤ finest
// gives `count` frames at finest. Throws OptionError for count = 0 or a non-positive finest.
std::vector<float> refinement_sequence(float start, float finest, unsigned count);

}  // namespace pointillist
