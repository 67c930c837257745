// The statistics of a render as JSON (what `pointillist render --stats` writes; a viewer can show
// the same): the last frame's counts and times, how it was drawn (level of detail, rasterizer,
// paging with each model's paging decision) and, for a sequence, every frame.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "pointillist/pipeline/scene.hpp"
#include "pointillist/render/renderer.hpp"
#include "pointillist/render/sequence.hpp"

namespace pointillist {

struct RenderReport {
  const Scene* scene = nullptr;        // its models' paths, kinds and paging decisions
  const Renderer* renderer = nullptr;  // paging and SPT counts of its last frame
  FrameSettings frame;                 // how the frames were drawn
  std::uint64_t memory_cap = 0;        // bytes; 0 = none
  RenderStats last;                    // the last frame's counts and times
  // A sequence: its frames (phase, the orbit's azimuth, detail, splats, times; paging bytes when
  // paged), and with target_ms > 0 the frame-time target and hit_rate over the frames after
  // `settle`.
  bool sequence = false;
  std::span<const SequenceFrame> frames;
  double target_ms = 0;
  std::size_t settle = 0;
  float finest = 1;
};

// The report as a JSON document (two-space indent, keys in a fixed order, times in ms rounded
// to microseconds), ending with a newline. Keys: splats, nodes_visited, culled_frustum,
// culled_backface, width, height, threads; lod and mode; reconstruction and opacity (quality);
// list_length, entries_scanned, fraction_scanned, chunks, chunks_culled (SPT); hybrid,
// triangle_px_per_epsilon, triangles_selected, triangles (drawn after near clipping),
// triangle_entries_scanned (SPT --hybrid; frames also get triangles); paged, pages,
// model_bytes, memory_cap, bytes_read, resident_bytes, resident_bytes_peak, pages_loaded,
// pages_evicted, complete (paged); models [{path, kind, paging}]; ms {select, raster, total};
// target_ms, hit_rate, frames [...] (sequences).
std::string render_report_json(const RenderReport& report);

}  // namespace pointillist
