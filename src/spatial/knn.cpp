// k nearest neighbours with a nanoflann kd-tree, queried in Morton order for memory locality.
#include "pointillist/spatial/knn.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <limits>
#include <nanoflann.hpp>

namespace pointillist {
namespace {

// Points per chunk of queries: enough to amortize task overhead, small enough to balance.
constexpr std::size_t kQueryGrain = 4096;
// Leaf size of the kd-tree; 16 measured faster than nanoflann's default 10 for k = 16 here.
constexpr std::size_t kLeafSize = 16;

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
  std::uint32_t index;
};

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

  // Queries and the tree both run over spatially ordered points; `order` maps back.
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
  const auto original = [&](std::uint32_t j) { return order.empty() ? j : order[j]; };

  const CloudAdaptor adaptor{tree_points};
  const KdTree tree(3, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(kLeafSize));

  // Ask for one more than k (the query point finds itself and is then dropped), and one more to
  // see whether points at the same distance straddle the k-th place: which of them the tree
  // returns depends on the tree, so such a query is asked again for kTieSlack more, and the cut
  // among the tied points is made here by their positions. The same neighbours are then found in
  // any subset of the points that holds them (a chunk and its halo, pipeline/chunked_convert.cpp)
  // as long as at most kTieSlack + 1 points tie at the cut.
  constexpr std::size_t kTieSlack = 8;
  const std::size_t wanted = std::min(k + 2, n);
  const std::size_t wanted_tied = std::min(k + 1 + kTieSlack, n);
  parallel_for(pool, n, kQueryGrain, [&](std::size_t begin, std::size_t end) {
    std::vector<std::uint32_t> found_index(wanted_tied);
    std::vector<float> found_d2(wanted_tied);
    std::vector<Neighbour> row;
    row.reserve(wanted_tied);
    for (std::size_t j = begin; j < end; ++j) {
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
      // Rows come sorted by distance. Equal distances at the cut: the lowest positions (x, then
      // y, then z) make it. (Many copies of the query point can crowd it out of its own list;
      // then the farthest is dropped.)
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
        for (; m > 0 && row[m - 1].d2 == x.d2 && row[m - 1].index > x.index; --m) {
          row[m] = row[m - 1];
        }
        row[m] = x;
      }

      const std::size_t self = original(static_cast<std::uint32_t>(j));
      std::uint32_t* out = &result[self * k];
      float* out_d2 = squared_distances ? &(*squared_distances)[self * k] : nullptr;
      const Neighbour pad =
          row.empty() ? Neighbour{0.0f, static_cast<std::uint32_t>(self)} : row.back();
      for (std::size_t i = 0; i < k; ++i) {
        const Neighbour& nb = i < row.size() ? row[i] : pad;
        out[i] = nb.index;
        if (out_d2) out_d2[i] = nb.d2;
      }
    }
    phase.advance(end - begin);
  });
  return result;
}

}  // namespace pointillist
