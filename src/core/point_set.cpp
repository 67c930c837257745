#include "pointillist/core/point_set.hpp"

#include <algorithm>

namespace pointillist {

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
