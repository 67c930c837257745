// Checks of the splats a hierarchy is built from (see splat_input.hpp).
#include "splat_input.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "pointillist/core/error.hpp"

namespace pointillist::lod_detail {
namespace {

constexpr std::size_t kMaxPoints = std::size_t{1} << 31;
constexpr std::size_t kPointGrain = 65536;  // points per task

std::string vec_text(Vec3f v) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "(%g, %g, %g)", v.x, v.y, v.z);
  return buf;
}

}  // namespace

void check_splat_attributes(const PointSet& points, const std::string& what) {
  const std::size_t n = points.size();
  if (n == 0) throw Error(what + " from an empty point set; the input has no points");
  if (n > kMaxPoints) {
    throw Error(what + " over " + std::to_string(n) +
                " points: the limit is 2^31 (2147483648); split the input into chunks");
  }
  if (!points.has_normals()) throw Error(what + ": the points have no normals; estimate them first");
  if (!points.has_radii()) {
    throw Error(what + ": the points have no splat radii; compute them first");
  }
  const auto check_size = [&](std::size_t size, const char* attribute) {
    if (size != n) {
      throw Error(what + ": " + std::to_string(size) + " " + attribute + " for " +
                  std::to_string(n) + " points; expected one per point");
    }
  };
  check_size(points.normals.size(), "normals");
  check_size(points.radii.size(), "radii");
  if (points.has_colors()) check_size(points.colors.size(), "colors");
}

// Inner loops never throw: each chunk notes its first bad point and the lowest one is reported.
Aabb check_points_and_bound(const PointSet& points, ThreadPool& pool, const std::string& what) {
  const std::size_t n = points.size();
  const std::size_t chunks = (n + kPointGrain - 1) / kPointGrain;
  std::vector<Aabb> boxes(chunks);
  std::vector<std::size_t> first_bad(chunks, n);
  parallel_for(pool, n, kPointGrain, [&](std::size_t begin, std::size_t end) {
    const std::size_t c = begin / kPointGrain;
    Aabb box;
    for (std::size_t i = begin; i < end; ++i) {
      const Vec3f p = points.positions[i];
      const bool ok = is_finite(p) && is_finite(points.normals[i]) &&
                      std::isfinite(points.radii[i]) && points.radii[i] >= 0;
      if (!ok && first_bad[c] == n) first_bad[c] = i;
      box.extend(p);
    }
    boxes[c] = box;
  });
  Aabb bounds;
  for (std::size_t c = 0; c < chunks; ++c) {
    if (const std::size_t i = first_bad[c]; i != n) {
      const std::string where = what + ": point " + std::to_string(i) + ": ";
      if (!is_finite(points.positions[i])) {
        throw Error(where + "position " + vec_text(points.positions[i]) +
                    " is not finite; remove or repair the point");
      }
      if (!is_finite(points.normals[i])) {
        throw Error(where + "normal " + vec_text(points.normals[i]) +
                    " is not finite; re-estimate the normals");
      }
      throw Error(where + "splat radius " + std::to_string(points.radii[i]) +
                  " is not a finite non-negative number; recompute the radii");
    }
    bounds.extend(boxes[c]);
  }
  return bounds;
}

float max_distance(const std::vector<Vec3f>& positions, Vec3f center, ThreadPool& pool) {
  const std::size_t chunks = (positions.size() + kPointGrain - 1) / kPointGrain;
  std::vector<float> d2(chunks, 0.0f);
  parallel_for(pool, positions.size(), kPointGrain, [&](std::size_t begin, std::size_t end) {
    float m = 0;
    for (std::size_t i = begin; i < end; ++i) m = std::max(m, length_squared(positions[i] - center));
    d2[begin / kPointGrain] = m;
  });
  float m = 0;
  for (float v : d2) m = std::max(m, v);
  return std::sqrt(m);
}

}  // namespace pointillist::lod_detail
