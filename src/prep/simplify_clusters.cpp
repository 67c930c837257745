// Clustering simplifications (Pauly, Gross & Kobbelt 2002, §3): hierarchical (binary space
// partition across the main axis) and incremental (region growing from seeds on the borders).
#include <algorithm>
#include <cmath>
#include <numeric>
#include <queue>

#include "pointillist/spatial/knn.hpp"
#include "simplify_internal.hpp"

namespace pointillist::simplify_detail {
namespace {

constexpr std::uint32_t kNone = UINT32_MAX;

// The incremental clusters stop growing when their surface variation reaches this: curved and
// creased regions get smaller clusters than flat ones (Pauly's σ_max).
constexpr double kMaxVariation = 0.05;

struct Range {
  std::uint32_t begin = 0, end = 0;
  double priority = 0;  // the squared spread: members × (λ0 + λ1 + λ2)
  Vec3f centroid, major;
};

// Larger spread first; ties by position, so the order is total and the result deterministic.
struct Smaller {
  bool operator()(const Range& a, const Range& b) const {
    return a.priority != b.priority ? a.priority < b.priority : a.begin > b.begin;
  }
};

Range make_range(const PointSet& in, const std::vector<std::uint32_t>& perm, std::uint32_t begin,
                 std::uint32_t end) {
  Moments m;
  m.origin = in.positions[perm[begin]];
  for (std::uint32_t j = begin; j < end; ++j) m.add(in.positions[perm[j]]);
  const Spread s = spread_of(m);
  return {begin, end, m.n * (s.lambda[0] + s.lambda[1] + s.lambda[2]), s.centroid, s.major};
}

}  // namespace

Clusters hierarchical_clusters(const PointSet& in, std::size_t target, ProgressPhase& /*phase*/) {
  const auto n = static_cast<std::uint32_t>(in.size());
  std::vector<std::uint32_t> perm(n);
  std::iota(perm.begin(), perm.end(), 0u);
  std::priority_queue<Range, std::vector<Range>, Smaller> heap;
  std::vector<Range> done;  // ranges that cannot be split (all members at one position)
  heap.push(make_range(in, perm, 0, n));
  while (!heap.empty() && heap.size() + done.size() < target) {
    const Range r = heap.top();
    heap.pop();
    if (!(r.priority > 0) || r.end - r.begin < 2) {
      done.push_back(r);
      continue;
    }
    const auto side = [&](std::uint32_t i) { return dot(in.positions[i] - r.centroid, r.major); };
    auto* first = perm.data() + r.begin;
    auto* last = perm.data() + r.end;
    auto* mid = std::partition(first, last, [&](std::uint32_t i) { return side(i) < 0; });
    if (mid == first || mid == last) {  // rounding put everything on one side: split at the median
      mid = first + (last - first) / 2;
      std::nth_element(first, mid, last, [&](std::uint32_t a, std::uint32_t b) {
        const float sa = side(a), sb = side(b);
        return sa != sb ? sa < sb : a < b;
      });
    }
    const auto m = static_cast<std::uint32_t>(mid - perm.data());
    heap.push(make_range(in, perm, r.begin, m));
    heap.push(make_range(in, perm, m, r.end));
  }
  while (!heap.empty()) {
    done.push_back(heap.top());
    heap.pop();
  }
  std::sort(done.begin(), done.end(), [](const Range& a, const Range& b) { return a.begin < b.begin; });
  Clusters c;
  c.of.resize(n);
  for (const Range& r : done) {
    for (std::uint32_t j = r.begin; j < r.end; ++j) c.of[perm[j]] = c.count;
    ++c.count;
  }
  return c;
}

namespace {

// Region growing over the k-nearest-neighbour graph: from a seed, the nearest unassigned
// points (by distance to the seed, through the graph) join until the cluster has `max_size`
// members or its variation reaches kMaxVariation; the points it reached but did not take are
// the next seeds.
Clusters grow(const PointSet& in, std::span<const std::uint32_t> knn, std::uint32_t k,
              std::uint32_t max_size) {
  const std::size_t n = in.size();
  Clusters c;
  c.of.assign(n, kNone);
  std::queue<std::uint32_t> seeds;
  std::size_t scan = 0;  // the next unassigned point by index, when no seed is left
  using Candidate = std::pair<float, std::uint32_t>;
  std::priority_queue<Candidate, std::vector<Candidate>, std::greater<>> near;
  for (;;) {
    std::uint32_t seed = kNone;
    while (!seeds.empty() && seed == kNone) {
      if (c.of[seeds.front()] == kNone) seed = seeds.front();
      seeds.pop();
    }
    while (seed == kNone && scan < n) {
      if (c.of[scan] == kNone) seed = static_cast<std::uint32_t>(scan);
      ++scan;
    }
    if (seed == kNone) break;
    const std::uint32_t id = c.count++;
    const Vec3f at = in.positions[seed];
    Moments m;
    m.origin = at;
    std::uint32_t size = 0;
    near = {};
    near.push({0.0f, seed});
    while (!near.empty() && size < max_size) {
      const std::uint32_t j = near.top().second;
      near.pop();
      if (c.of[j] != kNone) continue;
      c.of[j] = id;
      m.add(in.positions[j]);
      ++size;
      for (std::uint32_t t = 0; t < k; ++t) {
        const std::uint32_t q = knn[std::size_t{j} * k + t];
        if (c.of[q] == kNone) near.push({length_squared(in.positions[q] - at), q});
      }
      // (Checked every fourth member: the eigen decomposition costs more than the growth.)
      if (size >= 4 && size % 4 == 0 && spread_of(m).variation() >= kMaxVariation) break;
    }
    while (!near.empty()) {  // the border: the next clusters start here
      if (c.of[near.top().second] == kNone) seeds.push(near.top().second);
      near.pop();
    }
  }
  return c;
}

// Merges the smallest cluster into the neighbouring one (joined by a graph edge) whose centroid
// is nearest its own, until `target` remain (Pauly's merging of small clusters, carried on to
// the count asked for). Ties go to the lower id.
Clusters merge_smallest(const PointSet& in, Clusters c, std::span<const std::uint32_t> knn,
                        std::uint32_t k, std::size_t target) {
  std::vector<std::vector<std::uint32_t>> members(c.count);
  for (std::uint32_t i = 0; i < c.of.size(); ++i) members[c.of[i]].push_back(i);
  std::vector<Moments> m(c.count);
  for (std::uint32_t id = 0; id < c.count; ++id) {
    m[id].origin = in.positions[members[id].front()];
    for (std::uint32_t i : members[id]) m[id].add(in.positions[i]);
  }
  const auto centroid = [&](std::uint32_t id) { return m[id].centroid(); };
  using Entry = std::pair<std::size_t, std::uint32_t>;  // (size, id)
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> small;
  for (std::uint32_t id = 0; id < c.count; ++id) small.push({members[id].size(), id});
  std::size_t alive = c.count;
  while (alive > target && !small.empty()) {
    const auto [size, id] = small.top();
    small.pop();
    if (members[id].size() != size || size == 0) continue;  // stale entry
    const Vec3f at = centroid(id);
    std::uint32_t best = kNone;
    float best_d = INFINITY;
    for (std::uint32_t i : members[id]) {
      for (std::uint32_t t = 0; t < k; ++t) {
        const std::uint32_t other = c.of[knn[std::size_t{i} * k + t]];
        if (other == id) continue;
        const float d = length_squared(centroid(other) - at);
        if (d < best_d || (d == best_d && other < best)) {
          best_d = d;
          best = other;
        }
      }
    }
    if (best == kNone) continue;  // no neighbour: an island stays
    for (std::uint32_t i : members[id]) c.of[i] = best;
    members[best].insert(members[best].end(), members[id].begin(), members[id].end());
    members[id].clear();
    m[best].add(m[id]);
    small.push({members[best].size(), best});
    --alive;
  }
  // Renumber the survivors in order of their lowest member.
  std::vector<std::uint32_t> renumber(c.count, kNone);
  std::uint32_t next = 0;
  for (std::uint32_t& id : c.of) {
    if (renumber[id] == kNone) renumber[id] = next++;
    id = renumber[id];
  }
  c.count = next;
  return c;
}

}  // namespace

Clusters incremental_clusters(const PointSet& in, std::size_t target, std::uint32_t k,
                              ThreadPool& pool, ProgressPhase& phase, int* passes) {
  const std::size_t n = in.size();
  k = static_cast<std::uint32_t>(std::min<std::size_t>(k, n - 1));
  const std::vector<std::uint32_t> knn =
      k_nearest_neighbours(in.positions, pool, KnnOptions{.k = k});
  // The largest cluster size that still gives at least `target` clusters (the count falls
  // about as 1 / size: a secant step from n / target, at most 6 passes), then the smallest
  // clusters are merged down to the target.
  std::uint32_t size = static_cast<std::uint32_t>(std::max<std::size_t>(1, n / target));
  std::uint32_t best_size = 0, fewest_too_large = UINT32_MAX;
  Clusters best;
  int count = 0;
  for (int pass = 0; pass < 6; ++pass) {
    Clusters c = grow(in, knn, k, size);
    ++count;
    phase.advance(n / 8);  // at most 6 passes and the merge
    const double step = double(c.count) / double(target);
    if (c.count >= target) {
      if (size > best_size) {
        best_size = size;
        best = std::move(c);
      }
    } else {
      fewest_too_large = std::min(fewest_too_large, size);
    }
    auto next = static_cast<std::uint32_t>(std::max(1.0, std::floor(double(size) * step)));
    if (next >= fewest_too_large) next = fewest_too_large - 1;
    if (next <= best_size) next = best_size + 1;
    if (next >= fewest_too_large || next == size) break;
    size = next;
  }
  if (best_size == 0) {  // every size tried gives too few: one point a cluster gives n
    best = grow(in, knn, k, 1);
    ++count;
  }
  if (passes) *passes = count;
  return merge_smallest(in, std::move(best), knn, k, target);
}

}  // namespace pointillist::simplify_detail
