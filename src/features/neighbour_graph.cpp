// The bounding-sphere graph over a uniform grid.
//
// Every splat of ordinary size finds all its neighbours of ordinary size itself (a search box of
// ±(r_i + r_cut), r_cut = 2 median radii or the largest radius if smaller) and writes its own
// row, sorted: no edge crosses between threads, so the rows need no merging and do not depend
// on the thread count. The few oversized splats (r > r_cut: isolated points of a scan) search
// ±(r_i + r_max) for all their neighbours, and their edges to ordinary splats are then merged
// into those splats' rows, so that one huge splat does not widen everybody's search.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <utility>

#include "pointillist/features/neighbour_graph.hpp"

namespace pointillist {
namespace {

// The test of eq. 3.1, written once so that the grid build and the brute force agree bit for bit
// (it is symmetric in i and j: negation and addition are exact in both orders).
inline bool spheres_overlap(Vec3f ci, float ri, Vec3f cj, float rj) {
  const float reach = ri + rj;
  return length_squared(ci - cj) < reach * reach;
}

struct Grid {
  float median_radius = 0;
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
  g.median_radius = sorted[sorted.size() / 2];
  float cell = 2.0f * g.median_radius;
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

// Four floats as one value (GCC and Clang vector extensions): the candidate test runs on four
// candidates at once on any target, with the scalar test's exact rounding.
using Lanes = float __attribute__((vector_size(16)));

using Index4 = std::uint32_t __attribute__((vector_size(16)));

// For each 4-bit mask of passing lanes, their lane numbers first (the rest is never read).
constexpr Index4 kPack[16] = {
    {0, 0, 0, 0}, {0, 0, 0, 0}, {1, 0, 0, 0}, {0, 1, 0, 0}, {2, 0, 0, 0}, {0, 2, 0, 0},
    {1, 2, 0, 0}, {0, 1, 2, 0}, {3, 0, 0, 0}, {0, 3, 0, 0}, {1, 3, 0, 0}, {0, 1, 3, 0},
    {2, 3, 0, 0}, {0, 2, 3, 0}, {1, 2, 3, 0}, {0, 1, 2, 3}};

// How many lanes pass, per mask (a table: the baseline x86-64 target has no popcount).
constexpr std::uint8_t kPassing[16] = {0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4};

// The lanes of a group of four that lie before the end of the run, `left` candidates on.
inline unsigned tail_mask(std::uint32_t left) { return left >= 4 ? 15u : (1u << left) - 1u; }

// The bounding spheres in cell order, one array a coordinate, so that a run of cells' candidates
// is read four at a time; 4 NaN entries of padding make a read past the last one harmless.
// Spheres wider than r_keep get NaN centres: no test accepts them.
struct Candidates {
  std::vector<float> x, y, z, r;

  Candidates() = default;
  Candidates(std::span<const Vec3f> centers, std::span<const float> radii,
             std::span<const std::uint32_t> order, float r_keep) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const std::size_t n = order.size();
    for (std::vector<float>* v : {&x, &y, &z, &r}) v->assign(n + 4, nan);
    for (std::size_t k = 0; k < n; ++k) {
      const std::uint32_t i = order[k];
      const bool kept = radii[i] <= r_keep;
      x[k] = kept ? centers[i].x : nan;
      y[k] = kept ? centers[i].y : nan;
      z[k] = kept ? centers[i].z : nan;
      r[k] = radii[i];
    }
  }
  static Lanes lanes(const std::vector<float>& v, std::size_t k) {
    Lanes out;
    std::memcpy(&out, v.data() + k, sizeof out);
    return out;
  }
};

// Writes the distinct values v[0..n) to out in increasing order. Rows are short (a dozen
// neighbours on a surface): each value's place is the count of smaller ones, found without a
// branch, which is cheaper there than any comparison sort's mispredicted branches.
void sort_distinct(const std::uint32_t* v, std::size_t n, std::uint32_t* out) {
  if (n > 48) {
    std::copy(v, v + n, out);
    std::sort(out, out + n);
    return;
  }
  for (std::size_t a = 0; a < n; ++a) {
    std::uint32_t rank = 0;
    for (std::size_t b = 0; b < n; ++b) rank += v[b] < v[a];
    out[rank] = v[a];
  }
}

// Adds each oversized splat (radius > r_cut) to the rows of its ordinary neighbours: its own
// row is complete, theirs did not look that far. Rows stay sorted.
void merge_oversized(NeighbourGraph& graph, std::span<const float> radii, float r_cut) {
  const std::size_t n = graph.vertex_count();
  std::vector<std::pair<std::uint32_t, std::uint32_t>> extra;  // (ordinary row, oversized)
  for (std::size_t b = 0; b < n; ++b) {
    if (radii[b] <= r_cut) continue;
    for (std::uint32_t s : graph.row(b)) {
      if (radii[s] <= r_cut) extra.emplace_back(s, static_cast<std::uint32_t>(b));
    }
  }
  if (extra.empty()) return;
  std::sort(extra.begin(), extra.end());
  NeighbourGraph merged;
  merged.offsets.assign(n + 1, 0);
  merged.neighbours.reserve(graph.neighbours.size() + extra.size());
  std::size_t e = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const auto row = graph.row(i);
    const std::size_t begin = merged.neighbours.size();
    merged.neighbours.insert(merged.neighbours.end(), row.begin(), row.end());
    for (; e < extra.size() && extra[e].first == i; ++e) merged.neighbours.push_back(extra[e].second);
    std::inplace_merge(merged.neighbours.begin() + static_cast<std::ptrdiff_t>(begin),
                       merged.neighbours.begin() + static_cast<std::ptrdiff_t>(begin + row.size()),
                       merged.neighbours.end());
    merged.offsets[i + 1] = merged.neighbours.size();
  }
  graph = std::move(merged);
}

}  // namespace

NeighbourGraph build_neighbour_graph(std::span<const Vec3f> centers, std::span<const float> radii,
                                     ThreadPool& pool, Progress& progress) {
  const std::size_t n = centers.size();
  if (n == 0) return NeighbourGraph{{0}, {}};
  ProgressPhase phase(progress, "neighbour graph", n);
  const Grid grid = make_grid(centers, radii);
  const float r_max = *std::max_element(radii.begin(), radii.end());
  const float r_cut = std::min(r_max, 2.0f * grid.median_radius);
  // What ordinary splats search has the oversized splats' centres made NaN, so that the overlap
  // test itself refuses them (they add their own edges) and the loop tests nothing else.
  const Candidates ordinary(centers, radii, grid.order, r_cut);
  const Candidates all = r_cut < r_max ? Candidates(centers, radii, grid.order, r_max) : Candidates{};

  // Blocks of splats in index order, each block's rows in one array, then concatenated.
  constexpr std::size_t kBlock = 2048;
  const std::size_t block_count = (n + kBlock - 1) / kBlock;
  std::vector<std::vector<std::uint32_t>> rows(block_count);
  NeighbourGraph graph;
  graph.offsets.assign(n + 1, 0);
  pool.run(block_count, [&](std::size_t b) {
    std::vector<std::uint32_t>& out = rows[b];
    // Positions (in cell order) of the candidates that pass, written without a branch: the
    // test's outcome is close to random, and mispredicting it cost more than the test.
    std::vector<std::uint32_t> hits(256);
    const std::size_t end = std::min(n, (b + 1) * kBlock);
    for (std::size_t i = b * kBlock; i < end; ++i) {
      const Vec3f ci = centers[i];
      const float ri = radii[i];
      const bool oversized = ri > r_cut;
      // Widened so that rounding in the box and cell arithmetic never drops a neighbour the
      // exact test accepts.
      const float reach = (ri + (oversized ? r_max : r_cut)) * 1.0001f;
      int lo[3], hi[3];
      for (int a = 0; a < 3; ++a) {
        lo[a] = grid.clamp_axis(ci[a] - reach, a);
        hi[a] = grid.clamp_axis(ci[a] + reach, a);
      }
      const Candidates& cand = oversized ? all : ordinary;
      const Lanes cx = ci.x - Lanes{}, cy = ci.y - Lanes{}, cz = ci.z - Lanes{},
                  cr = ri - Lanes{};
      std::size_t count = 0;
      for (int z = lo[2]; z <= hi[2]; ++z) {
        for (int y = lo[1]; y <= hi[1]; ++y) {
          const std::size_t row = (static_cast<std::size_t>(z) * grid.dims[1] + y) * grid.dims[0];
          const std::uint32_t first = grid.cell_start[row + lo[0]];
          const std::uint32_t last = grid.cell_start[row + hi[0] + 1];
          if (hits.size() < count + (last - first) + 4) hits.resize(2 * (count + (last - first) + 4));
          std::uint32_t* const slots = hits.data();
          for (std::uint32_t k = first; k < last; k += 4) {
            // The same operations in the same order as spheres_overlap, four candidates at a time.
            const Lanes dx = cx - cand.lanes(cand.x, k), dy = cy - cand.lanes(cand.y, k),
                        dz = cz - cand.lanes(cand.z, k);
            Lanes reach_sum = cr + cand.lanes(cand.r, k);
            const auto inside = dx * dx + dy * dy + dz * dz < reach_sum * reach_sum;
            const unsigned mask = ((inside[0] & 1) | (inside[1] & 2) | (inside[2] & 4) |
                                   (inside[3] & 8)) & tail_mask(last - k);
            // The passing lanes' positions, packed to the front of four slots.
            const Index4 packed = k + kPack[mask];
            std::memcpy(slots + count, &packed, sizeof packed);
            count += kPassing[mask];
          }
        }
      }
      // The hits' indices, i itself dropped, written back over the hits (each index is read
      // before its slot can be overwritten), then sorted into the row.
      std::size_t kept = 0;
      for (std::size_t h = 0; h < count; ++h) {
        const std::uint32_t j = grid.order[hits[h]];
        hits[kept] = j;
        kept += j != i;
      }
      const std::size_t first_entry = out.size();
      out.resize(first_entry + kept);
      sort_distinct(hits.data(), kept, out.data() + first_entry);
      graph.offsets[i + 1] = out.size() - first_entry;
    }
    progress.advance(end - b * kBlock);
  });
  for (std::size_t i = 0; i < n; ++i) graph.offsets[i + 1] += graph.offsets[i];
  graph.neighbours.resize(graph.offsets[n]);
  pool.run(block_count, [&](std::size_t b) {
    std::copy(rows[b].begin(), rows[b].end(),
              graph.neighbours.begin() + static_cast<std::ptrdiff_t>(graph.offsets[b * kBlock]));
  });
  if (r_cut < r_max) merge_oversized(graph, radii, r_cut);
  return graph;
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
