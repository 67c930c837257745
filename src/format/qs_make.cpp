// QSplat 1.0's preprocessor (Rusinkiewicz & Levoy, "QSplat: A Multiresolution Point Rendering
// System for Large Meshes", SIGGRAPH 2000), restated in ../shared/specs/qsplat-qs-format.md
// §8.2-8.4. Every value is float32 and evaluated in the spec's order (§8.6), because the files
// must come out byte-identical to the original's: do not "simplify" an expression here (e.g.
// x / k into x * (1 / k)) without checking the golden files.
#include "qs_make.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <span>
#include <utility>

#include "pointillist/core/error.hpp"

namespace pointillist::qs_detail {
namespace {

// n · (1/|n|) with the float32 reciprocal; a zero vector becomes (0, 0, 1).
Vec3f unit(Vec3f n) {
  const float len = std::sqrt(n.x * n.x + n.y * n.y + n.z * n.z);
  if (len == 0) return {0, 0, 1};
  const float inv = 1.0f / len;
  return {n.x * inv, n.y * inv, n.z * inv};
}

// Radius of the smallest circle enclosing the triangle (§8.2): half the longest edge when an
// angle is >= 90°, else the circumradius.
float enclosing_radius(Vec3f p1, Vec3f p2, Vec3f p3) {
  const float d1 = dot(p2 - p1, p3 - p1);
  const float d2 = dot(p1 - p2, p3 - p2);
  const float d3 = dot(p1 - p3, p2 - p3);
  if (d1 <= 0) return 0.5f * length(p3 - p2);
  if (d2 <= 0) return 0.5f * length(p3 - p1);
  if (d3 <= 0) return 0.5f * length(p2 - p1);
  // R = abc / 4K with a², b², c² = d2+d3, d3+d1, d1+d2 and (4K)² = 4(d2d3 + d3d1 + d1d2).
  const float denominator = d2 * d3 + d3 * d1 + d1 * d2;
  if (denominator == 0) return 0;
  return 0.5f * std::sqrt((d1 + d2) * (d2 + d3) * (d3 + d1) / denominator);
}

class HierarchyBuilder {
 public:
  explicit HierarchyBuilder(MakeTree& tree) : nodes_(tree.nodes) {
    refs_.resize(nodes_.size());
    for (std::size_t i = 0; i < refs_.size(); ++i) refs_[i] = static_cast<std::uint32_t>(i);
  }

  std::uint32_t build(std::size_t begin, std::size_t end) {
    if (end - begin <= 4) return group(begin, end);
    const std::size_t mid = partition(begin, end);
    std::array<std::uint32_t, 4> children{};
    std::size_t k = 0;
    for (const auto& [b, e] : {std::pair{begin, mid}, std::pair{mid, end}}) {
      if (e - b <= 4) {
        children[k++] = group(b, e);
      } else {
        const std::size_t quarter = partition(b, e);
        children[k++] = build(b, quarter);
        children[k++] = build(quarter, e);
      }
    }
    return interior(std::span(children).first(k));
  }

 private:
  // One leaf is itself; 2..4 leaves get a parent, in array order.
  std::uint32_t group(std::size_t begin, std::size_t end) {
    assert(end > begin);
    if (end - begin == 1) return refs_[begin];
    return interior(std::span(refs_).subspan(begin, end - begin));
  }

  // Spatial midpoint split along the longest box side (§8.3); returns the first index of the
  // upper part.
  std::size_t partition(std::size_t begin, std::size_t end) {
    Vec3f lo = nodes_[refs_[begin]].center, hi = lo;
    for (std::size_t i = begin + 1; i < end; ++i) {
      lo = min(lo, nodes_[refs_[i]].center);
      hi = max(hi, nodes_[refs_[i]].center);
    }
    if (lo == hi) return (begin + end) / 2;
    const Vec3f e = hi - lo;
    const int axis = (e.x > e.y && e.x > e.z) ? 0 : (e.y > e.z ? 1 : 2);
    const float split = 0.5f * (lo[axis] + hi[axis]);
    const auto coord = [&](std::ptrdiff_t i) { return nodes_[refs_[std::size_t(i)]].center[axis]; };
    const auto b = static_cast<std::ptrdiff_t>(begin), e_ = static_cast<std::ptrdiff_t>(end);
    std::ptrdiff_t left = b, right = e_ - 1;
    for (;;) {
      while (left < e_ && coord(left) < split) ++left;
      while (right >= b && coord(right) >= split) --right;
      if (right < left) break;
      std::swap(refs_[std::size_t(left)], refs_[std::size_t(right)]);
    }
    // Only when the midpoint rounds onto the box's low side can one part be empty (QSplat 1.0
    // would then fail); split in the middle instead.
    if (left == b || left == e_) return (begin + end) / 2;
    return static_cast<std::size_t>(left);
  }

  // Interior node over 2..4 children (§8.4), appended to the node array.
  std::uint32_t interior(std::span<const std::uint32_t> children) {
    const auto k = static_cast<std::uint32_t>(children.size());
    MakeNode n;
    Vec3f sum = nodes_[children[0]].center;
    for (std::uint32_t i = 1; i < k; ++i) sum += nodes_[children[i]].center;
    n.center = sum / float(k);
    Vec3f normal_sum = nodes_[children[0]].normal;
    for (std::uint32_t i = 1; i < k; ++i) normal_sum += nodes_[children[i]].normal;
    n.normal = unit(normal_sum);
    unsigned r = 0, g = 0, b = 0;
    for (std::uint32_t i = 0; i < k; ++i) {
      const MakeNode& c = nodes_[children[i]];
      n.radius = std::max(n.radius, length(n.center - c.center) + c.radius);
      const float cos_angle = std::clamp(dot(n.normal, c.normal), 0.0f, 1.0f);
      n.cone = std::max(n.cone, std::acos(cos_angle) + c.cone);
      r += c.color.r;
      g += c.color.g;
      b += c.color.b;
      n.children[i] = children[i];
      n.has_grandchild |= c.child_count > 0;
    }
    n.color = {static_cast<std::uint8_t>(r / k), static_cast<std::uint8_t>(g / k),
               static_cast<std::uint8_t>(b / k)};
    n.child_count = static_cast<std::uint8_t>(k);
    nodes_.push_back(n);
    return static_cast<std::uint32_t>(nodes_.size() - 1);
  }

  std::vector<MakeNode>& nodes_;
  std::vector<std::uint32_t> refs_;  // leaf indices, permuted by the partitions
};

[[noreturn]] void fail(const std::string& name, const std::string& what) {
  throw Error("cannot write " + name + " as QSplat: " + what);
}

}  // namespace

MakeTree make_leaves(const PointSet& points, bool with_colors, const std::string& name) {
  const std::size_t n = points.size();
  if (with_colors && points.colors.size() != n) {
    fail(name, std::to_string(points.colors.size()) + " colors for " + std::to_string(n) +
                   " points");
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!is_finite(points.positions[i])) {
      fail(name, "point " + std::to_string(i) + " has a non-finite coordinate");
    }
  }
  std::vector<Vec3f> normals(n);
  std::vector<float> radii(n, 0.0f);
  if (points.is_mesh()) {
    for (std::size_t f = 0; f < points.triangles.size(); ++f) {
      const auto& t = points.triangles[f];
      if (t[0] >= n || t[1] >= n || t[2] >= n) {
        fail(name, "triangle " + std::to_string(f) + " uses a vertex past the last of " +
                       std::to_string(n));
      }
      const Vec3f p1 = points.positions[t[0]], p2 = points.positions[t[1]],
                  p3 = points.positions[t[2]];
      const Vec3f face_normal = cross(p2 - p1, p3 - p1);  // |u × v| = twice the area
      const float r = enclosing_radius(p1, p2, p3);
      for (const std::uint32_t v : t) {
        normals[v] += face_normal;
        if (r > radii[v]) radii[v] = r;
      }
    }
  } else {
    if (points.normals.size() != n || points.radii.size() != n) {
      fail(name, "a point set without faces needs a normal and a radius per point (" +
                     std::to_string(points.normals.size()) + " normals, " +
                     std::to_string(points.radii.size()) + " radii for " + std::to_string(n) +
                     " points); run prepare_splats first");
    }
    normals = points.normals;
    radii = points.radii;
  }
  MakeTree tree;
  for (std::size_t i = 0; i < n; ++i) {
    if (radii[i] == 0) continue;  // unused by any face, or only in degenerate ones
    MakeNode leaf;
    leaf.center = points.positions[i];
    leaf.radius = radii[i];
    leaf.normal = unit(normals[i]);
    if (!(std::isfinite(leaf.radius) && leaf.radius > 0) || !is_finite(leaf.normal)) {
      fail(name, "point " + std::to_string(i) + " has a radius or normal that is negative or "
                 "not finite");
    }
    if (with_colors) leaf.color = points.colors[i];
    tree.nodes.push_back(leaf);
  }
  tree.leaf_count = tree.nodes.size();
  return tree;
}

void build_hierarchy(MakeTree& tree) {
  assert(tree.nodes.size() >= 2);
  tree.nodes.reserve(tree.nodes.size() * 2);
  HierarchyBuilder builder(tree);
  tree.root = builder.build(0, tree.leaf_count);
}

}  // namespace pointillist::qs_detail
