#include "pointillist/core/point_set.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace pointillist {

std::size_t keep_points(PointSet& p, std::span<const std::uint8_t> keep) {
  const std::size_t n = p.size();
  assert(keep.size() == n);
  std::vector<std::uint32_t> new_index(n);
  std::uint32_t kept = 0;
  for (std::size_t i = 0; i < n; ++i) new_index[i] = keep[i] ? kept++ : UINT32_MAX;
  if (kept == n) return n;
  const auto compact = [&](auto& values) {
    if (values.empty()) return;
    for (std::size_t i = 0; i < n; ++i) {
      if (new_index[i] != UINT32_MAX) values[new_index[i]] = values[i];
    }
    values.resize(kept);
    values.shrink_to_fit();
  };
  compact(p.positions);
  compact(p.normals);
  compact(p.colors);
  compact(p.radii);
  std::size_t faces = 0;
  for (const auto& t : p.triangles) {
    const std::array<std::uint32_t, 3> r{new_index[t[0]], new_index[t[1]], new_index[t[2]]};
    if (r[0] != UINT32_MAX && r[1] != UINT32_MAX && r[2] != UINT32_MAX) p.triangles[faces++] = r;
  }
  p.triangles.resize(faces);
  return kept;
}

Aabb bounding_box(const std::vector<Vec3f>& positions) {
  Aabb box;
  for (const Vec3f& p : positions) box.extend(p);
  return box;
}

Sphere view_sphere(const std::vector<Vec3f>& positions) {
  const Aabb box = bounding_box(positions);
  if (box.empty()) return {};
  const Vec3f c = box.center();
  float r2 = 0;
  for (const Vec3f& p : positions) r2 = std::max(r2, length_squared(p - c));
  return {c, std::sqrt(r2)};
}

}  // namespace pointillist
