// Turning decoded QSplat fragments into one SphereTree whose bounds nest. QSplat's quantized
// spheres are inscribed in covering cubes, so a decoded child can stick out of its decoded parent
// (spec ../shared/specs/qsplat-qs-format.md §4.3), and its normal cone codes were computed from
// the undithered normals (§5.2, §6). Our traversal culls whole subtrees on a parent's sphere and
// cone, so both are enlarged here, bottom-up, until they cover the children's.
#include "qs_assemble.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <span>
#include <utility>

namespace pointillist::qs_detail {
namespace {

constexpr float kNoConeBound = 2.0f;  // cone_sin >= 1: no bound (sphere_tree.hpp)
constexpr Rgb8 kGrey{204, 204, 204};  // colourless fragments in a coloured model

// The smallest float >= v (v >= 0, finite).
float round_up(double v) {
  float f = static_cast<float>(v);
  if (double(f) < v) f = std::nextafter(f, std::numeric_limits<float>::infinity());
  return f;
}

double distance_d(Vec3f a, Vec3f b) {
  const double dx = double(a.x) - b.x, dy = double(a.y) - b.y, dz = double(a.z) - b.z;
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

// Normal and color of a node without a stored record (a fragment root or an added node): the
// normalized sum of its children's normals and their truncated mean color. Its cone starts
// at 0 and is widened by enclose().
void summarize_children(std::span<const SphereNode> children, SphereNode& n) {
  Vec3f sum{};
  unsigned r = 0, g = 0, b = 0;
  for (const SphereNode& c : children) {
    sum += c.normal;
    r += c.color.r;
    g += c.color.g;
    b += c.color.b;
  }
  const float len = length(sum);
  n.normal = len > 0 ? sum / len : Vec3f{0, 0, 1};
  n.cone_sin = len > 0 ? 0.0f : kNoConeBound;
  const auto k = static_cast<unsigned>(children.size());
  n.color = {static_cast<std::uint8_t>(r / k), static_cast<std::uint8_t>(g / k),
             static_cast<std::uint8_t>(b / k)};
}

// An added node above `children`: a sphere around the box of their spheres.
SphereNode node_above(std::span<const SphereNode> children) {
  Aabb box;
  for (const SphereNode& c : children) {
    box.extend(c.center - Vec3f{c.radius, c.radius, c.radius});
    box.extend(c.center + Vec3f{c.radius, c.radius, c.radius});
  }
  SphereNode n;
  n.center = box.center();
  double radius = 0;
  for (const SphereNode& c : children) {
    radius = std::max(radius, distance_d(n.center, c.center) + c.radius);
  }
  n.radius = round_up(radius);
  n.child_count = static_cast<std::uint8_t>(children.size());
  summarize_children(children, n);
  return n;
}

// Joins several fragment trees breadth-first under added levels. All fragment roots sit on one
// level, so level j of the result below them is the concatenation of every fragment's level j.
// Returns the number of added nodes (they come first).
std::size_t join(std::vector<DecodedTree>& trees, std::vector<SphereNode>& out) {
  // Added levels, top first; each groups the level below into runs of 2..4 (as even as possible).
  std::vector<std::vector<SphereNode>> above;
  std::vector<SphereNode> level;
  for (const DecodedTree& t : trees) level.push_back(t.nodes[0]);
  while (level.size() > 1) {
    const std::size_t groups = (level.size() + 3) / 4;
    std::vector<SphereNode> parents;
    std::size_t begin = 0;
    for (std::size_t g = 0; g < groups; ++g) {
      const std::size_t end = level.size() * (g + 1) / groups;
      SphereNode n = node_above(std::span(level).subspan(begin, end - begin));
      n.first_child = static_cast<std::uint32_t>(begin);  // relative to the level below
      parents.push_back(n);
      begin = end;
    }
    above.insert(above.begin(), parents);
    level = std::move(parents);
  }
  // Rebase: first_child of an added node is an index into the next level.
  std::size_t added = 0;
  for (const auto& l : above) added += l.size();
  std::size_t level_begin = 0;
  for (const auto& l : above) {
    const std::size_t next_begin = level_begin + l.size();
    for (SphereNode n : l) {
      n.first_child += static_cast<std::uint32_t>(next_begin);
      out.push_back(n);
    }
    level_begin = next_begin;
  }
  // Fragment levels, interleaved by level.
  std::size_t levels = 0;
  for (const DecodedTree& t : trees) levels = std::max(levels, t.level_start.size() - 1);
  // new_start[f][j]: output index of fragment f's first node at level j.
  std::vector<std::vector<std::size_t>> new_start(trees.size(),
                                                  std::vector<std::size_t>(levels + 1, 0));
  std::size_t at = added;
  for (std::size_t j = 0; j <= levels; ++j) {
    for (std::size_t f = 0; f < trees.size(); ++f) {
      new_start[f][j] = at;
      const auto& ls = trees[f].level_start;
      if (j + 1 < ls.size()) at += ls[j + 1] - ls[j];
    }
  }
  out.reserve(at);
  for (std::size_t j = 0; j < levels; ++j) {
    for (std::size_t f = 0; f < trees.size(); ++f) {
      const auto& ls = trees[f].level_start;
      if (j + 1 >= ls.size()) continue;
      for (std::size_t i = ls[j]; i < ls[j + 1]; ++i) {
        SphereNode n = trees[f].nodes[i];
        if (n.child_count > 0) {
          n.first_child =
              static_cast<std::uint32_t>(new_start[f][j + 1] + (n.first_child - ls[j + 1]));
        }
        if (!trees[f].has_colors) n.color = kGrey;
        out.push_back(n);
      }
    }
  }
  return added;
}

double length_d(Vec3f v) {
  return std::sqrt(double(v.x) * v.x + double(v.y) * v.y + double(v.z) * v.z);
}

// Enlarges node i's sphere to enclose its children's and its cone to cover theirs. Returns
// which of the two changed.
std::pair<bool, bool> enclose(std::vector<SphereNode>& nodes, std::size_t i) {
  SphereNode& n = nodes[i];
  const std::span<const SphereNode> children(nodes.data() + n.first_child, n.child_count);
  double need_radius = n.radius;
  for (const SphereNode& c : children) {
    const double dx = double(c.center.x) - n.center.x, dy = double(c.center.y) - n.center.y,
                 dz = double(c.center.z) - n.center.z;
    const double d2 = dx * dx + dy * dy + dz * dz, slack = double(n.radius) - c.radius;
    // Most children fit with room to spare: decide those without a square root.
    if (slack < 0 || d2 > slack * slack * (1 - 1e-9)) {
      need_radius = std::max(need_radius, std::sqrt(d2) + c.radius);
    }
  }
  const bool grew = need_radius > n.radius;
  if (grew) n.radius = round_up(need_radius);

  if (!(n.cone_sin < 1.0f)) return {grew, false};
  // The cone must hold every child's cone: θ >= α_c + θ_c, α_c = angle(n, n_c). Without
  // trigonometric calls: sin(α + θ_c) = sin α cos θ_c + cos α sin θ_c, which grows with the
  // angle while cos(α + θ_c) = cos α cos θ_c - sin α sin θ_c stays positive.
  const double nl = length_d(n.normal);
  double max_sin = 0;
  bool unbounded = !(nl > 0);
  for (const SphereNode& c : children) {
    if (unbounded) break;
    const double cl = length_d(c.normal);
    if (!(c.cone_sin < 1.0f) || !(cl > 0)) {
      unbounded = true;
      break;
    }
    const Vec3f a = n.normal, b = c.normal;
    const double crx = double(a.y) * b.z - double(a.z) * b.y,
                 cry = double(a.z) * b.x - double(a.x) * b.z,
                 crz = double(a.x) * b.y - double(a.y) * b.x;
    const double sin_a = std::sqrt(crx * crx + cry * cry + crz * crz) / (nl * cl);
    const double cos_a = (double(a.x) * b.x + double(a.y) * b.y + double(a.z) * b.z) / (nl * cl);
    const double sin_t = c.cone_sin, cos_t = std::sqrt(1 - sin_t * sin_t);
    if (!(cos_a * cos_t - sin_a * sin_t > 0)) {
      unbounded = true;
      break;
    }
    max_sin = std::max(max_sin, sin_a * cos_t + cos_a * sin_t);
  }
  if (unbounded) {
    n.cone_sin = kNoConeBound;
    return {grew, true};
  }
  if (max_sin <= n.cone_sin) return {grew, false};
  const float s = round_up(max_sin * (1 + 1e-12));
  n.cone_sin = s < 1.0f ? s : kNoConeBound;
  return {grew, true};
}

}  // namespace

SphereTree assemble_tree(std::vector<DecodedTree>&& trees, QsStats& stats) {
  assert(!trees.empty());
  SphereTree tree;
  for (const DecodedTree& t : trees) tree.has_colors |= t.has_colors;
  for (DecodedTree& t : trees) {
    SphereNode& root = t.nodes[0];
    summarize_children(std::span(t.nodes).subspan(root.first_child, root.child_count), root);
  }
  std::size_t added = 0;
  std::size_t levels = trees[0].level_start.size() - 1;
  if (trees.size() == 1) {
    tree.nodes = std::move(trees[0].nodes);
  } else {
    added = join(trees, tree.nodes);
    std::size_t fragment_levels = 0;
    for (const DecodedTree& t : trees) {
      fragment_levels = std::max(fragment_levels, t.level_start.size() - 1);
    }
    std::size_t added_levels = 0;
    for (std::size_t n = trees.size(); n > 1; n = (n + 3) / 4) ++added_levels;
    levels = added_levels + fragment_levels;
  }
  std::vector<SphereNode>& nodes = tree.nodes;
  const std::size_t records_begin = added + trees.size();
  for (std::size_t i = nodes.size(); i-- > 0;) {
    SphereNode& n = nodes[i];
    if (n.child_count == 0) {
      tree.bounds.extend(n.center);
      ++tree.leaf_count;
      continue;
    }
    if (i < added) {
      // Added nodes were built from the fragment roots before the roots' own fix.
      summarize_children(std::span(nodes).subspan(n.first_child, n.child_count), n);
    }
    const auto [grew, widened] = enclose(nodes, i);
    if (grew && i >= added) ++stats.spheres_enlarged;
    if (widened && i >= records_begin) ++stats.cones_widened;
  }
  tree.depth = static_cast<std::uint32_t>(levels - 1);
  tree.view_sphere.center = tree.bounds.center();
  double far2 = 0;
  for (const SphereNode& n : nodes) {
    if (n.child_count != 0) continue;
    const Vec3f d = n.center - tree.view_sphere.center;
    far2 = std::max(far2, double(d.x) * d.x + double(d.y) * d.y + double(d.z) * d.z);
  }
  tree.view_sphere.radius = round_up(std::sqrt(far2));
  return tree;
}

}  // namespace pointillist::qs_detail
