// k nearest neighbours over spatially ordered points. Most queries are answered from a grid of
// Morton cells (the cells of morton_order, grouped 2^level a side): the points of a cell's
// 3x3x3 block are gathered once and searched for every point of the cell, and a query whose
// k-th distance could reach past its block is asked again of a nanoflann kd-tree. Both give the
// exact answer, so which one answers a query never shows.
#include "pointillist/spatial/knn.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cassert>
#include <cmath>
#include <limits>
#include <nanoflann.hpp>
#if defined(__AVX2__)
#include <immintrin.h>
#endif

namespace pointillist {
namespace {

// Points per chunk of queries: enough to amortize task overhead, small enough to balance.
constexpr std::size_t kQueryGrain = 4096;
// Leaf size of the kd-tree; 16 measured faster than nanoflann's default 10 for k = 16 here.
constexpr std::size_t kLeafSize = 16;
// The grid's cells hold about this many points on average (its level is chosen so).
constexpr double kCellPoints = 8;
// A block with more candidates than this leaves its queries to the kd-tree (piles of copies).
constexpr std::size_t kMaxCandidates = 4096;
// Below this many points the kd-tree answers every query.
constexpr std::size_t kGridMinPoints = 64;
// Up to this many misses of the grid are asked again of wider blocks before a kd-tree is built
// over all the points for them.
constexpr std::size_t kWideMisses = 4096;

struct CloudAdaptor {
  std::span<const Vec3f> points;
  std::size_t kdtree_get_point_count() const { return points.size(); }
  float kdtree_get_pt(std::uint32_t i, std::size_t dim) const { return points[i][int(dim)]; }
  template <class Box>
  bool kdtree_get_bbox(Box&) const {
    return false;
  }
};

using Metric = nanoflann::L2_Simple_Adaptor<float, CloudAdaptor, float, std::uint32_t>;
using KdTree = nanoflann::KDTreeSingleIndexAdaptor<Metric, CloudAdaptor, 3, std::uint32_t>;

struct Neighbour {
  float d2;
  std::uint32_t index;  // in the caller's order
};

// Nearer first, equal distances by index: the order of a row.
bool closer(const Neighbour& x, const Neighbour& y) {
  return x.d2 < y.d2 || (x.d2 == y.d2 && x.index < y.index);
}

// The squared distance as the kd-tree's metric sums it (x, then y, then z), so both paths give
// the same bits (this file is compiled without floating-point contraction).
inline float squared_distance(const Vec3f& q, float x, float y, float z) {
  float r = 0.0f;
  float d = q.x - x;
  r += d * d;
  d = q.y - y;
  r += d * d;
  d = q.z - z;
  r += d * d;
  return r;
}

// Finishes a row sorted by distance that holds every point tied with its k-th: equal distances
// at the k-th place go to the lowest positions (x, then y, then z), then equal distances are
// ordered by index; writes the row (padded by its last entry, or the point itself) to out.
void finish_row(std::vector<Neighbour>& row, std::size_t k, std::span<const Vec3f> points,
                std::uint32_t self, std::uint32_t* out, float* out_d2) {
  if (row.size() > k) {
    const float cut = row[k - 1].d2;
    std::size_t first = k - 1, last = k;
    while (first > 0 && row[first - 1].d2 == cut) --first;
    while (last < row.size() && row[last].d2 == cut) ++last;
    if (last > k) {
      const auto position = [&](const Neighbour& nb) {
        const Vec3f p = points[nb.index];
        return std::array<float, 3>{p.x, p.y, p.z};
      };
      std::sort(row.begin() + std::ptrdiff_t(first), row.begin() + std::ptrdiff_t(last),
                [&](const Neighbour& a, const Neighbour& b) {
                  const auto pa = position(a), pb = position(b);
                  return pa < pb || (pa == pb && a.index < b.index);
                });
    }
    row.resize(k);
  }
  // Order equal distances by index (insertion sort, ~linear).
  for (std::size_t i = 1; i < row.size(); ++i) {
    const Neighbour x = row[i];
    std::size_t m = i;
    for (; m > 0 && row[m - 1].d2 == x.d2 && row[m - 1].index > x.index; --m) row[m] = row[m - 1];
    row[m] = x;
  }
  const Neighbour pad = row.empty() ? Neighbour{0.0f, self} : row.back();
  for (std::size_t i = 0; i < k; ++i) {
    const Neighbour& nb = i < row.size() ? row[i] : pad;
    out[i] = nb.index;
    if (out_d2) out_d2[i] = nb.d2;
  }
}

// The grid: Morton cells of one level over spatially ordered points, each a run of them.
struct CellGrid {
  MortonFrame frame;
  int level = 0;                        // cells of 2^level Morton cells a side
  std::vector<std::uint64_t> key;       // each cell's Morton code at its level, ascending
  std::vector<std::uint32_t> begin;     // each cell's first point; one more entry: n
  std::vector<std::uint32_t> table;     // open addressing: cell index + 1, or 0
  std::uint64_t mask = 0;

  // True when every point outside the cells within r of cell a (on each axis) lies farther
  // from q than sqrt(d2), so those cells hold all of q's neighbours up to there: measured in
  // cells of the Morton grid, less 2 for the rounding of both cell assignments; sides at the
  // grid's edge have no points beyond them.
  bool vouches(Vec3f q, const std::array<std::uint32_t, 3>& a, std::uint32_t r,
               float d2) const {
    const std::uint32_t side = MortonFrame::kMaxCell >> level;
    const double cell_units = double(1u << level), scale = frame.scale;
    const float u[3] = {(q.x - frame.lo.x) * frame.scale, (q.y - frame.lo.y) * frame.scale,
                        (q.z - frame.lo.z) * frame.scale};
    double reach = std::numeric_limits<double>::infinity();
    for (int axis = 0; axis < 3; ++axis) {
      if (a[axis] >= r) {
        reach = std::min(reach, double(u[axis]) - (double(a[axis]) - r) * cell_units);
      }
      if (a[axis] + r <= side) {
        reach = std::min(reach, (double(a[axis]) + r + 1) * cell_units - double(u[axis]));
      }
    }
    reach = reach - 2;
    return reach > 0 && double(d2) * scale * scale < reach * reach * (1 - 1e-5);
  }

  // A point's Morton code at the grid's level, and a cell's coordinates from it.
  std::uint64_t cell_key(std::uint64_t code) const {
    return 3 * level >= 64 ? 0 : code >> (3 * level);
  }
  static std::array<std::uint32_t, 3> cell_coords(std::uint64_t key) {
    return {compact_bits_21(key), compact_bits_21(key >> 1), compact_bits_21(key >> 2)};
  }

  std::uint64_t slot(std::uint64_t k) const { return (k * 0x9E3779B97F4A7C15ULL) >> 20 & mask; }
  std::uint32_t find(std::uint64_t k) const {  // cell index + 1, or 0
    for (std::uint64_t h = slot(k);; h = (h + 1) & mask) {
      const std::uint32_t c = table[h];
      if (c == 0 || key[c - 1] == k) return c;
    }
  }
};

// Builds the grid when the points are in Morton order (false otherwise): the level at which
// cells hold about kCellPoints points on average.
bool build_grid(std::span<const Vec3f> points, CellGrid& g) {
  const std::size_t n = points.size();
  g.frame = MortonFrame::of(points);
  std::vector<std::uint64_t> code(n);
  for (std::size_t i = 0; i < n; ++i) code[i] = g.frame.code(points[i]);
  // Cells at level m differ between neighbours in the order whose codes differ above bit 3m.
  std::array<std::size_t, MortonFrame::kBits + 1> differ{};
  for (std::size_t i = 1; i < n; ++i) {
    const std::uint64_t x = code[i] ^ code[i - 1];
    if (code[i] < code[i - 1]) return false;
    if (x != 0) ++differ[std::size_t(63 - std::countl_zero(x)) / 3];
  }
  std::size_t cells = 1;
  for (std::size_t m = 0; m <= MortonFrame::kBits; ++m) cells += differ[m];
  g.level = 0;
  for (int m = 0; m <= MortonFrame::kBits; ++m) {
    if (double(n) / double(cells) >= kCellPoints) break;
    cells -= differ[std::size_t(m)];
    g.level = m + 1;
  }
  g.key.clear();
  g.begin.clear();
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint64_t k = g.cell_key(code[i]);
    if (g.key.empty() || g.key.back() != k) {
      g.key.push_back(k);
      g.begin.push_back(std::uint32_t(i));
    }
  }
  g.begin.push_back(std::uint32_t(n));
  const std::size_t capacity = std::bit_ceil(std::max<std::size_t>(2 * g.key.size(), 16));
  g.mask = capacity - 1;
  g.table.assign(capacity, 0);
  for (std::size_t c = 0; c < g.key.size(); ++c) {
    std::uint64_t h = g.slot(g.key[c]);
    while (g.table[h] != 0) h = (h + 1) & g.mask;
    g.table[h] = std::uint32_t(c + 1);
  }
  return true;
}

// Lanes of the vector filter and of the rank count's padding.
constexpr std::size_t kLanes = 8;

// Writes the distances d[i] <= limit (NaN never) and their i to out_d, out_i, in order of i;
// returns their count. out_d and out_i have room for m entries (a vector step stores whole
// vectors, but at out + count <= i with i + kLanes <= m).
std::size_t within_limit(const float* d, std::size_t m, float limit, float* out_d,
                         std::uint32_t* out_i) {
  std::size_t count = 0, i = 0;
#if defined(__AVX2__)
  // Eight at a time: the lanes that pass, moved to the front by a permutation looked up from
  // their mask (three bits a lane), stored whole; the count advances by the lanes that passed.
  static constexpr auto kPack = [] {
    std::array<std::uint64_t, 256> t{};
    for (std::uint32_t mask = 0; mask < 256; ++mask) {
      std::uint64_t packed = 0;
      int at = 0;
      for (int lane = 0; lane < 8; ++lane) {
        if (mask >> lane & 1) packed |= std::uint64_t(lane) << (8 * at++);
      }
      t[mask] = packed;
    }
    return t;
  }();
  const __m256 lim = _mm256_set1_ps(limit);
  for (; i + kLanes <= m; i += kLanes) {
    const __m256 v = _mm256_loadu_ps(d + i);
    const auto mask = unsigned(_mm256_movemask_ps(_mm256_cmp_ps(v, lim, _CMP_LE_OQ)));
    const __m256i lanes = _mm256_cvtepu8_epi32(_mm_cvtsi64_si128(std::int64_t(kPack[mask])));
    _mm256_storeu_ps(out_d + count, _mm256_permutevar8x32_ps(v, lanes));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(out_i + count),
                        _mm256_add_epi32(lanes, _mm256_set1_epi32(int(i))));
    count += std::size_t(std::popcount(mask));
  }
#endif
  for (; i < m; ++i) {
    out_d[count] = d[i];
    out_i[count] = std::uint32_t(i);
    count += d[i] <= limit;
  }
  return count;
}

// Answers the queries of cells [cell_begin, cell_end) from their blocks; queries whose answer
// the block cannot vouch for go to `missed`.
void grid_queries(const CellGrid& g, std::size_t cell_begin, std::size_t cell_end,
                  std::span<const Vec3f> tree_points, std::span<const Vec3f> points,
                  const std::uint32_t* order, std::size_t k, std::uint32_t* result,
                  float* result_d2, std::vector<std::uint32_t>& missed) {
  float guess = 0;  // a squared distance that k candidates are expected to be within
  std::vector<float> cx, cy, cz;
  std::vector<std::uint32_t> cj;
  std::vector<Neighbour> near, row;
  std::vector<float> cd, kd;  // candidates' and entries' squared distances
  std::vector<std::uint32_t> ki;
  const auto original = [&](std::uint32_t j) { return order ? order[j] : j; };
  const std::uint32_t side = MortonFrame::kMaxCell >> g.level;  // the last cell on each axis
  for (std::size_t c = cell_begin; c < cell_end; ++c) {
    const std::array<std::uint32_t, 3> a = CellGrid::cell_coords(g.key[c]);
    // Gather the block: the cell itself first (its points are the likeliest neighbours).
    std::array<std::uint32_t, 27> block;
    std::size_t block_cells = 0;
    block[block_cells++] = std::uint32_t(c);
    for (int dz = -1; dz <= 1; ++dz) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          if (dx == 0 && dy == 0 && dz == 0) continue;
          const std::int64_t b[3] = {std::int64_t(a[0]) + dx, std::int64_t(a[1]) + dy,
                                     std::int64_t(a[2]) + dz};
          if (b[0] < 0 || b[1] < 0 || b[2] < 0 || b[0] > side || b[1] > side || b[2] > side) {
            continue;
          }
          const std::uint32_t found = g.find(
              morton_code(std::uint32_t(b[0]), std::uint32_t(b[1]), std::uint32_t(b[2])));
          if (found) block[block_cells++] = found - 1;
        }
      }
    }
    std::size_t m = 0;
    for (std::size_t b = 0; b < block_cells; ++b) m += g.begin[block[b] + 1] - g.begin[block[b]];
    if (m > kMaxCandidates || m <= k) {
      for (std::uint32_t j = g.begin[c]; j < g.begin[c + 1]; ++j) missed.push_back(j);
      continue;
    }
    cx.resize(m), cy.resize(m), cz.resize(m), cj.resize(m);
    for (std::size_t b = 0, at = 0; b < block_cells; ++b) {
      for (std::uint32_t j = g.begin[block[b]]; j < g.begin[block[b] + 1]; ++j, ++at) {
        const Vec3f p = tree_points[j];
        cx[at] = p.x, cy[at] = p.y, cz[at] = p.z, cj[at] = j;
      }
    }
    near.resize(m);
    cd.resize(m);
    kd.resize(m + kLanes), ki.resize(m + kLanes);
    for (std::uint32_t j = g.begin[c]; j < g.begin[c + 1]; ++j) {
      const Vec3f q = tree_points[j];
      // The candidates within a limit (the last query's k-th distance, grown), but the point
      // itself: when they are k or more, they hold the k nearest and all tied with the k-th.
      // Else the limit grows until they do (all m - 1 of them at the end).
      // Every candidate's distance first (in vectors); the point itself gets NaN, which no
      // limit admits (its cell is gathered first, so it is candidate j - begin).
      for (std::size_t i = 0; i < m; ++i) cd[i] = squared_distance(q, cx[i], cy[i], cz[i]);
      cd[j - g.begin[c]] = std::numeric_limits<float>::quiet_NaN();
      std::size_t count = 0;
      // (A 5 M cloud, k = 15: with 1.25 and 1.5, 13 % of the queries grow their limit, against
      // 3 % with 1.5 and 4, but they rank 0.82x the entries: the search takes 0.94x the time.)
      for (float limit = guess > 0 ? guess * 1.25f : std::numeric_limits<float>::infinity();;
           limit = limit * 1.5f) {
        count = within_limit(cd.data(), m, limit, kd.data(), ki.data());
        if (count >= k || !(limit < std::numeric_limits<float>::max())) break;
        if (!(limit > 0)) limit = std::numeric_limits<float>::min();
      }
      for (std::size_t t = 0; t < count; ++t) ki[t] = original(cj[ki[t]]);
      // In order of distance, then index. Usually a few dozen entries: each entry's place is
      // the number of entries before it, counted without branches, in vectors (padded to whole
      // vectors by entries that come after every real one). Many (the limit grew, or piles of
      // copies): a comparison sort.
      constexpr std::size_t kMostRanked = 128;
      if (count > kMostRanked) {
        for (std::size_t t = 0; t < count; ++t) near[t] = Neighbour{kd[t], ki[t]};
        std::sort(near.begin(), near.begin() + std::ptrdiff_t(count), closer);
      } else {
        // kd and ki have room for m + kLanes entries: count + 7 of them fit.
        const std::size_t padded = (count + kLanes - 1) & ~(kLanes - 1);
        assert(padded <= kd.size());
        std::fill(kd.begin() + std::ptrdiff_t(count), kd.begin() + std::ptrdiff_t(padded),
                  std::numeric_limits<float>::infinity());
        std::fill(ki.begin() + std::ptrdiff_t(count), ki.begin() + std::ptrdiff_t(padded),
                  std::numeric_limits<std::uint32_t>::max());
#if defined(__AVX2__)
        // Eight entries at a time, one per lane, each lane counting the entries before its
        // own: no sum across lanes per entry. Indices compare as signed after flipping the top
        // bit.
        const __m256i flip = _mm256_set1_epi32(std::int32_t(0x80000000u));
        for (std::size_t t = 0; t < count; t += kLanes) {
          const __m256 d = _mm256_loadu_ps(&kd[t]);
          const __m256i i = _mm256_xor_si256(
              _mm256_loadu_si256(reinterpret_cast<const __m256i*>(&ki[t])), flip);
          __m256i before = _mm256_setzero_si256();
          for (std::size_t e = 0; e < count; ++e) {
            const __m256 de = _mm256_broadcast_ss(&kd[e]);
            const __m256i ie = _mm256_set1_epi32(std::int32_t(ki[e] ^ 0x80000000u));
            const __m256i nearer = _mm256_castps_si256(_mm256_cmp_ps(de, d, _CMP_LT_OQ));
            const __m256i tied = _mm256_and_si256(
                _mm256_castps_si256(_mm256_cmp_ps(de, d, _CMP_EQ_OQ)), _mm256_cmpgt_epi32(i, ie));
            before = _mm256_sub_epi32(before, _mm256_or_si256(nearer, tied));  // -(-1) per hit
          }
          alignas(32) std::uint32_t place[kLanes];
          _mm256_store_si256(reinterpret_cast<__m256i*>(place), before);
          for (std::size_t l = 0; l < std::min(kLanes, count - t); ++l) {
            near[place[l]] = Neighbour{kd[t + l], ki[t + l]};
          }
        }
#else
        for (std::size_t t = 0; t < count; ++t) {
          const float d = kd[t];
          const std::uint32_t i = ki[t];
          std::uint32_t place = 0;
          for (std::size_t e = 0; e < padded; ++e) {
            place += (kd[e] < d) | ((kd[e] == d) & (ki[e] < i));
          }
          near[place] = Neighbour{d, i};
        }
#endif
      }
      const float cut = near[k - 1].d2;
      guess = cut;

      if (!g.vouches(q, a, 1, cut)) {
        missed.push_back(j);
        continue;
      }
      row.clear();
      for (std::size_t i = 0; i < count && near[i].d2 <= cut; ++i) row.push_back(near[i]);
      const std::uint32_t self = original(j);
      finish_row(row, k, points, self, &result[std::size_t(self) * k],
                 result_d2 ? &result_d2[std::size_t(self) * k] : nullptr);
    }
  }
}

// A miss of grid_queries asked again of the cells within `r` (> 1) of its own, which vouch for
// it by the same reach as the 3x3x3 block: true when answered. So a few misses (a sparse edge of
// a chunk's halo) need no kd-tree over all the points. At most kMaxWideCandidates candidates.
constexpr std::size_t kMaxWideCandidates = 4 * kMaxCandidates;
bool wide_block_query(const CellGrid& g, std::uint32_t j, std::uint32_t r,
                      std::span<const Vec3f> tree_points, std::span<const Vec3f> points,
                      const std::uint32_t* order, std::size_t k, std::uint32_t* result,
                      float* result_d2, std::vector<Neighbour>& near) {
  const Vec3f q = tree_points[j];
  const std::array<std::uint32_t, 3> a = CellGrid::cell_coords(g.cell_key(g.frame.code(q)));
  const std::uint32_t side = MortonFrame::kMaxCell >> g.level;
  std::uint32_t lo[3], hi[3];
  for (int axis = 0; axis < 3; ++axis) {
    lo[axis] = a[axis] > r ? a[axis] - r : 0;
    hi[axis] = std::min(side, a[axis] + r);
  }
  const auto original = [&](std::uint32_t i) { return order ? order[i] : i; };
  near.clear();
  for (std::uint32_t z = lo[2]; z <= hi[2]; ++z) {
    for (std::uint32_t y = lo[1]; y <= hi[1]; ++y) {
      for (std::uint32_t x = lo[0]; x <= hi[0]; ++x) {
        const std::uint32_t c = g.find(morton_code(x, y, z));
        if (c == 0) continue;
        if (near.size() + (g.begin[c] - g.begin[c - 1]) > kMaxWideCandidates) return false;
        for (std::uint32_t i = g.begin[c - 1]; i < g.begin[c]; ++i) {
          if (i == j) continue;
          const Vec3f p = tree_points[i];
          near.push_back({squared_distance(q, p.x, p.y, p.z), original(i)});
        }
      }
    }
  }
  if (near.size() < k) return false;
  std::nth_element(near.begin(), near.begin() + std::ptrdiff_t(k - 1), near.end(), closer);
  const float cut = near[k - 1].d2;
  if (!g.vouches(q, a, r, cut)) return false;
  // The row: every candidate within the cut, by distance then index.
  const auto end = std::partition(near.begin(), near.end(),
                                  [&](const Neighbour& nb) { return nb.d2 <= cut; });
  near.erase(end, near.end());
  std::sort(near.begin(), near.end(), closer);
  const std::uint32_t self = original(j);
  finish_row(near, k, points, self, &result[std::size_t(self) * k],
             result_d2 ? &result_d2[std::size_t(self) * k] : nullptr);
  return true;
}

}  // namespace

std::vector<std::uint32_t> k_nearest_neighbours(std::span<const Vec3f> points, ThreadPool& pool,
                                                const KnnOptions& options,
                                                std::vector<float>* squared_distances,
                                                Progress& progress) {
  const std::size_t n = points.size();
  const std::size_t k = options.k;
  assert(n <= std::size_t{UINT32_MAX});
  ProgressPhase phase(progress, "neighbours", n);
  std::vector<std::uint32_t> result(n * k);
  if (squared_distances) squared_distances->assign(n * k, 0.0f);
  if (n == 0 || k == 0) return result;
  float* result_d2 = squared_distances ? squared_distances->data() : nullptr;

  // Queries, the grid and the tree all run over spatially ordered points; `order` maps back.
  std::vector<std::uint32_t> order;
  std::vector<Vec3f> ordered_points;
  std::span<const Vec3f> tree_points = points;
  if (!options.points_are_ordered) {
    order = morton_order(points, pool);
    ordered_points.resize(n);
    parallel_for(pool, n, 1 << 16, [&](std::size_t begin, std::size_t end) {
      for (std::size_t j = begin; j < end; ++j) ordered_points[j] = points[order[j]];
    });
    tree_points = ordered_points;
  }
  const std::uint32_t* order_map = order.empty() ? nullptr : order.data();
  const auto original = [&](std::uint32_t j) { return order.empty() ? j : order[j]; };

  // The grid answers what it can; `missed` lists the rest (ascending).
  std::vector<std::uint32_t> missed;
  CellGrid grid;
  if (n >= kGridMinPoints && n > k + 1 && build_grid(tree_points, grid)) {
    const std::size_t cells = grid.key.size();
    const std::size_t grain = std::max<std::size_t>(1, cells * kQueryGrain / n);
    const std::size_t tasks = (cells + grain - 1) / grain;
    std::vector<std::vector<std::uint32_t>> task_missed(tasks);
    pool.run(tasks, [&](std::size_t t) {
      const std::size_t begin = t * grain, end = std::min(cells, begin + grain);
      grid_queries(grid, begin, end, tree_points, points, order_map, k, result.data(), result_d2,
                   task_missed[t]);
      phase.advance(grid.begin[end] - grid.begin[begin] - task_missed[t].size());
    });
    for (const auto& t : task_missed) missed.insert(missed.end(), t.begin(), t.end());
    if (options.paths) options.paths->grid += n - missed.size();
    // Misses asked again of wider blocks (5^3, then 9^3 cells); the kd-tree takes the rest.
    if (!missed.empty() && missed.size() <= kWideMisses) {
      std::vector<std::uint8_t> answered(missed.size(), 0);
      parallel_for(pool, missed.size(), 16, [&](std::size_t begin, std::size_t end) {
        std::vector<Neighbour> near;
        for (std::size_t at = begin; at < end; ++at) {
          for (const std::uint32_t r : {2u, 4u}) {
            if (wide_block_query(grid, missed[at], r, tree_points, points, order_map, k,
                                 result.data(), result_d2, near)) {
              answered[at] = 1;
              break;
            }
          }
        }
      });
      std::size_t kept = 0;
      for (std::size_t at = 0; at < missed.size(); ++at) {
        if (!answered[at]) missed[kept++] = missed[at];
      }
      phase.advance(missed.size() - kept);
      if (options.paths) options.paths->wide += missed.size() - kept;
      missed.resize(kept);
    }
  } else {
    missed.resize(n);
    for (std::size_t j = 0; j < n; ++j) missed[j] = std::uint32_t(j);
  }
  if (missed.empty()) return result;
  if (options.paths) options.paths->tree += missed.size();

  const CloudAdaptor adaptor{tree_points};
  const KdTree tree(3, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(kLeafSize));

  // Ask for one more than k (the query point finds itself and is then dropped), and one more to
  // see whether points at the same distance straddle the k-th place: which of them the tree
  // returns depends on the tree, so such a query is asked again for kTieSlack more, and the cut
  // among the tied points is made by their positions (finish_row). The same neighbours are then
  // found in any subset of the points that holds them (a chunk and its halo,
  // pipeline/chunked_convert.cpp) as long as at most kTieSlack + 1 points tie at the cut.
  constexpr std::size_t kTieSlack = 8;
  const std::size_t wanted = std::min(k + 2, n);
  const std::size_t wanted_tied = std::min(k + 1 + kTieSlack, n);
  parallel_for(pool, missed.size(), kQueryGrain, [&](std::size_t begin, std::size_t end) {
    std::vector<std::uint32_t> found_index(wanted_tied);
    std::vector<float> found_d2(wanted_tied);
    std::vector<Neighbour> row;
    row.reserve(wanted_tied);
    for (std::size_t at = begin; at < end; ++at) {
      const std::uint32_t j = missed[at];
      const Vec3f q = tree_points[j];
      const float query[3] = {q.x, q.y, q.z};
      const auto query_row = [&](std::size_t count) {
        nanoflann::KNNResultSet<float, std::uint32_t, std::size_t> results(count);
        results.init(found_index.data(), found_d2.data());
        tree.findNeighbors(results, query, nanoflann::SearchParams());
        const std::size_t found = results.size();
        row.clear();
        bool dropped_self = false;
        for (std::size_t i = 0; i < found; ++i) {
          if (!dropped_self && found_index[i] == j) {
            dropped_self = true;
            continue;
          }
          row.push_back({found_d2[i], original(found_index[i])});
        }
      };
      query_row(wanted);
      if (row.size() > k && row[k].d2 == row[k - 1].d2 && wanted_tied > wanted) {
        query_row(wanted_tied);
      }
      // Many copies of the query point can crowd it out of its own list; then the farthest is
      // dropped.
      const std::uint32_t self = original(j);
      finish_row(row, k, points, self, &result[std::size_t(self) * k],
                 result_d2 ? &result_d2[std::size_t(self) * k] : nullptr);
    }
    phase.advance(end - begin);
  });
  return result;
}

}  // namespace pointillist
