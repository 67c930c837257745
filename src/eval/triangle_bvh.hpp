// Bounding-volume hierarchy for exact nearest-primitive queries (private to eval): a binary tree
// of axis-aligned boxes built by median splits, searched nearest-first with pruning. The triangle
// mesh reference uses it with Ericson's closest point on a triangle; surface_error.cpp uses the
// same tree over discs (nearest disc of a sample) and over points (nearest original point).
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "pointillist/core/math.hpp"

namespace pointillist::eval_detail {

// Inner nodes have count == 0 and children `first` and `first + 1`; a leaf holds the slots
// [first, first + count) of the tree's leaf order.
struct BvhNode {
  Aabb box;
  std::uint32_t first = 0;
  std::uint32_t count = 0;
};

// Squared distance from p to the box (0 inside).
inline float box_distance_squared(const Aabb& box, Vec3f p) { return box.distance_squared(p); }

class BoxTree {
 public:
  static constexpr std::uint32_t kLeafSize = 4;

  // Builds the tree over the primitives' boxes: each node split at the median of its
  // primitives' box centres along the longest axis of those centres' bounds (ties by index),
  // leaves of at most kLeafSize primitives. Deterministic in the boxes.
  explicit BoxTree(std::span<const Aabb> boxes);
  BoxTree() = default;

  // Leaf order: slot -> primitive index. Callers store their primitives in this order so that a
  // leaf's primitives are adjacent in memory.
  std::span<const std::uint32_t> order() const { return order_; }

  // Visits, nearest box first, every slot whose leaf box lies within squared distance `bound`
  // of q: `bound = visit(slot, bound)`, the visitor shrinking the (squared) bound as it finds
  // nearer primitives. Exact as long as each primitive lies inside its box.
  template <class Visit>
  void search(Vec3f q, float bound, Visit&& visit) const {
    if (nodes_.empty()) return;
    struct Entry {
      std::uint32_t node;
      float distance_squared;
    };
    Entry stack[96];  // depth ≤ log2(n / kLeafSize) + 1 (median splits), one far child per level
    int top = 0;
    stack[top++] = {0, box_distance_squared(nodes_[0].box, q)};
    while (top > 0) {
      const Entry e = stack[--top];
      if (e.distance_squared > bound) continue;
      const BvhNode& node = nodes_[e.node];
      if (node.count > 0) {
        for (std::uint32_t s = node.first; s < node.first + node.count; ++s) {
          bound = visit(s, bound);
        }
        continue;
      }
      Entry near{node.first, box_distance_squared(nodes_[node.first].box, q)};
      Entry far{node.first + 1, box_distance_squared(nodes_[node.first + 1].box, q)};
      if (far.distance_squared < near.distance_squared) std::swap(near, far);
      if (far.distance_squared <= bound) stack[top++] = far;
      if (near.distance_squared <= bound) stack[top++] = near;
    }
  }

 private:
  std::vector<BvhNode> nodes_;
  std::vector<std::uint32_t> order_;
};

// Closest point on triangle (a, b, c) to p: C. Ericson, "Real-Time Collision Detection", 2005,
// section 5.1.5 (Voronoi regions of the vertices, edges and face), computed in double so that
// distances of queries near the surface keep their relative precision. Degenerate triangles
// (zero area) fall back to the nearest of their three edges.
struct TrianglePoint {
  Vec3f point;
  double distance_squared = 0;
};
TrianglePoint closest_on_triangle(Vec3f p, Vec3f a, Vec3f b, Vec3f c);

// A triangle mesh for exact point-to-surface queries.
class TriangleBvh {
 public:
  // Indices must be < positions.size() (the caller checks). Keeps copies of the corners.
  TriangleBvh(std::span<const Vec3f> positions,
              std::span<const std::array<std::uint32_t, 3>> triangles);

  struct Hit {
    Vec3f point;
    Vec3f normal;  // unit face normal (right-hand rule), +z for a degenerate triangle
    float distance = 0;
    std::uint32_t triangle = 0;  // index in the caller's triangle list
  };
  // Nearest point of the mesh to p (ties go to the lower triangle index).
  Hit closest(Vec3f p) const;

 private:
  BoxTree tree_;
  std::vector<std::array<Vec3f, 3>> corners_;  // in the tree's leaf order
};

}  // namespace pointillist::eval_detail
