// k-nearest-neighbour queries over a point set (nanoflann kd-tree).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "pointillist/core/math.hpp"
#include "pointillist/core/progress.hpp"
#include "pointillist/core/thread_pool.hpp"

namespace pointillist {

// For every point, the indices of its k nearest other points (itself excluded), nearest first,
// as a flat row-major array of n*k entries (fewer than k neighbours exist only when n <= k; then
// the missing entries repeat the last found neighbour, or the point itself when n == 1).
// `squared_distances`, when not null, receives the matching squared distances.
// Parallel over points; the result does not depend on the thread count.
struct KnnOptions {
  std::uint32_t k = 16;
};
std::vector<std::uint32_t> k_nearest_neighbours(std::span<const Vec3f> points, ThreadPool& pool,
                                                const KnnOptions& options,
                                                std::vector<float>* squared_distances = nullptr,
                                                Progress& progress = Progress::none());

// Permutation that sorts points along a Morton (Z-order) curve over their bounding box;
// neighbour queries and tree builds run several times faster on spatially ordered input.
std::vector<std::uint32_t> morton_order(std::span<const Vec3f> points, ThreadPool& pool);

}  // namespace pointillist
