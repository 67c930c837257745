// Render statistics as JSON (for --stats).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "pointillist/render/render.hpp"
#include "pointillist/render/sequence.hpp"

namespace pointillist::cli {

// {"splats": ..., "nodes_visited": ..., ..., "ms": {"select": .., "raster": .., "total": ..}}
// `extra` (zero or more `  "key": value,\n` lines) goes before "ms".
std::string stats_to_json(const RenderStats& stats, const std::string& extra = "");

// The statistics of the last frame as stats_to_json writes them, plus "frames": [...] with each
// frame's phase, azimuth, threshold, splats and ms (select, raster, total), and, when target_ms
// > 0, "target_ms" and "hit_rate" (render's hit_rate over the path frames after `settle`).
std::string sequence_to_json(std::span<const SequenceFrame> frames, double target_ms,
                             std::size_t settle, float finest, const std::string& extra = "");

}  // namespace pointillist::cli
