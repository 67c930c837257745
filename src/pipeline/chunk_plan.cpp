// plan_chunks (see chunk_plan.hpp): the top levels of build_sphere_tree's median splits, found
// with one selection per range and level (std::nth_element by (coordinate, index)) instead of
// the full partition, over the points with their indices (no indirection: 100 M points planned
// in 30 s through an index array).
#include "chunk_plan.hpp"

#include <algorithm>
#include <array>
#include <limits>
#include <optional>

#include "pointillist/core/error.hpp"
#include "pointillist/core/float_order.hpp"

namespace pointillist::chunking {
namespace {

// Index of the largest extent; ties go to the lower axis (as the hierarchy's splits choose).
int longest(const float extent[3]) {
  return (extent[0] >= extent[1] && extent[0] >= extent[2]) ? 0 : (extent[1] >= extent[2] ? 1 : 2);
}

// The hierarchy's split order on `axis`: coordinate (-0 as +0), then input index.
bool before_on(int axis, const PlanPoint& i, const PlanPoint& j) {
  const float ci = i.position[axis] + 0.0f, cj = j.position[axis] + 0.0f;
  return ci < cj || (ci == cj && i.index < j.index);
}

// The box of pts[b, e) (coordinates with -0 as +0).
void range_box(std::span<const PlanPoint> pts, std::size_t b, std::size_t e, float lo[3],
               float hi[3]) {
  for (int a = 0; a < 3; ++a) {
    lo[a] = std::numeric_limits<float>::infinity();
    hi[a] = -lo[a];
  }
  for (std::size_t k = b; k < e; ++k) {
    const Vec3f& p = pts[k].position;
    for (int a = 0; a < 3; ++a) {
      const float c = p[a] + 0.0f;
      lo[a] = std::min(lo[a], c);
      hi[a] = std::max(hi[a], c);
    }
  }
}

// The same on every thread of the pool, a part each.
void range_box(std::span<const PlanPoint> pts, std::size_t b, std::size_t e, ThreadPool& pool,
               float lo[3], float hi[3]) {
  const std::size_t tasks = pool.thread_count();
  std::vector<std::array<float, 6>> part(tasks);
  pool.run(tasks, [&](std::size_t t) {
    range_box(pts, b + (e - b) * t / tasks, b + (e - b) * (t + 1) / tasks, &part[t][0],
              &part[t][3]);
  });
  range_box(pts, 0, 0, lo, hi);  // the empty box, then the parts' together
  for (const auto& x : part) {
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], x[std::size_t(a)]);
      hi[a] = std::max(hi[a], x[std::size_t(a) + 3]);
    }
  }
}

// What std::nth_element(pts + b, pts + mid, pts + e, before) leaves for the next levels, on two
// threads: pts[b, mid) the points before the (mid - b)-th by (coordinate on `axis`, index),
// pts[mid, e) the others; returns that point (which need not end at mid). The point is found
// by counting the coordinates' top 16 bits (of their order-preserving integers) and selecting
// in the bucket that holds it; each half is partitioned in place, then the left half's points
// that go right trade places with the right half's that go left (as many: the halves meet at
// mid). Nothing when the bucket holds more than a sixteenth of the range (many equal
// coordinates): its copy would take memory the plan is not allowed.
std::optional<PlanPoint> split_on_two_threads(std::vector<PlanPoint>& pts, std::size_t b,
                                              std::size_t mid, std::size_t e, int axis,
                                              ThreadPool& pool) {
  // (ordered_key keeps the coordinates' order, so its top bits bucket them in that order.)
  const auto key = [axis](const PlanPoint& p) { return ordered_key(p.position[axis] + 0.0f); };
  const auto before = [axis](const PlanPoint& i, const PlanPoint& j) {
    return before_on(axis, i, j);
  };
  const std::size_t bounds[3] = {b, mid, e};
  std::vector<std::vector<std::uint32_t>> counts(2, std::vector<std::uint32_t>(1 << 16, 0));
  pool.run(2, [&](std::size_t t) {
    for (std::size_t k = bounds[t]; k < bounds[t + 1]; ++k) ++counts[t][key(pts[k]) >> 16];
  });
  std::uint32_t bucket = 0;
  std::size_t below = 0, rank = mid - b;
  for (;; ++bucket) {
    const std::size_t here = std::size_t(counts[0][bucket]) + counts[1][bucket];
    if (below + here > rank) {
      if (here > (e - b) / 16) return std::nullopt;
      break;
    }
    below += here;
  }
  std::vector<std::vector<PlanPoint>> in_bucket(2);
  pool.run(2, [&](std::size_t t) {
    for (std::size_t k = bounds[t]; k < bounds[t + 1]; ++k) {
      if ((key(pts[k]) >> 16) == bucket) in_bucket[t].push_back(pts[k]);
    }
  });
  std::vector<PlanPoint>& candidates = in_bucket[0];
  candidates.insert(candidates.end(), in_bucket[1].begin(), in_bucket[1].end());
  const auto nth = candidates.begin() + std::ptrdiff_t(rank - below);
  std::nth_element(candidates.begin(), nth, candidates.end(), before);
  const PlanPoint pivot = *nth;
  std::size_t left[2];
  pool.run(2, [&](std::size_t t) {
    const auto first = pts.begin() + std::ptrdiff_t(bounds[t]);
    const auto middle = std::partition(first, pts.begin() + std::ptrdiff_t(bounds[t + 1]),
                                       [&](const PlanPoint& p) { return before(p, pivot); });
    left[t] = std::size_t(middle - first);
  });
  // pts[b + left[0], mid) go right, pts[mid, mid + left[1]) go left: mid - b - left[0] =
  // left[1] points each.
  const std::size_t moving = left[1];
  pool.run(2, [&](std::size_t t) {
    const std::size_t from = moving * t / 2, to = moving * (t + 1) / 2;
    std::swap_ranges(pts.begin() + std::ptrdiff_t(b + left[0] + from),
                     pts.begin() + std::ptrdiff_t(b + left[0] + to),
                     pts.begin() + std::ptrdiff_t(mid + from));
  });
  return pivot;
}

}  // namespace

ChunkPlan plan_chunks(std::span<const Vec3f> positions, std::uint32_t levels, ThreadPool& pool,
                      std::vector<std::vector<std::uint32_t>>* members) {
  if (positions.size() >= (std::size_t{1} << 32)) {
    throw Error("cannot plan chunks over " + std::to_string(positions.size()) + " points");
  }
  std::vector<PlanPoint> points(positions.size());
  for (std::size_t i = 0; i < positions.size(); ++i) {
    points[i] = {positions[i], static_cast<std::uint32_t>(i)};
  }
  return plan_chunks(std::move(points), levels, pool, members);
}

ChunkPlan plan_chunks(std::vector<PlanPoint> pts, std::uint32_t levels, ThreadPool& pool,
                      std::vector<std::vector<std::uint32_t>>* members) {
  const std::size_t n = pts.size();
  if (n == 0 || n >= (std::size_t{1} << 32) || levels > 20 || (levels > 0 && (n >> levels) < 2)) {
    throw Error("cannot plan " + std::to_string(std::size_t{1} << levels) + " chunks over " +
                std::to_string(n) + " points");
  }
  ChunkPlan plan;
  plan.levels = levels;
  plan.splits.resize((std::size_t{1} << levels) - 1);
  // Ranges of the current level, in heap order.
  std::vector<std::size_t> bounds{0, n};
  for (std::uint32_t level = 0; level < levels; ++level) {
    const std::size_t nodes = bounds.size() - 1;
    const std::size_t first = (std::size_t{1} << level) - 1;
    std::vector<std::size_t> next(2 * nodes + 1);
    // Fewer ranges than threads (the first level) on many points: a range at a time, its box
    // and split on two threads; else a range a thread.
    const bool on_two =
        nodes < pool.thread_count() && pool.thread_count() >= 2 && n >= kSplitOnTwoThreads;
    const auto split_range = [&](std::size_t r) {
      const std::size_t b = bounds[r], e = bounds[r + 1];
      float lo[3], hi[3];
      if (on_two) {
        range_box(pts, b, e, pool, lo, hi);
      } else {
        range_box(pts, b, e, lo, hi);
      }
      const float extent[3] = {hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]};
      const int axis = longest(extent);
      const std::size_t mid = b + (e - b) / 2;
      std::optional<PlanPoint> pivot;
      if (on_two) pivot = split_on_two_threads(pts, b, mid, e, axis, pool);
      if (!pivot) {
        std::nth_element(pts.begin() + std::ptrdiff_t(b), pts.begin() + std::ptrdiff_t(mid),
                         pts.begin() + std::ptrdiff_t(e),
                         [axis](const PlanPoint& i, const PlanPoint& j) {
                           return before_on(axis, i, j);
                         });
        pivot = pts[mid];
      }
      plan.splits[first + r] = {static_cast<std::uint8_t>(axis), pivot->position[axis] + 0.0f,
                                pivot->index};
      next[2 * r] = b;
      next[2 * r + 1] = mid;
      next[2 * r + 2] = e;
    };
    if (on_two) {
      for (std::size_t r = 0; r < nodes; ++r) split_range(r);
    } else {
      pool.run(nodes, split_range);
    }
    bounds = std::move(next);
  }
  const std::size_t chunks = bounds.size() - 1;
  plan.counts.resize(chunks);
  plan.boxes.resize(chunks);
  if (members) members->assign(chunks, {});
  pool.run(chunks, [&](std::size_t c) {
    const std::size_t b = bounds[c], e = bounds[c + 1];
    plan.counts[c] = e - b;
    Aabb box;
    for (std::size_t k = b; k < e; ++k) box.extend(pts[k].position);
    plan.boxes[c] = box;
    if (members) {
      std::vector<std::uint32_t>& m = (*members)[c];
      for (std::size_t k = b; k < e; ++k) m.push_back(pts[k].index);
      std::sort(m.begin(), m.end());
    }
  });
  return plan;
}

}  // namespace pointillist::chunking
