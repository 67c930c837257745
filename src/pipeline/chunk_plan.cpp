// plan_chunks (see chunk_plan.hpp): the top levels of build_sphere_tree's median splits, found
// with one selection per range and level (std::nth_element by (coordinate, index)) instead of
// the full partition, over the points with their indices (no indirection: 100 M points planned
// in 30 s through an index array).
#include "chunk_plan.hpp"

#include <algorithm>
#include <limits>

#include "pointillist/core/error.hpp"

namespace pointillist::chunking {
namespace {

// Index of the largest extent; ties go to the lower axis (as the hierarchy's splits choose).
int longest(const float extent[3]) {
  return (extent[0] >= extent[1] && extent[0] >= extent[2]) ? 0 : (extent[1] >= extent[2] ? 1 : 2);
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
    pool.run(nodes, [&](std::size_t r) {
      const std::size_t b = bounds[r], e = bounds[r + 1];
      float lo[3], hi[3];
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
      const float extent[3] = {hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]};
      const int axis = longest(extent);
      const std::size_t mid = b + (e - b) / 2;
      const auto before = [&](const PlanPoint& i, const PlanPoint& j) {
        const float ci = i.position[axis] + 0.0f, cj = j.position[axis] + 0.0f;
        return ci < cj || (ci == cj && i.index < j.index);
      };
      std::nth_element(pts.begin() + std::ptrdiff_t(b), pts.begin() + std::ptrdiff_t(mid),
                       pts.begin() + std::ptrdiff_t(e), before);
      plan.splits[first + r] = {static_cast<std::uint8_t>(axis),
                                pts[mid].position[axis] + 0.0f, pts[mid].index};
      next[2 * r] = b;
      next[2 * r + 1] = mid;
      next[2 * r + 2] = e;
    });
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
