// Bounding-volume hierarchy by median splits and exact closest points on triangles (Ericson,
// "Real-Time Collision Detection", 2005, section 5.1.5).
#include "triangle_bvh.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace pointillist::eval_detail {
namespace {

Vec3d closest_on_segment(Vec3d p, Vec3d a, Vec3d b) {
  const Vec3d ab = b - a;
  const double len2 = dot(ab, ab);
  if (!(len2 > 0)) return a;
  return a + ab * std::clamp(dot(p - a, ab) / len2, 0.0, 1.0);
}

Vec3d closest_on_edges(Vec3d p, Vec3d a, Vec3d b, Vec3d c) {
  Vec3d best = closest_on_segment(p, a, b);
  for (const Vec3d q : {closest_on_segment(p, b, c), closest_on_segment(p, c, a)}) {
    if (dot(p - q, p - q) < dot(p - best, p - best)) best = q;
  }
  return best;
}

Vec3d ericson(Vec3d p, Vec3d a, Vec3d b, Vec3d c) {
  const Vec3d ab = b - a, ac = c - a, ap = p - a;
  const Vec3d n = cross(ab, ac);
  if (!(dot(n, n) > 0)) return closest_on_edges(p, a, b, c);
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vec3d bp = p - b;
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));  // d1 - d3 = |ab|²
  const Vec3d cp = p - c;
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));  // d2 - d6 = |ac|²
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
    return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));  // denominator |bc|²
  }
  const double sum = va + vb + vc;  // = |ab × ac|², lost to rounding only on slivers
  if (!(sum > 0)) return closest_on_edges(p, a, b, c);
  return a + ab * (vb / sum) + ac * (vc / sum);
}

}  // namespace

BoxTree::BoxTree(std::span<const Aabb> boxes) {
  const std::size_t n = boxes.size();
  order_.resize(n);
  std::iota(order_.begin(), order_.end(), 0u);
  if (n == 0) return;
  std::vector<Vec3f> centres(n);
  for (std::size_t i = 0; i < n; ++i) centres[i] = boxes[i].center();
  nodes_.reserve(2 * (n / kLeafSize) + 2);
  nodes_.push_back({});
  struct Task {
    std::uint32_t node, begin, end;
  };
  std::vector<Task> tasks{{0, 0, std::uint32_t(n)}};
  while (!tasks.empty()) {
    const Task t = tasks.back();
    tasks.pop_back();
    Aabb box, centre_box;
    for (std::uint32_t i = t.begin; i < t.end; ++i) {
      box.extend(boxes[order_[i]]);
      centre_box.extend(centres[order_[i]]);
    }
    nodes_[t.node].box = box;
    if (t.end - t.begin <= kLeafSize) {
      nodes_[t.node].first = t.begin;
      nodes_[t.node].count = t.end - t.begin;
      continue;
    }
    const int axis = centre_box.longest_axis();
    const std::uint32_t mid = t.begin + (t.end - t.begin) / 2;
    std::nth_element(order_.begin() + t.begin, order_.begin() + mid, order_.begin() + t.end,
                     [&](std::uint32_t a, std::uint32_t b) {
                       const float ca = centres[a][axis], cb = centres[b][axis];
                       return ca < cb || (ca == cb && a < b);
                     });
    const auto child = std::uint32_t(nodes_.size());
    nodes_.push_back({});
    nodes_.push_back({});
    nodes_[t.node].first = child;
    nodes_[t.node].count = 0;
    tasks.push_back({child + 1, mid, t.end});
    tasks.push_back({child, t.begin, mid});
  }
}

TrianglePoint closest_on_triangle(Vec3f p, Vec3f a, Vec3f b, Vec3f c) {
  const Vec3d pd = to_double(p);
  const Vec3d q = ericson(pd, to_double(a), to_double(b), to_double(c));
  const Vec3d d = pd - q;
  return {{float(q.x), float(q.y), float(q.z)}, dot(d, d)};
}

TriangleBvh::TriangleBvh(std::span<const Vec3f> positions,
                         std::span<const std::array<std::uint32_t, 3>> triangles) {
  std::vector<Aabb> boxes(triangles.size());
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    for (const std::uint32_t v : triangles[t]) boxes[t].extend(positions[v]);
  }
  tree_ = BoxTree(boxes);
  const auto order = tree_.order();
  corners_.resize(triangles.size());
  for (std::size_t s = 0; s < order.size(); ++s) {
    const auto& tri = triangles[order[s]];
    corners_[s] = {positions[tri[0]], positions[tri[1]], positions[tri[2]]};
  }
}

TriangleBvh::Hit TriangleBvh::closest(Vec3f p) const {
  const auto order = tree_.order();
  double best = std::numeric_limits<double>::infinity();
  std::uint32_t best_slot = 0, best_triangle = std::numeric_limits<std::uint32_t>::max();
  Vec3f best_point = p;
  tree_.search(p, std::numeric_limits<float>::infinity(), [&](std::uint32_t slot, float bound) {
    const auto& t = corners_[slot];
    const TrianglePoint q = closest_on_triangle(p, t[0], t[1], t[2]);
    if (q.distance_squared < best || (q.distance_squared == best && order[slot] < best_triangle)) {
      best = q.distance_squared;
      best_slot = slot;
      best_triangle = order[slot];
      best_point = q.point;
      // Rounded up so that pruning in float never drops a box the double distance would keep.
      return std::nextafter(float(best), std::numeric_limits<float>::infinity());
    }
    return bound;
  });
  Hit hit;
  if (best_triangle == std::numeric_limits<std::uint32_t>::max()) {
    hit.distance = std::numeric_limits<float>::infinity();
    return hit;
  }
  const auto& t = corners_[best_slot];
  hit.point = best_point;
  hit.normal = normalized(cross(t[1] - t[0], t[2] - t[0]));
  hit.distance = float(std::sqrt(best));
  hit.triangle = best_triangle;
  return hit;
}

}  // namespace pointillist::eval_detail
