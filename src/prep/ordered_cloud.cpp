#include "ordered_cloud.hpp"

#include <sstream>

#include "pointillist/core/error.hpp"
#include "pointillist/spatial/knn.hpp"

namespace pointillist::prep_detail {

OrderedCloud order_cloud(std::span<const Vec3f> positions, std::uint32_t k, ThreadPool& pool,
                         Progress& progress) {
  for (std::size_t i = 0; i < positions.size(); ++i) {
    if (!is_finite(positions[i])) {
      std::ostringstream s;
      s << "point " << i << " has a non-finite position (" << positions[i].x << ", "
        << positions[i].y << ", " << positions[i].z
        << "); remove it before estimating normals or radii";
      throw Error(s.str());
    }
  }
  OrderedCloud cloud;
  cloud.k = k;
  cloud.order = morton_order(positions, pool);
  cloud.positions.resize(positions.size());
  parallel_for(pool, positions.size(), 1 << 16, [&](std::size_t begin, std::size_t end) {
    for (std::size_t j = begin; j < end; ++j) cloud.positions[j] = positions[cloud.order[j]];
  });
  cloud.neighbours = k_nearest_neighbours(cloud.positions, pool,
                                          {.k = k, .points_are_ordered = true}, nullptr, progress);
  return cloud;
}

}  // namespace pointillist::prep_detail
