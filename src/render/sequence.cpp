// Frame sequences and settled images (see sequence.hpp).
#include "pointillist/render/sequence.hpp"

#include <algorithm>
#include <optional>
#include <string>

#include "pointillist/core/error.hpp"
#include "pointillist/render/frame_control.hpp"

namespace pointillist {
namespace {

// A single image of a paged model: at most this many load rounds (each loads one more level).
constexpr int kMaxSettleRounds = 1000;

}  // namespace

float initial_detail(const RenderSettings& settings, const FrameSettings& fs) {
  return fs.lod == LodScheme::Spt ? fs.epsilon_px : settings.threshold_px;
}

void check_sequence_options(const SequenceOptions& o) {
  if (o.frame_ms > 0 && o.orbit_frames == 0 && o.path.empty()) {
    throw OptionError("--frame-ms holds a frame time over a sequence of frames; add --path orbit:N "
                      "(N frames around the model) or --path FILE (a camera path file)");
  }
  if (o.orbit_frames > 0 && !o.path.empty()) {
    throw OptionError("a sequence follows either the orbit (--path orbit:N) or a camera path "
                      "file, not both");
  }
  if (o.progressive_frames > 0 && (o.orbit_frames > 0 || !o.path.empty() || o.frame_ms > 0)) {
    throw OptionError("--progressive N renders N frames at one view while pages load; it cannot "
                      "be combined with --path or --frame-ms (use --refine K to refine after it)");
  }
}

std::vector<SequenceFrame> render_sequence(
    Renderer& renderer, std::span<const SceneInstance> scene,
    const std::function<Camera(float)>& camera_at, float azimuth_deg,
    const RenderSettings& settings, const FrameSettings& fs, const SequenceOptions& o,
    ThreadPool& pool, Frame& frame, const std::function<void(const Frame&, std::size_t)>& on_frame) {
  check_sequence_options(o);
  const float start = initial_detail(settings, fs);
  const float finest = std::min(1.0f, start);
  std::optional<FrameTimeController> control;
  if (o.frame_ms > 0) {
    control.emplace(FrameControlOptions{.target_ms = o.frame_ms, .finest = finest}, start);
  }
  std::vector<SequenceFrame> records;
  // Orbit and progressive frames record their azimuth; frames of a path file do not.
  auto draw = [&](const char* phase, const Camera& camera, std::optional<float> azimuth,
                  float detail) {
    RenderSettings s = settings;
    FrameSettings f = fs;
    (fs.lod == LodScheme::Spt ? f.epsilon_px : s.threshold_px) = detail;
    renderer.render(scene, camera, s, f, pool, frame);
    SequenceFrame r{phase, azimuth, detail, frame.stats};
    if (renderer.paging()) {
      const PagingStats p = renderer.paging_stats();
      r.bytes_read = static_cast<std::int64_t>(p.cache.bytes_read);
      r.resident_bytes = static_cast<std::int64_t>(p.cache.resident_bytes);
    }
    records.push_back(r);
    if (on_frame) on_frame(frame, records.size() - 1);
    if (o.progressive_frames > 0) {
      // The loader thread reads the pages, as a viewer's does; waiting for it keeps the frames
      // reproducible (each shows exactly read_per_frame more of the model).
      renderer.request_in_background(SIZE_MAX, o.read_per_frame);
      renderer.wait_for_loader();
    } else {
      renderer.request_in_background();
    }
  };
  for (unsigned i = 0; i < o.progressive_frames; ++i) {
    draw("progressive", camera_at(azimuth_deg), azimuth_deg, start);
  }
  for (unsigned i = 0; i < o.orbit_frames; ++i) {
    const float azimuth =
        azimuth_deg + 360.0f * static_cast<float>(i) / static_cast<float>(o.orbit_frames);
    draw("path", camera_at(azimuth), azimuth, control ? control->parameter() : start);
    if (control) control->report(frame.stats.ms_total);
  }
  for (const Camera& camera : o.path) {
    draw("path", camera, std::nullopt, control ? control->parameter() : start);
    if (control) control->report(frame.stats.ms_total);
  }
  if (o.refine_frames > 0) {
    const float from = control ? control->parameter() : start;
    const float azimuth =
        o.orbit_frames > 0
            ? azimuth_deg + 360.0f * static_cast<float>(o.orbit_frames - 1) /
                                static_cast<float>(o.orbit_frames)
            : azimuth_deg;
    for (float detail : refinement_sequence(from, finest, o.refine_frames)) {
      if (o.path.empty()) {
        draw("refine", camera_at(azimuth), azimuth, detail);
      } else {
        draw("refine", o.path.back(), std::nullopt, detail);  // at the path's last camera
      }
    }
  }
  return records;
}

void render_settled(Renderer& renderer, std::span<const SceneInstance> scene, const Camera& camera,
                    const RenderSettings& settings, const FrameSettings& fs, ThreadPool& pool,
                    Frame& frame) {
  // A paged quality image loads its pages with fast frames (the same selection, so the same
  // pages) and is drawn once at the end.
  const bool quality_last = fs.rasterizer == Rasterizer::Quality && renderer.pages_any(scene);
  FrameSettings loading = fs;
  if (quality_last) loading.rasterizer = Rasterizer::Fast;
  for (int round = 0; round < kMaxSettleRounds; ++round) {
    renderer.render(scene, camera, settings, loading, pool, frame);
    if (!renderer.paging() || renderer.complete() || renderer.load_requested(pool) == 0) break;
  }
  if (quality_last) renderer.render(scene, camera, settings, fs, pool, frame);
}

double hit_rate(std::span<const SequenceFrame> frames, double target_ms, std::size_t settle,
                float finest) {
  std::size_t hits = 0, counted = 0, path_index = 0;
  for (const SequenceFrame& f : frames) {
    // Only the frames along the path are held to the target (refinement adds detail on purpose).
    if (std::string(f.phase) != "path" || path_index++ < settle) continue;
    const double ms = f.stats.ms_total;
    ++counted;
    hits += (ms >= 0.8 * target_ms && ms <= 1.2 * target_ms) || (f.detail <= finest && ms < target_ms);
  }
  return counted ? double(hits) / double(counted) : 1.0;
}

}  // namespace pointillist
