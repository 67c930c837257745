// Sharp features into the splat stream: each splat's surface id and clip planes, looked up by
// its node. Internal to render.
#pragma once

#include <cstdint>
#include <span>

#include "pointillist/lod/tree_features.hpp"
#include "pointillist/render/renderer.hpp"
#include "pointillist/render/splat_stream.hpp"

namespace pointillist::render_detail {

// Sizes chunk.surface, clip_first and clip_code for the chunk's capacity.
void reserve_features(SplatChunk& chunk);

// Fills chunk.surface, clip_first, clip_code and clip_planes for the chunk's splats from
// `lookup(i, surface, mode)`, which sets splat i's surface id and clip mode and returns its
// planes (in the model's frame, ids the model's own).
template <class Lookup>
void fill_features(SplatChunk& chunk, const Lookup& lookup) {
  reserve_features(chunk);
  chunk.clip_planes.clear();
  for (std::size_t i = 0; i < chunk.count; ++i) {
    std::uint32_t surface = kMixedSurface;
    ClipMode mode = ClipMode::None;
    const std::span<const ClipPlane> planes = lookup(i, surface, mode);
    chunk.surface[i] = surface;
    chunk.clip_first[i] = static_cast<std::uint32_t>(chunk.clip_planes.size());
    chunk.clip_code[i] = clip_code(planes.size(), planes.empty() ? ClipMode::None : mode);
    chunk.clip_planes.insert(chunk.clip_planes.end(), planes.begin(), planes.end());
  }
}

// Moves features filled in the model's frame into the scene's: surface ids offset by `id_base`
// (ids of other instances come before; kMixedSurface stays), planes moved by `transform`
// (null: identity).
void place_features(const InstanceTransform* transform, std::uint32_t id_base, SplatChunk& chunk);

// fill_features from `features` by the splats' node ids (null: a model without features, whose
// splats blend with any surface and are never clipped), then place_features.
void attach_features(const TreeFeatures* features, const InstanceTransform* transform,
                     std::uint32_t id_base, SplatChunk& chunk);

}  // namespace pointillist::render_detail
