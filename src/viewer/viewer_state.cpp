#include "viewer_state.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>

#include "pointillist/render/sequence.hpp"

namespace pointillist {
namespace {

constexpr float kSplatScaleStep = 1.25f;
constexpr std::size_t kFpsFrames = 10;

// The depth buffer at pixel (x, y) of the frame on screen, if something is drawn there.
std::optional<float> depth_at(const Frame& f, float x, float y) {
  const int px = static_cast<int>(std::floor(x)), py = static_cast<int>(std::floor(y));
  if (px < 0 || py < 0 || px >= f.width || py >= f.height) return std::nullopt;
  const float d = f.depth[static_cast<std::size_t>(py) * f.width + px];
  if (!std::isfinite(d) || !(d > 0)) return std::nullopt;
  return d;
}

std::string megabytes(std::uint64_t bytes) {
  char s[32];
  std::snprintf(s, sizeof s, "%.0f MB", double(bytes) / 1e6);
  return s;
}

}  // namespace

ViewerState::ViewerState(const ViewerOptions& o, Navigator& nav)
    : options_(o),
      nav_(nav),
      settings_(o.settings),
      frame_(o.frame),
      undo_settings_(o.settings),
      undo_frame_(o.frame),
      control_(FrameControlOptions{.target_ms = 1000.0 / o.fps,
                                   .finest = initial_detail(o.settings, o.frame),
                                   .coarsest = std::max(64.0f, initial_detail(o.settings, o.frame))},
               initial_detail(o.settings, o.frame)) {}

void ViewerState::changed(double now_ms) {
  moved_ = true;
  phase_ = Phase::Moving;
  if (input_ms_ < 0) input_ms_ = now_ms;
}

void ViewerState::handle(const InputEvent& e, double now_ms, const Frame& frame) {
  using T = InputEvent::Type;
  switch (e.type) {
    case T::Quit:
      quit_ = true;
      break;
    case T::Resize:
      nav_.resize(e.width, e.height);
      changed(now_ms);
      break;
    case T::Press:
      buttons_ |= 1 << (e.button - 1);
      last_x_ = e.x;
      last_y_ = e.y;
      if (e.button == 1 && e.clicks == 2) {
        if (const auto d = depth_at(frame, e.x, e.y)) {
          nav_.pick_pivot(e.x, e.y, *d);
          changed(now_ms);
        }
      }
      break;
    case T::Release:
      buttons_ &= ~(1 << (e.button - 1));
      break;
    case T::Motion: {
      const float dx = e.x - last_x_, dy = e.y - last_y_;
      last_x_ = e.x;
      last_y_ = e.y;
      if (dx == 0 && dy == 0) break;
      if (buttons_ & 1) {
        nav_.orbit(dx, dy);
        changed(now_ms);
      } else if (buttons_ & 6) {
        nav_.pan(dx, dy);
        changed(now_ms);
      }
      break;
    }
    case T::Wheel:
      if (e.wheel != 0) {
        nav_.zoom(e.wheel, e.x, e.y, depth_at(frame, e.x, e.y));
        changed(now_ms);
      }
      break;
    case T::Key:
      key(e.key, now_ms);
      break;
  }
}

void ViewerState::key(const std::string& k, double now_ms) {
  if (k == "q" || k == "escape") {
    quit_ = true;
    return;
  }
  if (k == "s") {
    screenshot_ = true;
    return;
  }
  if (k == "h") {
    help_ = true;
    return;
  }
  if (k.size() == 1 && k[0] >= '1' && k[0] <= '6') {
    nav_.axis_view(static_cast<AxisView>(k[0] - '1'));
  } else if (k == "0" || k == "r") {
    nav_.reset();
  } else {
    const RenderSettings settings = settings_;
    const FrameSettings frame = frame_;
    const bool ortho = nav_.ortho();
    if (!toggle(k)) return;  // not a key of the viewer
    undo_settings_ = settings;
    undo_frame_ = frame;
    undo_ortho_ = ortho;
    toggled_ = true;
  }
  changed(now_ms);
}

bool ViewerState::toggle(const std::string& k) {
  if (k == "o") {
    nav_.toggle_ortho();
  } else if (k == "m") {
    frame_.rasterizer =
        frame_.rasterizer == Rasterizer::Fast ? Rasterizer::Quality : Rasterizer::Fast;
  } else if (k == "k") {
    settings_.shape = settings_.shape == SplatShape::Square   ? SplatShape::Circle
                      : settings_.shape == SplatShape::Circle ? SplatShape::Ellipse
                                                              : SplatShape::Square;
  } else if (k == "l") {
    // Full detail follows (finest()): the other scheme's parameter as the viewer started with.
    frame_.lod = frame_.lod == LodScheme::QSplat ? LodScheme::Spt : LodScheme::QSplat;
    if (frame_.lod == LodScheme::QSplat) frame_.hybrid = false;  // it draws with SPT only
  } else if (k == "p") {
    // Hybrid point/polygon rendering needs the Sequential Point Tree: switching it on switches
    // to SPT, switching it off leaves the scheme alone.
    frame_.hybrid = !frame_.hybrid;
    if (frame_.hybrid) frame_.lod = LodScheme::Spt;
  } else if (k == "plus") {
    frame_.splat_scale = std::min(100.0f, frame_.splat_scale * kSplatScaleStep);
  } else if (k == "minus") {
    frame_.splat_scale = std::max(0.01f, frame_.splat_scale / kSplatScaleStep);
  } else if (k == "e") {
    const float strength = options_.settings.edl_strength > 0 ? options_.settings.edl_strength : 1;
    settings_.edl_strength = settings_.edl_strength > 0 ? 0.0f : strength;
  } else if (k == "t") {
    settings_.two_sided = !settings_.two_sided;
  } else if (k == "f") {
    frame_.features = !frame_.features;
  } else if (k == "c") {
    frame_.occlusion.method = frame_.occlusion.method == OcclusionMethod::None
                                  ? OcclusionMethod::ChcPlusPlus
                                  : OcclusionMethod::None;
  } else {
    return false;
  }
  return true;
}

bool ViewerState::refuse(const std::string& message, double now_ms) {
  if (!toggled_) return false;
  toggled_ = false;
  settings_ = undo_settings_;
  frame_ = undo_frame_;
  if (nav_.ortho() != undo_ortho_) nav_.toggle_ortho();
  message_ = "refused: " + message;
  message_until_ = now_ms + 5000;
  changed(now_ms);
  return true;
}

std::optional<float> ViewerState::next_detail(const Renderer& renderer) {
  if (phase_ == Phase::Moving && !moved_) {
    if (last_detail_ <= finest()) {
      // The last moving frame was already at full detail, and nothing moved since.
      full_detail_reached(renderer, last_handed_);
    } else {
      // The camera stopped: refine from the moving detail to full detail.
      refine_ = refinement_sequence(last_detail_, finest(), options_.refine_frames);
      refine_index_ = 0;
      phase_ = Phase::Refine;
    }
  }
  switch (phase_) {
    case Phase::Moving:
      return last_detail_ = std::max(control_.parameter(), finest());
    case Phase::Refine:
      return last_detail_ = refine_[refine_index_];
    case Phase::Loading:
      // While pages are on their way, frames at the held frame rate's detail show them arriving
      // (full-detail frames of a large model would keep input waiting); once the loader is idle,
      // one frame at full detail, which may ask for more.
      loading_budget_ = renderer.loading();
      return last_detail_ = loading_budget_ ? std::max(control_.parameter(), finest()) : finest();
    case Phase::Settled:
      break;
  }
  return std::nullopt;
}

void ViewerState::full_detail_reached(const Renderer& renderer, std::size_t pages_handed) {
  // Settled once the last frame had every page it wanted, or none more can come (the memory cap
  // is reached and nothing is on its way).
  const bool waiting = renderer.paging() && !renderer.complete() &&
                       (pages_handed > 0 || renderer.loading());
  phase_ = waiting ? Phase::Loading : Phase::Settled;
}

void ViewerState::frame_done(double frame_ms, const Renderer& renderer, std::size_t pages_handed) {
  input_ms_ = -1;
  toggled_ = false;  // drawn: nothing to undo
  last_handed_ = pages_handed;
  recent_ms_.push_back(frame_ms);
  if (recent_ms_.size() > kFpsFrames) recent_ms_.erase(recent_ms_.begin());
  switch (phase_) {
    case Phase::Moving:
      // The first frame also opened the window: not a measure of the frame time.
      if (frames_++ > 0) control_.report(frame_ms);
      moved_ = false;
      break;
    case Phase::Refine:
      if (++refine_index_ >= refine_.size()) full_detail_reached(renderer, pages_handed);
      break;
    case Phase::Loading:
      if (loading_budget_) {
        control_.report(frame_ms);
      } else {
        full_detail_reached(renderer, pages_handed);
      }
      break;
    case Phase::Settled:
      break;
  }
}

const char* ViewerState::phase_name() const {
  switch (phase_) {
    case Phase::Moving: return "moving";
    case Phase::Refine: return "refine";
    case Phase::Loading: return "loading";
    case Phase::Settled: return "settled";
  }
  return "";
}

std::string ViewerState::title(const Renderer& renderer, double now_ms,
                               const ViewerFrame* last) const {
  std::string t = "Pointillist \xe2\x80\x94 " + options_.name;
  char s[160];
  if (!recent_ms_.empty()) {
    const double mean = std::accumulate(recent_ms_.begin(), recent_ms_.end(), 0.0) /
                        double(recent_ms_.size());
    std::snprintf(s, sizeof s, " \xe2\x80\x94 %.0f fps", mean > 0 ? 1000.0 / mean : 0.0);
    t += s;
  }
  if (last) {
    std::snprintf(s, sizeof s, " \xc2\xb7 %.2f M splats \xc2\xb7 detail %.2f px \xc2\xb7 ",
                  double(last->splats) / 1e6, double(last->detail));
    t += s;
    t += megabytes(last->resident_bytes);
  }
  const std::string dot = " \xc2\xb7 ";
  t += dot;
  t += name(frame_.rasterizer);
  t += ' ';
  t += name(settings_.shape);
  t += ' ';
  t += name(frame_.lod);
  if (frame_.hybrid) t += " hybrid";
  if (frame_.splat_scale != 1.0f) {
    std::snprintf(s, sizeof s, " size x%.2f", double(frame_.splat_scale));
    t += s;
  }
  if (settings_.edl_strength > 0) t += " edl";
  if (settings_.two_sided) t += " two-sided";
  if (nav_.ortho()) t += " ortho";
  if (frame_.occlusion.method != OcclusionMethod::None) t += " culling";
  if (!frame_.features) t += " no-features";
  t += dot;
  t += phase_ == Phase::Settled ? "full detail" : phase_name();
  if (renderer.paging() && !renderer.complete()) t += " (pages loading)";
  if (now_ms < message_until_) {
    t += dot;
    t += message_;
  }
  t += dot;
  t += "h: help";
  return t;
}

}  // namespace pointillist
