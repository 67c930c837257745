// The bounding-sphere neighbour graph of a splat set (Ivo, eq. 3.1; specs/sharp-features.md
// §1.2): splats i and j are neighbours iff the distance between their centres is below the sum
// of their radii. Every pair of discs that cross is joined by an edge, whatever the sampling
// density on either side.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "pointillist/core/math.hpp"
#include "pointillist/core/progress.hpp"
#include "pointillist/core/thread_pool.hpp"

namespace pointillist {

// Compressed sparse rows, symmetric: the neighbours of splat i are
// neighbours[offsets[i] .. offsets[i + 1]), in increasing index order, i itself never among
// them. Every edge is stored in both rows.
struct NeighbourGraph {
  std::vector<std::uint64_t> offsets;  // size n + 1
  std::vector<std::uint32_t> neighbours;

  std::size_t vertex_count() const { return offsets.empty() ? 0 : offsets.size() - 1; }
  std::size_t edge_count() const { return neighbours.size() / 2; }  // undirected edges
  std::span<const std::uint32_t> row(std::size_t i) const {
    return {neighbours.data() + offsets[i], neighbours.data() + offsets[i + 1]};
  }
};

// The graph of eq. 3.1 with `radii` the radii the renderer draws: edge (i, j) iff
// |c_i − c_j| < r_i + r_j (strict). Built over a uniform grid of cells about two typical radii
// wide; each splat of ordinary size (at most 2 median radii) searches for its ordinary
// neighbours and writes its own row, and the few oversized splats search farther and are merged
// into their neighbours' rows after, so they do not slow every query. Parallel over blocks of
// splats; the result does not depend on the thread count. Positions and radii must be finite,
// radii >= 0. Memory: the graph (8 bytes an edge: both rows) plus about 24 bytes a splat; while
// the rows are joined they exist twice (and once more when oversized splats are merged in).
NeighbourGraph build_neighbour_graph(std::span<const Vec3f> centers, std::span<const float> radii,
                                     ThreadPool& pool, Progress& progress = Progress::none());

// The same graph by comparing every pair (n²/2 tests): the oracle of the tests and the baseline
// of the benchmark (the dissertation built it this way).
NeighbourGraph build_neighbour_graph_brute_force(std::span<const Vec3f> centers,
                                                 std::span<const float> radii);

}  // namespace pointillist
