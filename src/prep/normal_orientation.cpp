// Consistent normal orientation by propagation along a minimum spanning tree: Hoppe, DeRose,
// Duchamp, McDonald, Stuetzle, "Surface reconstruction from unorganized points", SIGGRAPH 1992,
// section 3.3. The graph is the symmetrized k-nearest-neighbour graph with edge weight
// 1 - |n_i·n_j|, so the tree follows the smoothest paths and crosses creases last. Each connected
// component is seeded at its point farthest from the centroid of the whole cloud (Hoppe seeds
// at the largest z instead; the farthest point lies on the convex hull and works for any
// rotation); then the component's points vote whether its normals point away from the centroid,
// and the whole component is flipped when they mostly do not.
#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cassert>
#include <cmath>
#include <limits>

#include "ordered_cloud.hpp"

namespace pointillist::prep_detail {
namespace {

constexpr std::size_t kGrain = 1 << 14;
constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
constexpr std::uint32_t kInTree = kNone - 1;

// Everything Prim's algorithm touches per point, together.
struct Node {
  Vec3f normal;
  float key = std::numeric_limits<float>::infinity();  // lightest edge to the tree so far
  std::uint32_t parent = kNone;
  std::uint32_t slot = kNone;  // place in the heap; kNone before the push, kInTree after the pop
};

// Binary min-heap of points ordered by (key, index), with decrease-key. The index breaks ties,
// so the pop order (and the tree) depends only on the keys, never on the order of relaxations.
// Entries pack the key's bits above the index: keys are >= 0, whose float bits order like
// integers, so one integer comparison orders entries and sifting reads only the heap array.
class FrontierHeap {
 public:
  explicit FrontierHeap(std::span<Node> nodes) : nodes_(nodes) {}

  bool empty() const { return heap_.empty(); }

  void push(std::uint32_t i) {
    heap_.push_back(0);
    sift_up(heap_.size() - 1, entry(i));
  }
  // After nodes[i].key decreased.
  void decreased(std::uint32_t i) { sift_up(nodes_[i].slot, entry(i)); }

  std::uint32_t pop() {
    const auto top = static_cast<std::uint32_t>(heap_.front());
    const std::uint64_t last = heap_.back();
    heap_.pop_back();
    if (!heap_.empty()) sift_down(0, last);
    nodes_[top].slot = kInTree;
    return top;
  }

 private:
  std::uint64_t entry(std::uint32_t i) const {
    return (std::uint64_t{std::bit_cast<std::uint32_t>(nodes_[i].key)} << 32) | i;
  }
  void place(std::size_t slot, std::uint64_t e) {
    heap_[slot] = e;
    nodes_[static_cast<std::uint32_t>(e)].slot = static_cast<std::uint32_t>(slot);
  }
  void sift_up(std::size_t slot, std::uint64_t item) {
    while (slot > 0) {
      const std::size_t up = (slot - 1) / 2;
      if (heap_[up] <= item) break;
      place(slot, heap_[up]);
      slot = up;
    }
    place(slot, item);
  }
  void sift_down(std::size_t slot, std::uint64_t item) {
    const std::size_t size = heap_.size();
    for (;;) {
      std::size_t child = 2 * slot + 1;
      if (child >= size) break;
      if (child + 1 < size && heap_[child + 1] < heap_[child]) ++child;
      if (heap_[child] >= item) break;
      place(slot, heap_[child]);
      slot = child;
    }
    place(slot, item);
  }

  std::span<Node> nodes_;
  std::vector<std::uint64_t> heap_;
};

// The k-neighbour graph is directed (j near i does not make i near j). The reverse edges j -> i
// that the forward rows lack, in CSR form, so rows + reverse lists are the symmetric graph. The
// order inside a list depends on thread timing; the tree does not (see FrontierHeap).
struct ReverseEdges {
  std::vector<std::uint32_t> begin;  // n + 1 offsets into `from`
  std::vector<std::uint32_t> from;
};

ReverseEdges missing_reverse_edges(const OrderedCloud& cloud, std::size_t graph_k,
                                   ThreadPool& pool) {
  const std::size_t n = cloud.size();
  const std::span<const Vec3f> p = cloud.positions;
  // Row j holds every point strictly closer to j than its last entry and none farther, so
  // comparing distances answers "does row j list i" without searching, except near equality
  // (ties, or rounding different from the kd-tree's).
  std::vector<float> last_d2(n);
  parallel_for(pool, n, kGrain, [&](std::size_t begin, std::size_t end) {
    for (std::size_t j = begin; j < end; ++j) {
      last_d2[j] = length_squared(p[cloud.row(j)[graph_k - 1]] - p[j]);
    }
  });
  const auto lists = [&](std::size_t j, std::size_t i) {
    const float d2 = length_squared(p[i] - p[j]);
    const float last = last_d2[j];
    if (d2 < last * (1.0f - 1e-5f)) return true;
    if (d2 > last * (1.0f + 1e-5f)) return false;
    const auto row = cloud.row(j).first(graph_k);
    return std::find(row.begin(), row.end(), static_cast<std::uint32_t>(i)) != row.end();
  };
  // Bit t of one_way[i]: row(j = row(i)[t]) does not list i, so j needs the reverse edge. Found
  // once and kept for the fill pass (graphs of more than 32 neighbours search again instead).
  std::vector<std::uint32_t> one_way(graph_k <= 32 ? n : 0);
  const auto needs_reverse = [&](std::size_t i, std::size_t t) {
    if (!one_way.empty()) return ((one_way[i] >> t) & 1) != 0;
    const std::uint32_t j = cloud.row(i)[t];
    return j != i && !lists(j, i);
  };
  ReverseEdges r;
  r.begin.assign(n + 1, 0);
  parallel_for(pool, n, kGrain, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const auto row = cloud.row(i);
      std::uint32_t bits = 0;
      for (std::size_t t = 0; t < graph_k; ++t) {
        const std::uint32_t j = row[t];
        if (j != i && !lists(j, i)) {
          bits |= std::uint32_t{1} << (t & 31);
          std::atomic_ref<std::uint32_t>(r.begin[j + 1]).fetch_add(1, std::memory_order_relaxed);
        }
      }
      if (!one_way.empty()) one_way[i] = bits;
    }
  });
  last_d2 = {};
  for (std::size_t j = 0; j < n; ++j) r.begin[j + 1] += r.begin[j];
  r.from.resize(r.begin[n]);
  // Fill with begin[j] as the cursor; afterwards begin[j] holds the old begin[j + 1].
  parallel_for(pool, n, kGrain, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      for (std::size_t t = 0; t < graph_k; ++t) {
        if (!needs_reverse(i, t)) continue;
        const std::uint32_t j = cloud.row(i)[t];
        const std::uint32_t slot =
            std::atomic_ref<std::uint32_t>(r.begin[j]).fetch_add(1, std::memory_order_relaxed);
        r.from[slot] = static_cast<std::uint32_t>(i);
      }
    }
  });
  for (std::size_t j = n; j > 0; --j) r.begin[j] = r.begin[j - 1];
  r.begin[0] = 0;
  return r;
}

Vec3f centroid(std::span<const Vec3f> positions, ThreadPool& pool) {
  const std::size_t n = positions.size();
  const std::size_t chunks = (n + kGrain - 1) / kGrain;
  std::vector<std::array<double, 3>> sums(chunks, {0, 0, 0});
  pool.run(chunks, [&](std::size_t c) {
    const std::size_t end = std::min(n, (c + 1) * kGrain);
    for (std::size_t i = c * kGrain; i < end; ++i) {
      sums[c][0] += positions[i].x;
      sums[c][1] += positions[i].y;
      sums[c][2] += positions[i].z;
    }
  });
  double s[3] = {0, 0, 0};  // merged in chunk order: the same bits for any thread count
  for (const auto& c : sums) {
    for (int a = 0; a < 3; ++a) s[a] += c[a];
  }
  return {float(s[0] / double(n)), float(s[1] / double(n)), float(s[2] / double(n))};
}

}  // namespace

void orient_normals_ordered(const OrderedCloud& cloud, std::uint32_t graph_k,
                            std::span<Vec3f> normals, ThreadPool& pool, Progress& progress,
                            const Vec3f* centre, std::vector<std::uint32_t>* components) {
  const std::size_t n = cloud.size();
  assert(normals.size() == n);
  const std::size_t m = std::min(graph_k, cloud.k);
  ProgressPhase phase(progress, "orientation", n);
  if (n == 0) return;
  const std::span<const Vec3f> p = cloud.positions;
  const ReverseEdges reverse = m > 0 ? missing_reverse_edges(cloud, m, pool) : ReverseEdges{};
  const Vec3f c = centre ? *centre : centroid(p, pool);
  const auto far = [&](std::size_t i) {
    const float f = length_squared(p[i] - c);
    return std::isfinite(f) ? f : -1.0f;
  };

  // Prim's algorithm; a point is oriented when it joins the tree, from its parent.
  std::vector<Node> nodes(n);
  for (std::size_t i = 0; i < n; ++i) nodes[i].normal = normals[i];
  FrontierHeap heap(nodes);
  std::size_t joined = 0;
  const auto relax = [&](const Node& from, std::uint32_t u, std::uint32_t v) {
    Node& to = nodes[v];
    if (to.slot == kInTree) return;
    const float w = std::max(0.0f, 1.0f - std::abs(dot(from.normal, to.normal)));
    if (w < to.key) {
      to.key = w;
      to.parent = u;
      if (to.slot == kNone) {
        heap.push(v);
      } else {
        heap.decreased(v);
      }
    }
  };
  const auto in_tree = [&](std::size_t i) { return nodes[i].slot == kInTree; };
  std::vector<std::uint32_t> members;
  std::uint32_t component_count = 0;
  if (components) components->assign(n, 0);
  const auto grow_tree = [&](std::uint32_t seed) {
    if (dot(nodes[seed].normal, p[seed] - c) < 0.0f) nodes[seed].normal = -nodes[seed].normal;
    nodes[seed].key = 0.0f;
    heap.push(seed);
    members.clear();
    while (!heap.empty()) {
      const std::uint32_t u = heap.pop();
      members.push_back(u);
      Node& node = nodes[u];
      if (node.parent != kNone && dot(node.normal, nodes[node.parent].normal) < 0.0f) {
        node.normal = -node.normal;
      }
      for (const std::uint32_t v : cloud.row(u).first(m)) relax(node, u, v);
      for (std::uint32_t e = reverse.begin[u]; e < reverse.begin[u + 1]; ++e) {
        relax(node, u, reverse.from[e]);
      }
      if (++joined % 65536 == 0) phase.advance(65536);
    }
    // The component's points vote: normals are made to point away from the centroid where,
    // summed over the component, they most do (each point weighted by how squarely its normal
    // faces away from or toward the centroid). One seed alone can sit where "away" is
    // ambiguous (the edge of a ground plane) and turn a whole scan inside out.
    double vote = 0;
    for (const std::uint32_t u : members) vote += double(dot(nodes[u].normal, p[u] - c));
    if (components) {
      for (const std::uint32_t u : members) (*components)[u] = component_count;
    }
    ++component_count;
    if (vote < 0) {
      for (const std::uint32_t u : members) nodes[u].normal = -nodes[u].normal;
    }
  };

  // Each component is seeded at its farthest point: the farthest point not yet in a tree always
  // is one. A scan finds it; after kScans components the rest are sorted by distance once.
  constexpr int kScans = 8;
  for (int scan = 0; scan < kScans && joined < n; ++scan) {
    std::uint32_t seed = kNone;
    float seed_far = -2.0f;  // below every far()
    for (std::size_t i = 0; i < n; ++i) {
      if (in_tree(i)) continue;
      const float f = far(i);
      if (f > seed_far) {  // ties go to the lower index
        seed_far = f;
        seed = static_cast<std::uint32_t>(i);
      }
    }
    grow_tree(seed);
  }
  if (joined < n) {
    std::vector<std::pair<float, std::uint32_t>> rest;
    for (std::size_t i = 0; i < n; ++i) {
      if (!in_tree(i)) rest.emplace_back(far(i), static_cast<std::uint32_t>(i));
    }
    std::sort(rest.begin(), rest.end(), [](const auto& a, const auto& b) {
      return a.first > b.first || (a.first == b.first && a.second < b.second);
    });
    for (const auto& [d2, i] : rest) {
      if (!in_tree(i)) grow_tree(i);
    }
  }
  for (std::size_t i = 0; i < n; ++i) normals[i] = nodes[i].normal;
  phase.advance(joined % 65536);
}

}  // namespace pointillist::prep_detail
