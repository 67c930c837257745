// Area-weighted vertex normals: each vertex sums the unnormalized normals (cross products, twice
// the area) of its triangles, so large faces count more and slivers barely at all.
#include <algorithm>
#include <cassert>

#include "pointillist/prep/normals.hpp"
#include "vertex_ranges.hpp"

namespace pointillist {

std::vector<Vec3f> mesh_vertex_normals(std::span<const Vec3f> positions,
                                       std::span<const std::array<std::uint32_t, 3>> triangles,
                                       ThreadPool& pool) {
  const std::size_t n = positions.size();
  std::vector<Vec3f> sums(n);
  // Every vertex adds its faces in face order, whoever owns it: the same bits for any threads.
  prep_detail::for_each_vertex_range(pool, n, [&](std::uint32_t lo, std::uint32_t hi) {
    const std::uint32_t size = hi - lo;
    for (const auto& t : triangles) {
      assert(t[0] < n && t[1] < n && t[2] < n);
      // v - lo < size (unsigned) tests lo <= v < hi.
      const std::uint32_t i0 = t[0] - lo, i1 = t[1] - lo, i2 = t[2] - lo;
      if (std::min({i0, i1, i2}) >= size) continue;
      const Vec3f a = positions[t[0]];
      const Vec3f face = cross(positions[t[1]] - a, positions[t[2]] - a);
      if (i0 < size) sums[t[0]] += face;
      if (i1 < size) sums[t[1]] += face;
      if (i2 < size) sums[t[2]] += face;
    }
    for (std::uint32_t v = lo; v < hi; ++v) sums[v] = normalized(sums[v], {0, 0, 1});
  });
  return sums;
}

}  // namespace pointillist
