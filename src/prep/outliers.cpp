// Statistical outlier removal (see outliers.hpp).
#include "pointillist/prep/outliers.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "pointillist/core/error.hpp"
#include "ordered_cloud.hpp"

namespace pointillist {
namespace {

// Median of `v` (reordered).
float median_of(std::vector<float>& v) {
  const auto mid = v.begin() + std::ptrdiff_t(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

}  // namespace

std::vector<std::uint8_t> find_outliers(std::span<const Vec3f> positions, ThreadPool& pool,
                                        Progress& progress, const OutlierOptions& options) {
  if (options.neighbours < 1) {
    throw OptionError("outlier neighbours must be at least 1");
  }
  if (!(options.ratio > 1.0f) || !std::isfinite(options.ratio)) {
    throw OptionError("outlier ratio " + std::to_string(options.ratio) +
                      " is invalid; give a number above 1 (3 is usual)");
  }
  const std::size_t n = positions.size();
  std::vector<std::uint8_t> outlier(n, 0);
  if (n <= options.neighbours) return outlier;
  const prep_detail::OrderedCloud cloud =
      prep_detail::order_cloud(positions, options.neighbours, pool, progress);
  // Each point's mean distance to its neighbours, in Morton order.
  std::vector<float> measure(n);
  parallel_for(pool, n, 1 << 14, [&](std::size_t begin, std::size_t end) {
    for (std::size_t j = begin; j < end; ++j) {
      double sum = 0;
      for (const std::uint32_t q : cloud.row(j)) {
        sum += double(length(cloud.positions[q] - cloud.positions[j]));
      }
      measure[j] = float(sum / double(cloud.k));
    }
  });
  // Spacing varies by factors across a scan (near and far from the scanner, overlapping
  // strips), so each point is compared with its own neighbours: an outlier's neighbours are
  // much closer to theirs than it is to its own. A cluster of strays smaller than the
  // neighbourhood reaches out to the surface, whose points are the majority of its neighbours.
  parallel_for(pool, n, 1 << 14, [&](std::size_t begin, std::size_t end) {
    std::vector<float> theirs(cloud.k);
    for (std::size_t j = begin; j < end; ++j) {
      const auto row = cloud.row(j);
      for (std::size_t q = 0; q < row.size(); ++q) theirs[q] = measure[row[q]];
      const float median = median_of(theirs);
      outlier[cloud.order[j]] = median > 0.0f && measure[j] > options.ratio * median;
    }
  });
  return outlier;
}

std::size_t remove_outliers(PointSet& points, ThreadPool& pool, Progress& progress,
                            const OutlierOptions& options) {
  if (points.is_mesh()) {
    throw OptionError("outlier removal applies to point clouds; this input is a mesh (its "
                      "vertices used by no face are dropped anyway)");
  }
  const std::vector<std::uint8_t> outlier = find_outliers(points.positions, pool, progress, options);
  std::vector<std::uint8_t> keep(outlier.size());
  for (std::size_t i = 0; i < keep.size(); ++i) keep[i] = !outlier[i];
  return points.size() - keep_points(points, keep);
}

}  // namespace pointillist
