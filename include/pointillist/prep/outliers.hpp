// Outlier removal for scans: stray returns (dust, birds, reflections, a leaf blown across the
// beam) float away from the surfaces and become large lone splats. Each point's measure is its
// mean distance to its nearest neighbours; a point is dropped when its measure is far above the
// median of its neighbours' measures. This is the statistical outlier filter of Rusu et al.
// ("Towards 3D point cloud based object maps for household environments", 2008) made local:
// compared with the whole scan, a region scanned more sparsely (farther from the scanner) would
// go too.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "pointillist/core/point_set.hpp"
#include "pointillist/core/progress.hpp"
#include "pointillist/core/thread_pool.hpp"

namespace pointillist {

struct OutlierOptions {
  // The mean distance to this many nearest neighbours is each point's measure, and its
  // neighbourhood. A cluster of strays of up to about half this many points reaches out to the
  // surface and is caught; raise it for larger clusters (the cost grows with it). >= 1.
  std::uint32_t neighbours = 16;
  // A point is an outlier when its measure exceeds `ratio` times the median of its neighbours'
  // measures. Lower drops more (sparse, ragged parts such as foliage first). > 1.
  float ratio = 3.0f;
};

// For each position, 1 when it is an outlier (see OutlierOptions), else 0. Fewer than
// neighbours + 1 points: none is. Throws OptionError for invalid options and Error naming the
// first non-finite position. Progress phase "neighbours". Deterministic for any thread count.
std::vector<std::uint8_t> find_outliers(std::span<const Vec3f> positions, ThreadPool& pool,
                                        Progress& progress = Progress::none(),
                                        const OutlierOptions& options = {});

// Removes the outliers of a point cloud (find_outliers) with their normals, colours and radii;
// returns how many were removed. Throws OptionError for a mesh (its faces define the surface;
// strays there are unreferenced vertices, which prepare_splats already drops).
std::size_t remove_outliers(PointSet& points, ThreadPool& pool,
                            Progress& progress = Progress::none(),
                            const OutlierOptions& options = {});

}  // namespace pointillist
