// Sharp features into the splat stream: each splat's surface id and clip planes, looked up by
// its node. Internal to render.
#pragma once

#include <cstdint>

#include "pointillist/lod/tree_features.hpp"
#include "pointillist/render/renderer.hpp"
#include "pointillist/render/splat_stream.hpp"

namespace pointillist::render_detail {

// Fills chunk.surface, clip_first, clip_code and clip_planes for the chunk's splats, whose node
// ids index `features` (null: a model without features, whose splats blend with any surface
// and are never clipped). Surface ids are offset by `id_base` (ids of other instances come
// before); planes are moved into the world by `transform` (null: identity).
void attach_features(const TreeFeatures* features, const InstanceTransform* transform,
                     std::uint32_t id_base, SplatChunk& chunk);

}  // namespace pointillist::render_detail
