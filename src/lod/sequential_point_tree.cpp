// Sequential Point Trees (Dachsbacher, Vogelgsang & Stamminger, "Sequential Point Trees",
// SIGGRAPH 2003, sections 3 and 4): octree point hierarchy, perpendicular and tangential
// errors, and the list sorted by r_max; split into spatial chunks (our addition).
//
// The build runs in four passes:
//   1. the order: points sorted by (Morton code in the bounding cube, input index), so every
//      octree cell is a contiguous range and a node's children are found by binary search;
//   2. the plan: ranges larger than the grain are split sequentially into "top" nodes, the rest
//      become tasks;
//   3. the subtrees: each task builds its range bottom-up (post-order) with its errors; then
//      the top nodes are combined from their children;
//   4. the list: nodes are sorted by (range, parent error descending, pre-order) and gathered
//      into the structure of arrays.
// Node attributes depend only on the children and the final order only on the tree, so the
// result is the same bits for any thread count or grain.
#include "pointillist/lod/sequential_point_tree.hpp"

#include <algorithm>
#include <bit>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "splat_input.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/core/morton.hpp"

namespace pointillist {
namespace {

constexpr std::uint32_t kMaxChunkLevel = 10;
constexpr int kLevels = 21;  // octree depth of the finest Morton cells
constexpr std::uint8_t kLeafLevel = kLevels;
constexpr std::size_t kPointGrain = 65536;  // points per task in the per-point passes
constexpr std::size_t kSortBlock = 1 << 14;
constexpr std::uint32_t kTaskRef = 0x80000000u;  // child reference: task id, not top node
constexpr float kInf = std::numeric_limits<float>::infinity();

struct MortonKey {
  std::uint64_t code = 0;
  std::uint32_t index = 0;
};
constexpr bool operator<(const MortonKey& a, const MortonKey& b) {
  return a.code != b.code ? a.code < b.code : a.index < b.index;
}

// A node during the build. [begin, begin + count) is its range of the Morton order; ordering by
// (begin ascending, count descending) is the pre-order, since no two nodes share a range.
struct BuildNode {
  Vec3f center;
  Vec3f normal;
  float diameter = 0;
  float error = 0;
  float color[3] = {0, 0, 0};  // mean colour, channels in [0, 1]
  std::uint32_t parent = kSptNoParent;
  std::uint32_t begin = 0;
  std::uint32_t count = 0;
  std::uint8_t level = kLeafLevel;  // depth of the smallest octree cell holding the points
  bool leaf = true;
};

// ---- Input checks --------------------------------------------------------------------------


void check_input(const PointSet& points, const SequentialPointTreeOptions& options) {
  const std::string what = "cannot build a sequential point tree";
  lod_detail::check_splat_attributes(points, what);
  if (options.chunk_level > kMaxChunkLevel) {
    throw OptionError(what + ": chunk_level " + std::to_string(options.chunk_level) +
                      " is out of range; use 0 to " + std::to_string(kMaxChunkLevel));
  }
  if (!(options.color_tolerance >= 0)) {
    throw OptionError(what + ": color_tolerance " + std::to_string(options.color_tolerance) +
                      " must be a non-negative number (or +infinity to ignore colours)");
  }
}



// ---- Pass 1: Morton order ------------------------------------------------------------------

std::vector<MortonKey> morton_keys(const std::vector<Vec3f>& positions, const Aabb& bounds,
                                   ThreadPool& pool) {
  const Vec3f e = bounds.extent();
  const double side = std::max({double(e.x), double(e.y), double(e.z)});
  const double scale = side > 0 ? double(1u << kLevels) / side : 0.0;
  const auto cell = [&](float p, float lo) {
    const double q = std::floor((double(p) - lo) * scale);
    return static_cast<std::uint32_t>(std::clamp(q, 0.0, double((1u << kLevels) - 1)));
  };
  std::vector<MortonKey> keys(positions.size());
  parallel_for(pool, positions.size(), kPointGrain, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const Vec3f p = positions[i];
      // z in the lowest bit of each triple, x in the highest: the octree's child order.
      keys[i] = {morton_code(cell(p.z, bounds.lo.z), cell(p.y, bounds.lo.y),
                             cell(p.x, bounds.lo.x)),
                 static_cast<std::uint32_t>(i)};
    }
  });
  parallel_sort(keys, pool, std::less<MortonKey>{}, kSortBlock);
  return keys;
}

// A splat in Morton order: the build reads these in sequence instead of gathering from the
// input at random.
struct SortedSplat {
  Vec3f position;
  Vec3f normal;
  float radius = 0;
  Rgb8 color;
};

std::vector<SortedSplat> gather_splats(const PointSet& points, std::span<const MortonKey> keys,
                                       ThreadPool& pool) {
  std::vector<SortedSplat> splats(keys.size());
  const bool has_colors = points.has_colors();
  parallel_for(pool, keys.size(), kPointGrain, [&](std::size_t begin, std::size_t end) {
    for (std::size_t k = begin; k < end; ++k) {
      const std::uint32_t p = keys[k].index;
      splats[k] = {points.positions[p], normalized(points.normals[p]), points.radii[p],
                   has_colors ? points.colors[p] : Rgb8{}};
    }
  });
  return splats;
}

// ---- Pass 2: splitting a range into children -----------------------------------------------

struct Split {
  std::uint8_t level = 0;  // depth of the cell holding the whole range
  std::uint32_t child_count = 0;
  std::uint32_t edge[9] = {};  // child k covers [edge[k], edge[k + 1])
};

// Children of the range [begin, end) (at least 2 points): the non-empty octants of the smallest
// cell holding it, or, when all codes are equal, at most 8 equal groups in order.
Split split_range(std::span<const MortonKey> keys, std::uint32_t begin, std::uint32_t end) {
  Split s;
  s.edge[0] = begin;
  const std::uint64_t diff = keys[begin].code ^ keys[end - 1].code;
  if (diff == 0) {
    const std::uint32_t n = end - begin, parts = std::min<std::uint32_t>(8, n);
    s.level = kLeafLevel;
    s.child_count = parts;
    for (std::uint32_t k = 1; k <= parts; ++k) {
      s.edge[k] = begin + static_cast<std::uint32_t>(std::uint64_t{n} * k / parts);
    }
    return s;
  }
  const int level = (std::countl_zero(diff) - 1) / 3;  // codes use the low 63 bits
  const int shift = 3 * (kLevels - 1 - level);
  s.level = static_cast<std::uint8_t>(level);
  std::uint32_t at = begin;
  for (std::uint32_t digit = 0; digit < 8 && at < end; ++digit) {
    const auto* first = keys.data() + at;
    const auto* stop = std::partition_point(first, keys.data() + end, [&](const MortonKey& k) {
      return ((k.code >> shift) & 7u) <= digit;
    });
    const auto next = static_cast<std::uint32_t>(stop - keys.data());
    if (next > at) s.edge[++s.child_count] = next;
    at = next;
  }
  return s;
}

// ---- Pass 3: nodes -------------------------------------------------------------------------

// Where a task writes its nodes: consecutive slots of the final node array from `next` on.
struct NodeOut {
  std::span<BuildNode> nodes;
  std::uint32_t next = 0;

  std::uint32_t put(const BuildNode& node) {
    nodes[next] = node;
    return next++;
  }
};

struct NodeMaker {
  std::span<const MortonKey> keys;
  std::span<const SortedSplat> splats;
  bool has_colors;
  float color_tolerance;

  std::uint32_t add_leaf(std::uint32_t k, NodeOut& out) const {
    const SortedSplat& splat = splats[k];
    BuildNode node;
    node.center = splat.position;
    node.normal = splat.normal;
    node.diameter = 2 * splat.radius;
    node.begin = k;
    node.count = 1;
    if (has_colors) {
      const Rgb8 c = splat.color;
      node.color[0] = c.r / 255.0f;
      node.color[1] = c.g / 255.0f;
      node.color[2] = c.b / 255.0f;
    }
    return out.put(node);
  }

  // Appends the interior node over `children` (indices into `nodes`) and links them to it.
  std::uint32_t add_interior(std::span<const std::uint32_t> children, const Split& split,
                             NodeOut& out) const {
    const std::span<BuildNode> nodes = out.nodes;
    SptDisc discs[8];
    for (std::size_t k = 0; k < children.size(); ++k) {
      const BuildNode& c = nodes[children[k]];
      discs[k] = {c.center, c.normal, c.diameter * 0.5f};
    }
    const SptNodeGeometry g = spt_combine_children({discs, children.size()});
    BuildNode node;
    node.center = g.center;
    node.normal = g.normal;
    node.diameter = g.diameter;
    node.error =
        static_cast<float>(std::hypot(double(g.perpendicular_error), double(g.tangential_error)));
    node.begin = split.edge[0];
    node.count = split.edge[split.child_count] - split.edge[0];
    node.level = split.level;
    node.leaf = false;
    if (has_colors) {
      for (const std::uint32_t c : children) {
        for (int a = 0; a < 3; ++a) node.color[a] += nodes[c].color[a];
      }
      for (float& channel : node.color) channel /= static_cast<float>(children.size());
      bool edge = false;
      for (const std::uint32_t c : children) {
        float d2 = 0;
        for (int a = 0; a < 3; ++a) {
          d2 += (nodes[c].color[a] - node.color[a]) * (nodes[c].color[a] - node.color[a]);
        }
        // Over a colour edge the node may only be drawn once its whole disc is below the bound.
        if (std::sqrt(d2) > color_tolerance) edge = true;
      }
      if (edge) {
        node.error = std::max(node.error, node.diameter);
        // And so may its interior children: even of one colour each, their discs reach across
        // the edge into their siblings' colour.
        for (const std::uint32_t c : children) {
          if (!nodes[c].leaf) nodes[c].error = std::max(nodes[c].error, nodes[c].diameter);
        }
      }
    }
    for (const std::uint32_t c : children) node.error = std::max(node.error, nodes[c].error);
    const std::uint32_t index = out.put(node);
    for (const std::uint32_t c : children) nodes[c].parent = index;
    return index;
  }

  // Builds the subtree over [begin, end) in post-order; returns its root's index.
  std::uint32_t build(std::uint32_t begin, std::uint32_t end, NodeOut& out) const {
    if (end - begin == 1) return add_leaf(begin, out);
    const Split split = split_range(keys, begin, end);
    std::uint32_t children[8];
    for (std::uint32_t k = 0; k < split.child_count; ++k) {
      children[k] = build(split.edge[k], split.edge[k + 1], out);
    }
    return add_interior({children, split.child_count}, split, out);
  }
};

// Top of the tree above the task subtrees, in post-order.
struct TopNode {
  Split split;
  std::uint32_t child_ref[8] = {};  // top node index, or kTaskRef | task id
};

struct Plan {
  std::vector<TopNode> top;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> tasks;  // point ranges [first, second)
};

std::uint32_t plan_range(std::span<const MortonKey> keys, std::uint32_t begin, std::uint32_t end,
                         std::size_t grain, Plan& plan) {
  if (end - begin <= grain) {
    plan.tasks.emplace_back(begin, end);
    return kTaskRef | static_cast<std::uint32_t>(plan.tasks.size() - 1);
  }
  TopNode node;
  node.split = split_range(keys, begin, end);
  for (std::uint32_t k = 0; k < node.split.child_count; ++k) {
    node.child_ref[k] = plan_range(keys, node.split.edge[k], node.split.edge[k + 1], grain, plan);
  }
  plan.top.push_back(node);
  return static_cast<std::uint32_t>(plan.top.size() - 1);
}

// Nodes of the subtree over [begin, end), without building it.
std::uint32_t count_nodes(std::span<const MortonKey> keys, std::uint32_t begin, std::uint32_t end) {
  if (end - begin == 1) return 1;
  const Split split = split_range(keys, begin, end);
  std::uint32_t total = 1;
  for (std::uint32_t k = 0; k < split.child_count; ++k) {
    total += count_nodes(keys, split.edge[k], split.edge[k + 1]);
  }
  return total;
}

// All nodes: the task subtrees one after the other (each in post-order), then the top nodes;
// children always come before their parent. Tasks count their nodes first so that each writes
// its final slots directly.
std::vector<BuildNode> build_nodes(const NodeMaker& maker, std::size_t grain, ThreadPool& pool,
                                   ProgressPhase& phase) {
  Plan plan;
  const auto n = static_cast<std::uint32_t>(maker.keys.size());
  plan_range(maker.keys, 0, n, std::max<std::size_t>(grain, 1), plan);

  const std::size_t task_count = plan.tasks.size();
  std::vector<std::uint32_t> task_base(task_count + 1, 0);
  pool.run(task_count, [&](std::size_t t) {
    task_base[t + 1] = count_nodes(maker.keys, plan.tasks[t].first, plan.tasks[t].second);
  });
  for (std::size_t t = 0; t < task_count; ++t) task_base[t + 1] += task_base[t];
  std::vector<BuildNode> nodes(std::size_t{task_base.back()} + plan.top.size());
  pool.run(task_count, [&](std::size_t t) {
    const auto [begin, end] = plan.tasks[t];
    NodeOut out{nodes, task_base[t]};
    maker.build(begin, end, out);
    assert(out.next == task_base[t + 1]);
    phase.advance(end - begin);
  });
  const std::uint32_t top_base = task_base.back();
  NodeOut out{nodes, top_base};
  for (const TopNode& top : plan.top) {
    std::uint32_t children[8];
    for (std::uint32_t k = 0; k < top.split.child_count; ++k) {
      const std::uint32_t ref = top.child_ref[k];
      // A task's root is its last node (post-order).
      children[k] = ref & kTaskRef ? task_base[(ref & ~kTaskRef) + 1] - 1 : top_base + ref;
    }
    maker.add_interior({children, top.split.child_count}, top.split, out);
  }
  return nodes;
}

// ---- Pass 4: the sequential list -----------------------------------------------------------

// List order packed into two integers: (range, parent error descending) and the pre-order
// (begin ascending, count descending). Non-negative floats order like their bit patterns.
struct ListKey {
  std::uint64_t major = 0;
  std::uint64_t minor = 0;
  std::uint32_t node = 0;
};
constexpr bool list_before(const ListKey& a, const ListKey& b) {
  return a.major != b.major ? a.major < b.major : a.minor < b.minor;
}
ListKey list_key(std::uint32_t range, float parent_error, const BuildNode& node,
                 std::uint32_t index) {
  const std::uint32_t error_bits = std::bit_cast<std::uint32_t>(parent_error + 0.0f);  // -0 -> +0
  return {std::uint64_t{range} << 32 | ~error_bits, std::uint64_t{node.begin} << 32 | ~node.count,
          index};
}
constexpr std::uint32_t range_of(const ListKey& k) {
  return static_cast<std::uint32_t>(k.major >> 32);
}

void fill_list(const std::vector<BuildNode>& nodes, std::span<const MortonKey> order,
               std::uint32_t chunk_level, bool has_colors, ThreadPool& pool,
               SequentialPointTree& tree) {
  const std::size_t count = nodes.size();
  const auto is_top = [&](const BuildNode& nd) { return !nd.leaf && nd.level < chunk_level; };
  // Chunk roots: not top, parent top (or none); disjoint ranges, so sorting by begin gives the
  // Morton order of their cells.
  std::vector<std::uint32_t> roots;
  for (std::uint32_t i = 0; i < count; ++i) {
    const BuildNode& nd = nodes[i];
    if (!is_top(nd) && (nd.parent == kSptNoParent || is_top(nodes[nd.parent]))) roots.push_back(i);
  }
  std::sort(roots.begin(), roots.end(),
            [&](std::uint32_t a, std::uint32_t b) { return nodes[a].begin < nodes[b].begin; });

  std::vector<ListKey> keys(count);
  parallel_for(pool, count, kPointGrain, [&](std::size_t first, std::size_t last) {
    for (std::size_t i = first; i < last; ++i) {
      const BuildNode& nd = nodes[i];
      std::uint32_t range = 0;
      if (!is_top(nd)) {
        // The chunk is the last root starting at or before this node's range.
        const auto it =
            std::upper_bound(roots.begin(), roots.end(), nd.begin,
                             [&](std::uint32_t b, std::uint32_t r) { return b < nodes[r].begin; });
        range = static_cast<std::uint32_t>(it - roots.begin());
      }
      keys[i] = list_key(range, nd.parent == kSptNoParent ? kInf : nodes[nd.parent].error, nd,
                         static_cast<std::uint32_t>(i));
    }
  });
  parallel_sort(keys, pool, [](const ListKey& a, const ListKey& b) { return list_before(a, b); });

  std::vector<std::uint32_t> position(count);
  parallel_for(pool, count, kPointGrain, [&](std::size_t first, std::size_t last) {
    for (std::size_t i = first; i < last; ++i) {
      position[keys[i].node] = static_cast<std::uint32_t>(i);
    }
  });
  for (auto* v : {&tree.center_x, &tree.center_y, &tree.center_z, &tree.normal_x, &tree.normal_y,
                  &tree.normal_z, &tree.diameter, &tree.error, &tree.parent_error}) {
    v->resize(count);
  }
  tree.is_leaf.resize(count);
  tree.parent.resize(count);
  tree.source.resize(count);
  if (has_colors) tree.colors.resize(count);
  parallel_for(pool, count, kPointGrain, [&](std::size_t first, std::size_t last) {
    for (std::size_t i = first; i < last; ++i) {
      const BuildNode& nd = nodes[keys[i].node];
      tree.center_x[i] = nd.center.x;
      tree.center_y[i] = nd.center.y;
      tree.center_z[i] = nd.center.z;
      tree.normal_x[i] = nd.normal.x;
      tree.normal_y[i] = nd.normal.y;
      tree.normal_z[i] = nd.normal.z;
      tree.diameter[i] = nd.diameter;
      tree.error[i] = nd.error;
      tree.parent_error[i] = nd.parent == kSptNoParent ? kInf : nodes[nd.parent].error;
      tree.is_leaf[i] = nd.leaf ? 1 : 0;
      tree.source[i] = nd.leaf ? order[nd.begin].index : kSptNoParent;
      tree.parent[i] = nd.parent == kSptNoParent ? kSptNoParent : position[nd.parent];
      if (has_colors) {
        const auto byte = [](float c) {
          return static_cast<std::uint8_t>(std::clamp(std::lround(c * 255.0f), 0l, 255l));
        };
        tree.colors[i] = {byte(nd.color[0]), byte(nd.color[1]), byte(nd.color[2])};
      }
    }
  });

  // Range boundaries of the sorted keys; each chunk root sorts first in its chunk (its parent
  // error bounds every other parent error of the chunk, and it is first in pre-order).
  tree.chunk_level = chunk_level;
  tree.chunks.resize(roots.size());
  std::uint32_t at = 0;
  while (at < count && range_of(keys[at]) == 0) ++at;
  tree.top_end = at;
  for (std::size_t k = 0; k < roots.size(); ++k) {
    SptChunk& chunk = tree.chunks[k];
    chunk.begin = at;
    while (at < count && range_of(keys[at]) == k + 1) ++at;
    chunk.end = at;
    const BuildNode& root = nodes[roots[k]];
    assert(position[roots[k]] == chunk.begin);
    chunk.bounds = {root.center, root.diameter * 0.5f};
  }
}

// Smallest float >= x, so a bound computed in double stays a bound once stored as float.
float round_up(double x) {
  float f = static_cast<float>(x);
  if (static_cast<double>(f) < x) f = std::nextafter(f, kInf);
  return f;
}

Vec3d unit(Vec3d a) { return a * (1.0 / std::sqrt(dot(a, a))); }

// The directions of the tangential error: angles jπ/8, j = 0..7, from t1 towards t2.
constexpr int kTangentDirections = 8;
constexpr double kDirectionCos[kTangentDirections] = {
    1.0, 0.92387953251128674,  0.70710678118654752,  0.38268343236508977,
    0.0, -0.38268343236508977, -0.70710678118654752, -0.92387953251128674};
constexpr double kDirectionSin[kTangentDirections] = {
    0.0, 0.38268343236508977, 0.70710678118654752, 0.92387953251128674,
    1.0, 0.92387953251128674, 0.70710678118654752, 0.38268343236508977};

// Half-extent of a disc of radius r and unit normal m along the unit direction u.
double disc_half_extent(double r, Vec3d m, Vec3d u) {
  const double c = dot(m, u);
  return r * std::sqrt(std::max(0.0, 1.0 - c * c));
}

}  // namespace

SptNodeGeometry spt_combine_children(std::span<const SptDisc> children) {
  assert(!children.empty());
  const double inv = 1.0 / static_cast<double>(children.size());
  Vec3d center_sum, normal_sum;
  for (const SptDisc& c : children) {
    center_sum = center_sum + to_double(c.center);
    normal_sum = normal_sum + to_double(c.normal);
  }
  SptNodeGeometry g;
  const Vec3d cm = center_sum * inv;
  g.center = {float(cm.x), float(cm.y), float(cm.z)};
  const double normal_len = std::sqrt(dot(normal_sum, normal_sum));
  // Normals that cancel (a thin sheet seen from both sides) have no mean; use the first child's.
  const Vec3d nm = normal_len > 1e-6 * static_cast<double>(children.size())
                    ? normal_sum * (1.0 / normal_len)
                    : to_double(normalized(children[0].normal));
  g.normal = normalized(Vec3f{float(nm.x), float(nm.y), float(nm.z)});

  // Everything below is measured from the stored (float) centre and normal.
  const Vec3d c0 = to_double(g.center), n = unit(to_double(g.normal));
  // Plane frame: t1 from the world axis least aligned with n.
  const double ax = std::abs(n.x), ay = std::abs(n.y), az = std::abs(n.z);
  const Vec3d axis = ax <= ay && ax <= az ? Vec3d{1, 0, 0} : (ay <= az ? Vec3d{0, 1, 0} : Vec3d{0, 0, 1});
  const Vec3d t1 = unit(axis - n * dot(axis, n)), t2 = cross(n, t1);

  double radius = 0, top = -INFINITY, bottom = INFINITY;
  double hi[kTangentDirections], lo[kTangentDirections];
  std::fill(hi, hi + kTangentDirections, -INFINITY);
  std::fill(lo, lo + kTangentDirections, INFINITY);
  for (const SptDisc& c : children) {
    const Vec3d d = to_double(c.center) - c0;
    const Vec3d m = unit(to_double(normalized(c.normal)));
    const double r = c.radius;
    radius = std::max(radius, std::sqrt(dot(d, d)) + r);
    const double h = dot(d, n), s = disc_half_extent(r, m, n);
    top = std::max(top, h + s);
    bottom = std::min(bottom, h - s);
    // Along u = cos·t1 + sin·t2, both the offset and the normal component are linear in (cos, sin).
    const double d1 = dot(d, t1), d2 = dot(d, t2), m1 = dot(m, t1), m2 = dot(m, t2);
    for (int j = 0; j < kTangentDirections; ++j) {
      const double cj = kDirectionCos[j], sj = kDirectionSin[j];
      const double along = d1 * cj + d2 * sj, mu = m1 * cj + m2 * sj;
      const double half = r * std::sqrt(std::max(0.0, 1.0 - mu * mu));
      hi[j] = std::max(hi[j], along + half);
      lo[j] = std::min(lo[j], along - half);
    }
  }
  g.diameter = round_up(2 * radius);
  g.perpendicular_error = static_cast<float>(top - bottom);
  double narrowest = INFINITY;
  for (int j = 0; j < kTangentDirections; ++j) narrowest = std::min(narrowest, hi[j] - lo[j]);
  g.tangential_error = static_cast<float>(std::max(0.0, double(g.diameter) - narrowest));
  return g;
}

SequentialPointTree build_sequential_point_tree(const PointSet& points, ThreadPool& pool,
                                                Progress& progress,
                                                const SequentialPointTreeOptions& options) {
  check_input(points, options);
  SequentialPointTree tree;
  tree.has_colors = points.has_colors();
  tree.leaf_count = points.size();
  tree.bounds =
      lod_detail::check_points_and_bound(points, pool, "cannot build a sequential point tree");
  tree.view_sphere = {tree.bounds.center(),
                      lod_detail::max_distance(points.positions, tree.bounds.center(), pool)};

  std::vector<BuildNode> nodes;
  std::vector<MortonKey> keys;
  {
    ProgressPhase phase(progress, "hierarchy", points.size());
    keys = morton_keys(points.positions, tree.bounds, pool);
    const std::vector<SortedSplat> splats = gather_splats(points, keys, pool);
    const NodeMaker maker{keys, splats, tree.has_colors, options.color_tolerance};
    nodes = build_nodes(maker, options.parallel_grain_points, pool, phase);
  }
  ProgressPhase phase(progress, "sequential list", nodes.size());
  fill_list(nodes, keys, options.chunk_level, tree.has_colors, pool, tree);
  phase.advance(nodes.size());
  return tree;
}

}  // namespace pointillist
