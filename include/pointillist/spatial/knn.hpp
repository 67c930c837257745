// k-nearest-neighbour queries over a point set (a grid of Morton cells, a nanoflann kd-tree for
// what the grid cannot answer).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "pointillist/core/math.hpp"
#include "pointillist/core/morton.hpp"
#include "pointillist/core/progress.hpp"
#include "pointillist/core/thread_pool.hpp"

namespace pointillist {

// How many queries each search answered (for tests and benchmarks).
struct KnnPaths {
  std::uint64_t grid = 0;  // from their cell's 3x3x3 block
  std::uint64_t wide = 0;  // from a wider block of cells around it
  std::uint64_t tree = 0;  // from the kd-tree
};

struct KnnOptions {
  std::uint32_t k = 16;  // neighbours per point (the point itself not counted)
  // The caller has already put the points in spatial order (e.g. by `morton_order`): skip the
  // internal reordering. Queries on shuffled points with this set run several times slower.
  bool points_are_ordered = false;
  KnnPaths* paths = nullptr;  // when not null, receives the count each search answered
};

// For every point, the indices of its k nearest other points (itself excluded), nearest first,
// as a flat row-major array of n*k entries: row i is entries [i*k, i*k + k) and belongs to
// points[i] (rows are in the caller's order, whatever order the queries run in). Fewer than k
// neighbours exist only when n <= k; then the missing entries repeat the last found neighbour,
// or the point itself when n == 1. `squared_distances`, when not null, receives the matching
// squared Euclidean distances (n*k entries).
// Equal distances: of several equidistant points at the k-th place, those with the lowest
// positions (x, then y, then z) make the cut, so the same neighbours are found in any subset of
// the points that holds them; within a row, equal distances are ordered by index. (Queries are
// answered from a grid of cells over the ordered points; a query whose k nearest could reach
// beyond its cell's 3x3x3 block, a stray point in a sparse region, is asked again of the 5^3
// and 9^3 blocks around it, then (or when there are more than 4,096 such queries) of a kd-tree
// over all the points, which finds up to 9 points tied at the cut and cuts more as it finds
// them.) Copies of a point
// (distance 0) are neighbours like any other point. Parallel over points (progress phase
// "neighbours"); the result does not depend on the thread count. Positions must be finite.
// Memory: the result plus about 30 bytes per point for the grid (40 more while a kd-tree lives).
std::vector<std::uint32_t> k_nearest_neighbours(std::span<const Vec3f> points, ThreadPool& pool,
                                                const KnnOptions& options,
                                                std::vector<float>* squared_distances = nullptr,
                                                Progress& progress = Progress::none());

}  // namespace pointillist
