#include "select/stream_features.hpp"

namespace pointillist::render_detail {

void reserve_features(SplatChunk& chunk) {
  if (chunk.surface.size() < chunk.count) {
    const std::size_t cap = chunk.capacity();
    chunk.surface.resize(cap);
    chunk.clip_first.resize(cap);
    chunk.clip_code.resize(cap);
  }
}

void place_features(const InstanceTransform* transform, std::uint32_t id_base,
                    SplatChunk& chunk) {
  if (id_base != 0) {
    for (std::size_t i = 0; i < chunk.count; ++i) {
      if (chunk.surface[i] != kMixedSurface) chunk.surface[i] += id_base;
    }
  }
  if (!transform) return;
  for (ClipPlane& p : chunk.clip_planes) {
    // n·x − h >= 0 in the model is n′·y − h′ >= 0 for y = t + s·R·x: n′ = R·n, h′ = s·h + n′·t
    // (a positive scale keeps the in-plane distances' ratios).
    const Vec3f n2 = transform->rotate(p.n);
    p = {n2, p.h * transform->scale + dot(n2, transform->translate)};
  }
}

void attach_features(const TreeFeatures* features, const InstanceTransform* transform,
                     std::uint32_t id_base, SplatChunk& chunk) {
  fill_features(chunk, [&](std::size_t i, std::uint32_t& surface, ClipMode& mode) {
    if (!features) return std::span<const ClipPlane>{};
    const std::uint32_t node = chunk.node[i];
    surface = features->surface[node];
    mode = features->clip_mode[node];
    return features->planes(node);
  });
  place_features(transform, id_base, chunk);
}

}  // namespace pointillist::render_detail
