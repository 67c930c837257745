// The viewer's state between frames: input turned into camera moves and toggles, and the phase
// that decides each frame's detail (moving: the frame-time controller; refine: towards full
// detail; loading: full detail while pages stream in; settled: nothing to draw). Internal to
// the viewer module.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "pointillist/render/frame_control.hpp"
#include "pointillist/render/sequence.hpp"
#include "pointillist/viewer/viewer.hpp"

namespace pointillist {

class ViewerState {
 public:
  ViewerState(const ViewerOptions& options, Navigator& navigator);

  // Applies one input event (at now_ms); `frame` is the frame on screen (its depth buffer picks
  // points under the cursor).
  void handle(const InputEvent& e, double now_ms, const Frame& frame);
  // The detail of the next frame, or nothing when the view is settled.
  std::optional<float> next_detail(const Renderer& renderer);
  // After a frame: its time (render and present) and the pages handed to the loader after it.
  void frame_done(double frame_ms, const Renderer& renderer, std::size_t pages_handed);
  // The frame could not be drawn: undo the toggle since the last frame and show why; false when
  // there was no toggle to undo (the models cannot be drawn at all).
  bool refuse(const std::string& message, double now_ms);

  const RenderSettings& settings() const { return settings_; }
  const FrameSettings& frame_settings() const { return frame_; }
  bool quit() const { return quit_; }
  bool settled() const { return phase_ == Phase::Settled; }
  const char* phase_name() const;
  // When the first input event the next frame answers to arrived (ms), or -1.
  double input_time() const { return input_ms_; }
  bool take_screenshot_request() { return std::exchange(screenshot_, false); }
  bool help_requested() { return std::exchange(help_, false); }
  std::string title(const Renderer& renderer, double now_ms,
                    const ViewerFrame* last = nullptr) const;

 private:
  enum class Phase { Moving, Refine, Loading, Settled };
  void changed(double now_ms);
  void key(const std::string& name, double now_ms);
  // Applies a mode key (m, k, l, plus, minus, e, t, o, f, c); false for any other key.
  bool toggle(const std::string& name);
  // Full detail of the scheme drawn: the QSplat threshold or SPT epsilon the viewer started with
  // (the viewer never changes those; frames draw copies with their own detail).
  float finest() const { return initial_detail(settings_, frame_); }
  void full_detail_reached(const Renderer& renderer, std::size_t pages_handed);

  const ViewerOptions& options_;
  Navigator& nav_;
  RenderSettings settings_;
  FrameSettings frame_;
  RenderSettings undo_settings_;
  FrameSettings undo_frame_;
  bool undo_ortho_ = false;
  bool toggled_ = false;  // a toggle since the last frame drawn
  FrameTimeController control_;
  Phase phase_ = Phase::Moving;
  bool moved_ = true;  // something changed since the last frame
  float last_detail_ = 0;
  std::vector<float> refine_;
  std::size_t refine_index_ = 0;
  std::size_t last_handed_ = 0;
  std::size_t frames_ = 0;
  bool loading_budget_ = false;  // the loading frame drawn at the held frame rate's detail  // pages handed to the loader after the last frame
  int buttons_ = 0;  // bit b-1 for button b held
  float last_x_ = 0, last_y_ = 0;
  double input_ms_ = -1;
  bool quit_ = false, screenshot_ = false, help_ = false;
  std::string message_;
  double message_until_ = 0;
  std::vector<double> recent_ms_;  // the last frames' times, for the fps shown
};

}  // namespace pointillist
