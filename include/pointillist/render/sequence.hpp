// Frame sequences, as a viewer shows them: a camera path around the model with frame-time control
// (QSplat section 4.3), idle refinement when the camera stops, progressive loading of a paged
// model; and a single image that waits for the pages its view needs.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "pointillist/render/renderer.hpp"

namespace pointillist {

struct SequenceOptions {
  unsigned progressive_frames = 0;  // frames at the first view while pages load
  // Storage bytes the loader reads between two progressive frames (at least one page).
  std::uint64_t read_per_frame = 1u << 20;
  unsigned orbit_frames = 0;  // frames around the orbit: azimuth + 360°·i / orbit_frames
  // Frames along these cameras instead (a camera path file, io/camera_path.hpp), in order;
  // orbit_frames must then be 0.
  std::vector<Camera> path;
  double frame_ms = 0;        // > 0: hold this frame time along the orbit or the path
  unsigned refine_frames = 0;  // idle refinement after the orbit or path, down to full detail
};

// Frames a sequence renders before the frame-time controller is judged (hit_rate).
inline constexpr std::size_t kSettleFrames = 5;

struct SequenceFrame {
  const char* phase = "";  // "progressive", "path" or "refine"
  std::optional<float> azimuth_deg;  // the orbit's azimuth; unset for the frames of a path
  float detail = 0;  // level of detail the frame was drawn with (QSplat threshold or SPT ε, px)
  RenderStats stats;
  // Paged models only (else negative): storage bytes read so far and resident page memory,
  // both when the frame was drawn.
  std::int64_t bytes_read = -1;
  std::int64_t resident_bytes = -1;
};

// The level-of-detail parameter the settings start from: threshold_px for QSplat, epsilon_px for
// SPT.
float initial_detail(const RenderSettings& settings, const FrameSettings& frame_settings);

// Throws OptionError for sequence options that cannot go together (the message says which).
void check_sequence_options(const SequenceOptions& options);

// Renders progressive_frames at `azimuth_deg`, orbit_frames around the orbit with
// camera_at(azimuth) or else one frame per camera of options.path (with frame-time control when
// frame_ms > 0), and refine_frames of idle refinement at the last camera, calling
// on_frame(frame, index) after each (may be empty). After each frame a paged model's
// pages are loaded: progressive frames wait for the loader (reproducible frames), the others hand
// the pages to it as a viewer does (frames then depend on timing). Returns every frame's record
// and leaves the last frame in `frame`.
std::vector<SequenceFrame> render_sequence(
    Renderer& renderer, std::span<const SceneInstance> scene,
    const std::function<Camera(float azimuth_deg)>& camera_at, float azimuth_deg,
    const RenderSettings& settings, const FrameSettings& frame_settings,
    const SequenceOptions& options, ThreadPool& pool, Frame& frame,
    const std::function<void(const Frame&, std::size_t)>& on_frame = {});

// One image of a view: renders until every paged model has loaded all the view needs (or all its
// memory cap allows), loading pages between frames on the pool; a quality image loads with fast
// frames (the same selection) and is drawn once at the end.
void render_settled(Renderer& renderer, std::span<const SceneInstance> scene, const Camera& camera,
                    const RenderSettings& settings, const FrameSettings& frame_settings,
                    ThreadPool& pool, Frame& frame);

// The share of path frames after the first `settle` whose total time is within ±20% of
// target_ms, frames at full detail (detail ≤ finest) and faster counting as hits; 1 when none
// is counted.
double hit_rate(std::span<const SequenceFrame> frames, double target_ms, std::size_t settle,
                float finest);

}  // namespace pointillist
