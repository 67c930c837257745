// Render statistics as JSON (for --stats).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "pointillist/render/render.hpp"

namespace pointillist::cli {

// {"splats": ..., "nodes_visited": ..., ..., "ms": {"select": .., "raster": .., "total": ..}}
// `extra` (zero or more `  "key": value,\n` lines) goes before "ms".
std::string stats_to_json(const RenderStats& stats, const std::string& extra = "");

// One frame of a sequence (render --path / --refine / --frame-ms).
struct FrameRecord {
  const char* phase;    // "path" or "refine"
  float azimuth_deg;
  float threshold_px;   // level of detail the frame was rendered with (threshold, or SPT ε)
  RenderStats stats;
  // Paged models only (else negative): storage bytes read so far and resident page memory,
  // both when the frame was drawn.
  std::int64_t bytes_read = -1;
  std::int64_t resident_bytes = -1;
};

// The statistics of the last frame as stats_to_json writes them, plus "frames": [...] with each
// frame's phase, azimuth, threshold, splats and ms (select, raster, total), and, when target_ms
// > 0, "target_ms" and "hit_rate": the share of path frames after the first `settle` whose total
// time is within ±20% of the target, frames at full detail and faster counting as hits.
double hit_rate(const std::vector<FrameRecord>& frames, double target_ms, std::size_t settle,
                float finest);
std::string sequence_to_json(const std::vector<FrameRecord>& frames, double target_ms,
                             std::size_t settle, float finest, const std::string& extra = "");

}  // namespace pointillist::cli
