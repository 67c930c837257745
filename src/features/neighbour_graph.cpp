// The bounding-sphere graph over a uniform grid.
//
// Each splat i looks for the neighbours j it "owns": r_j < r_i, or r_j = r_i and j < i. Such a
// neighbour lies within r_i + r_j <= 2·r_i, so the search box is ±2·r_i whatever the largest
// radius of the set, and every edge is found exactly once, by its larger splat. The rows are
// then filled from both ends of every edge (in parallel, in any order) and sorted, which makes
// the result independent of the thread count.
#include <algorithm>
#include <atomic>
#include <cmath>

#include "pointillist/features/neighbour_graph.hpp"

namespace pointillist {
namespace {

// The test of eq. 3.1, written once so that the grid build and the brute force agree bit for bit
// (it is symmetric in i and j: negation and addition are exact in both orders).
inline bool spheres_overlap(Vec3f ci, float ri, Vec3f cj, float rj) {
  const float reach = ri + rj;
  return length_squared(ci - cj) < reach * reach;
}

inline bool owns(float ri, std::uint32_t i, float rj, std::uint32_t j) {
  return rj < ri || (rj == ri && j < i);
}

struct Grid {
  Vec3f origin;
  float inv_cell = 1;
  int dims[3] = {1, 1, 1};
  std::vector<std::uint32_t> cell_start;  // per cell, into order; size cells + 1
  std::vector<std::uint32_t> order;       // splat indices by cell, increasing within a cell

  int clamp_axis(float v, int axis) const {
    const float c = std::floor((v - origin[axis]) * inv_cell);
    return static_cast<int>(std::clamp(c, 0.0f, static_cast<float>(dims[axis] - 1)));
  }
  std::size_t cell_of(Vec3f p) const {
    return (static_cast<std::size_t>(clamp_axis(p.z, 2)) * dims[1] + clamp_axis(p.y, 1)) * dims[0] +
           clamp_axis(p.x, 0);
  }
};

// Cells two typical (median) radii wide, made larger when the box would need more than about
// 2 cells a splat (a few huge splats, or radii near zero).
Grid make_grid(std::span<const Vec3f> centers, std::span<const float> radii) {
  Grid g;
  Aabb box;
  for (Vec3f c : centers) box.extend(c);
  g.origin = box.lo;
  const Vec3f ext = box.extent();
  std::vector<float> sorted(radii.begin(), radii.end());
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  float cell = 2.0f * sorted[sorted.size() / 2];
  const double max_cells = 2.0 * static_cast<double>(centers.size()) + 64.0;
  const float longest = std::max({ext.x, ext.y, ext.z, 1e-30f});
  if (!(cell > longest * 1e-6f)) cell = longest / std::cbrt(static_cast<float>(max_cells));
  for (;;) {
    double cells = 1;
    for (int a = 0; a < 3; ++a) cells *= std::floor(ext[a] / cell) + 1.0;
    if (cells <= max_cells) break;
    cell *= static_cast<float>(std::cbrt(cells / max_cells)) * 1.01f;
  }
  g.inv_cell = 1.0f / cell;
  for (int a = 0; a < 3; ++a) g.dims[a] = static_cast<int>(std::floor(ext[a] / cell)) + 1;
  const std::size_t cells = static_cast<std::size_t>(g.dims[0]) * g.dims[1] * g.dims[2];
  g.cell_start.assign(cells + 1, 0);
  std::vector<std::uint32_t> cell_of(centers.size());
  for (std::size_t i = 0; i < centers.size(); ++i) {
    cell_of[i] = static_cast<std::uint32_t>(g.cell_of(centers[i]));
    ++g.cell_start[cell_of[i] + 1];
  }
  for (std::size_t c = 0; c < cells; ++c) g.cell_start[c + 1] += g.cell_start[c];
  g.order.resize(centers.size());
  std::vector<std::uint32_t> cursor(g.cell_start.begin(), g.cell_start.end() - 1);
  for (std::size_t i = 0; i < centers.size(); ++i) {
    g.order[cursor[cell_of[i]]++] = static_cast<std::uint32_t>(i);
  }
  return g;
}

// CSR from the owned edges of every block: degrees, offsets, rows filled from both ends, rows
// sorted.
NeighbourGraph assemble(std::size_t n, const std::vector<std::vector<std::uint32_t>>& blocks,
                        ThreadPool& pool) {
  std::vector<std::atomic<std::uint32_t>> degree(n);
  pool.run(blocks.size(), [&](std::size_t b) {
    const std::vector<std::uint32_t>& e = blocks[b];
    for (std::size_t k = 0; k < e.size(); k += 2) {
      degree[e[k]].fetch_add(1, std::memory_order_relaxed);
      degree[e[k + 1]].fetch_add(1, std::memory_order_relaxed);
    }
  });
  NeighbourGraph graph;
  graph.offsets.resize(n + 1);
  graph.offsets[0] = 0;
  for (std::size_t i = 0; i < n; ++i) graph.offsets[i + 1] = graph.offsets[i] + degree[i].load();
  graph.neighbours.resize(graph.offsets[n]);
  for (std::size_t i = 0; i < n; ++i) degree[i].store(0, std::memory_order_relaxed);
  pool.run(blocks.size(), [&](std::size_t b) {
    const std::vector<std::uint32_t>& e = blocks[b];
    for (std::size_t k = 0; k < e.size(); k += 2) {
      const std::uint32_t i = e[k], j = e[k + 1];
      graph.neighbours[graph.offsets[i] + degree[i].fetch_add(1, std::memory_order_relaxed)] = j;
      graph.neighbours[graph.offsets[j] + degree[j].fetch_add(1, std::memory_order_relaxed)] = i;
    }
  });
  constexpr std::size_t kRowsPerTask = 4096;
  pool.run((n + kRowsPerTask - 1) / kRowsPerTask, [&](std::size_t t) {
    const std::size_t end = std::min(n, (t + 1) * kRowsPerTask);
    for (std::size_t i = t * kRowsPerTask; i < end; ++i) {
      std::sort(graph.neighbours.begin() + static_cast<std::ptrdiff_t>(graph.offsets[i]),
                graph.neighbours.begin() + static_cast<std::ptrdiff_t>(graph.offsets[i + 1]));
    }
  });
  return graph;
}

}  // namespace

NeighbourGraph build_neighbour_graph(std::span<const Vec3f> centers, std::span<const float> radii,
                                     ThreadPool& pool, Progress& progress) {
  const std::size_t n = centers.size();
  if (n == 0) return NeighbourGraph{{0}, {}};
  ProgressPhase phase(progress, "neighbour graph", n);
  const Grid grid = make_grid(centers, radii);
  // Centres and radii in cell order, so that a cell's candidates are read contiguously.
  std::vector<Vec3f> cell_centers(n);
  std::vector<float> cell_radii(n);
  for (std::size_t k = 0; k < n; ++k) {
    cell_centers[k] = centers[grid.order[k]];
    cell_radii[k] = radii[grid.order[k]];
  }
  // Splats in cell order, so that neighbouring queries read neighbouring memory.
  constexpr std::size_t kBlock = 2048;
  std::vector<std::vector<std::uint32_t>> blocks((n + kBlock - 1) / kBlock);
  pool.run(blocks.size(), [&](std::size_t b) {
    std::vector<std::uint32_t>& edges = blocks[b];
    const std::size_t end = std::min(n, (b + 1) * kBlock);
    for (std::size_t s = b * kBlock; s < end; ++s) {
      const std::uint32_t i = grid.order[s];
      const Vec3f ci = centers[i];
      const float ri = radii[i];
      // 2·r_i, widened so that rounding in the box and cell arithmetic never drops a neighbour
      // the exact test accepts.
      const float reach = 2.0f * ri * 1.0001f;
      int lo[3], hi[3];
      for (int a = 0; a < 3; ++a) {
        lo[a] = grid.clamp_axis(ci[a] - reach, a);
        hi[a] = grid.clamp_axis(ci[a] + reach, a);
      }
      for (int z = lo[2]; z <= hi[2]; ++z) {
        for (int y = lo[1]; y <= hi[1]; ++y) {
          const std::size_t row = (static_cast<std::size_t>(z) * grid.dims[1] + y) * grid.dims[0];
          const std::uint32_t first = grid.cell_start[row + lo[0]];
          const std::uint32_t last = grid.cell_start[row + hi[0] + 1];
          for (std::uint32_t k = first; k < last; ++k) {
            const float rj = cell_radii[k];
            if (rj <= ri && spheres_overlap(ci, ri, cell_centers[k], rj)) {
              const std::uint32_t j = grid.order[k];
              if (owns(ri, i, rj, j)) {
                edges.push_back(i);
                edges.push_back(j);
              }
            }
          }
        }
      }
    }
    progress.advance(end - b * kBlock);
  });
  return assemble(n, blocks, pool);
}

NeighbourGraph build_neighbour_graph_brute_force(std::span<const Vec3f> centers,
                                                 std::span<const float> radii) {
  const std::size_t n = centers.size();
  std::vector<std::vector<std::uint32_t>> rows(n);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      if (spheres_overlap(centers[i], radii[i], centers[j], radii[j])) {
        rows[i].push_back(static_cast<std::uint32_t>(j));
        rows[j].push_back(static_cast<std::uint32_t>(i));
      }
    }
  }
  NeighbourGraph graph;
  graph.offsets.resize(n + 1);
  graph.offsets[0] = 0;
  for (std::size_t i = 0; i < n; ++i) {
    graph.offsets[i + 1] = graph.offsets[i] + rows[i].size();
    graph.neighbours.insert(graph.neighbours.end(), rows[i].begin(), rows[i].end());
  }
  return graph;
}

}  // namespace pointillist
