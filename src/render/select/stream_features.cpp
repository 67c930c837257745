#include "select/stream_features.hpp"

namespace pointillist::render_detail {

void attach_features(const TreeFeatures* features, const InstanceTransform* transform,
                     std::uint32_t id_base, SplatChunk& chunk) {
  const std::size_t n = chunk.count;
  if (chunk.surface.size() < n) {
    const std::size_t cap = chunk.capacity();
    chunk.surface.resize(cap);
    chunk.clip_first.resize(cap);
    chunk.clip_code.resize(cap);
  }
  chunk.clip_planes.clear();
  for (std::size_t i = 0; i < n; ++i) {
    if (!features) {
      chunk.surface[i] = kMixedSurface;
      chunk.clip_first[i] = 0;
      chunk.clip_code[i] = clip_code(0, ClipMode::None);
      continue;
    }
    const std::uint32_t node = chunk.node[i];
    const std::uint32_t id = features->surface[node];
    chunk.surface[i] = id == kMixedSurface ? id : id + id_base;
    chunk.clip_first[i] = static_cast<std::uint32_t>(chunk.clip_planes.size());
    const auto planes = features->planes(node);
    chunk.clip_code[i] = clip_code(planes.size(), features->clip_mode[node]);
    for (ClipPlane p : planes) {
      if (transform) {
        // n·x − h >= 0 in the model is n′·y − h′ >= 0 for y = t + s·R·x: n′ = R·n, h′ =
        // s·h + n′·t (a positive scale keeps the in-plane distances' ratios).
        const Vec3f n2 = transform->rotate(p.n);
        p = {n2, p.h * transform->scale + dot(n2, transform->translate)};
      }
      chunk.clip_planes.push_back(p);
    }
  }
}

}  // namespace pointillist::render_detail
