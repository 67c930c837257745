// Private to prep: a point cloud in Morton order with its k-nearest-neighbour graph, shared by
// PCA normals, their orientation and cloud radii so the neighbours are searched only once and
// every pass over the graph touches memory in spatial order.
#pragma once

#include <algorithm>
#include <cstdint>
#include <span>
#include <vector>

#include "pointillist/core/math.hpp"
#include "pointillist/core/progress.hpp"
#include "pointillist/core/thread_pool.hpp"

namespace pointillist::prep_detail {

struct OrderedCloud {
  std::vector<std::uint32_t> order;       // ordered index -> caller's index
  std::vector<Vec3f> positions;           // positions[j] = caller's positions[order[j]]
  std::vector<std::uint32_t> neighbours;  // k per point, nearest first, ordered indices
  std::uint32_t k = 0;

  std::size_t size() const { return positions.size(); }
  std::span<const std::uint32_t> row(std::size_t j) const {
    return std::span<const std::uint32_t>(neighbours).subspan(j * k, k);
  }
};

// Orders the points (morton_order) and finds the k nearest other points of each
// (progress phase "neighbours"). Throws Error naming the first point with a non-finite position.
OrderedCloud order_cloud(std::span<const Vec3f> positions, std::uint32_t k, ThreadPool& pool,
                         Progress& progress);

// out[order[j]] = in[j]: results computed in Morton order back to the caller's order.
template <class T>
std::vector<T> to_caller_order(const OrderedCloud& cloud, std::span<const T> in, ThreadPool& pool) {
  std::vector<T> out(in.size());
  parallel_for(pool, in.size(), 1 << 16, [&](std::size_t begin, std::size_t end) {
    for (std::size_t j = begin; j < end; ++j) out[cloud.order[j]] = in[j];
  });
  return out;
}

// Unit normals by PCA over each point and the first k - 1 entries of its neighbour row
// (Hoppe et al. 1992, section 3.2), unoriented, in Morton order (progress phase "normals").
std::vector<Vec3f> pca_normals_ordered(const OrderedCloud& cloud, std::uint32_t k, ThreadPool& pool,
                                       Progress& progress);

// Neighbours of a point in the orientation graph: the first 10 entries of the PCA rows (fewer
// when k is smaller). Hoppe's graph used the same k as the tangent planes; measured on the
// Stanford dragon's vertices against their mesh normals (2026-11-28), the 10 nearest flip fewer
// normals than the 15 that k = 16 gives (7.2 M vertices: 0.28 % against 0.34 %; 0.44 M: 0.66 %
// against 0.71 %) and take 0.79x the time.
constexpr std::uint32_t kOrientationNeighbours = 10;
inline std::uint32_t orientation_graph_k(std::uint32_t k) {
  return std::min(k - 1, kOrientationNeighbours);
}

// Flips normals in place so neighbours agree, propagating along minimum spanning trees of the
// symmetrized graph of the first `graph_k` neighbours inside pieces of the Morton order, then
// joining the pieces' components (Hoppe et al. 1992, section 3.3; normal_orientation.cpp);
// progress phase "orientation".
// `centre`: the point "away" is measured from; null: the cloud's centroid. `components`, when
// not null, receives each point's joined surface (oriented each on its own), numbered in the
// order of their first point, Morton order.
void orient_normals_ordered(const OrderedCloud& cloud, std::uint32_t graph_k,
                            std::span<Vec3f> normals, ThreadPool& pool, Progress& progress,
                            const Vec3f* centre = nullptr,
                            std::vector<std::uint32_t>* components = nullptr);

// Mean distance to the first `neighbours` entries of each row, capped at outlier_ratio × the
// median of the same over the row's first kOutlierNeighbours entries (all of them when the row
// is shorter; 0 = no cap), times `factor`, Morton order.
std::vector<float> cloud_radii_ordered(const OrderedCloud& cloud, std::uint32_t neighbours,
                                       float factor, float outlier_ratio, ThreadPool& pool,
                                       Progress& progress);

}  // namespace pointillist::prep_detail
