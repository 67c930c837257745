// Consistent normal orientation by propagation along a spanning tree of smooth edges: Hoppe,
// DeRose, Duchamp, McDonald, Stuetzle, "Surface reconstruction from unorganized points",
// SIGGRAPH 1992, section 3.3. The graph is the symmetrized k-nearest-neighbour graph with edge
// weight 1 - |n_i·n_j|, so the tree follows the smoothest paths and crosses creases last. Hoppe
// grows one minimum spanning tree by Prim's algorithm, which runs on one thread and jumps over the
// whole cloud; here the Morton-ordered points are cut into pieces of kPiece points (compact blocks
// of space) that grow their own minimum spanning trees in parallel, in cache; then the
// components of all pieces are joined by Kruskal's rule on the graph of components, strongest
// evidence first, the evidence of a pair being the summed n_u·n_v of the edges between them.
// Finally each joined surface's points vote whether its normals point away from the centroid,
// and the whole surface is flipped when they mostly do not (Hoppe seeds at the largest z; a
// vote works for any rotation and for surfaces that face the centroid in places, like a torus).
// The pieces do not depend on the thread count, so neither do the normals.
#include <algorithm>
#include <array>
#include <bit>
#include <cassert>
#include <cmath>
#include <limits>

#include "ordered_cloud.hpp"

namespace pointillist::prep_detail {
namespace {

constexpr std::size_t kGrain = 1 << 14;
// Points per piece of the orientation forest: a piece's nodes and rows stay in cache while its
// trees grow.
constexpr std::size_t kPiece = 1 << 14;
constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
constexpr std::uint32_t kInTree = kNone - 1;

// What Prim's algorithm keeps per point of a piece, together.
struct Node {
  float key = std::numeric_limits<float>::infinity();  // lightest edge to the tree so far
  std::uint32_t parent = kNone;  // its tree neighbour so far (an index of the whole cloud)
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

// The k-neighbour graph is directed (j near i does not make i near j). Prim's algorithm inside
// a piece needs the symmetric graph of the piece: besides j's own row, every i of the piece whose
// row lists j, in CSR form, built per piece, in cache, while its tree grows. Where i and j list
// each other, the edge is relaxed twice from the same end with the same weight; only a strictly
// lighter key replaces a node's, so the second changes nothing and the lists need not leave those
// out (finding them cost more than relaxing them again). A list holds its i in increasing order
// (the tree does not depend on it anyway, see FrontierHeap).
class PieceInEdges {
 public:
  // Rebuilds the lists for the points [lo, lo + size) (all empty for graph_k = 0).
  void build(const OrderedCloud& cloud, std::size_t graph_k, std::uint32_t lo,
             std::uint32_t size) {
    lo_ = lo;
    begin_.assign(std::size_t{size} + 1, 0);
    from_.clear();
    if (graph_k == 0) return;
    const auto in_piece = [&](std::uint32_t i, std::size_t t) {
      const std::uint32_t j = cloud.row(i)[t];
      return j - lo < size && j != i;
    };
    for (std::uint32_t i = lo; i < lo + size; ++i) {
      for (std::size_t t = 0; t < graph_k; ++t) {
        if (in_piece(i, t)) ++begin_[cloud.row(i)[t] - lo + 1];
      }
    }
    for (std::uint32_t j = 0; j < size; ++j) begin_[j + 1] += begin_[j];
    from_.resize(begin_[size]);
    // Fill with begin_[j] as the cursor; afterwards begin_[j] holds the old begin_[j + 1].
    for (std::uint32_t i = lo; i < lo + size; ++i) {
      for (std::size_t t = 0; t < graph_k; ++t) {
        if (in_piece(i, t)) from_[begin_[cloud.row(i)[t] - lo]++] = i;
      }
    }
    for (std::uint32_t j = size; j > 0; --j) begin_[j] = begin_[j - 1];
    begin_[0] = 0;
  }
  // The points i of the piece whose rows list the piece's point j.
  std::span<const std::uint32_t> of(std::uint32_t j) const {
    return std::span<const std::uint32_t>(from_).subspan(begin_[j - lo_],
                                                         begin_[j - lo_ + 1] - begin_[j - lo_]);
  }

 private:
  std::uint32_t lo_ = 0;
  std::vector<std::uint32_t> begin_;  // size + 1 offsets into from_
  std::vector<std::uint32_t> from_;
};

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

// Union-find over components with each one's flip relative to its parent, so that joining two
// sets by "these two agree / are opposite" keeps every relative flip.
class ParityForest {
 public:
  explicit ParityForest(std::size_t n) : parent_(n), flip_(n, 0), size_(n, 1) {
    for (std::size_t i = 0; i < n; ++i) parent_[i] = static_cast<std::uint32_t>(i);
  }
  // The root of x's set and x's flip relative to it.
  std::pair<std::uint32_t, std::uint8_t> find(std::uint32_t x) {
    std::uint8_t flip = 0;
    std::uint32_t r = x;
    while (parent_[r] != r) {
      flip ^= flip_[r];
      r = parent_[r];
    }
    // Path compression: point every node on the way at the root, with its flip to it.
    std::uint8_t rest = flip;
    while (parent_[x] != r) {
      const std::uint32_t up = parent_[x];
      const std::uint8_t own = flip_[x];
      parent_[x] = r;
      flip_[x] = rest;
      rest ^= own;
      x = up;
    }
    return {r, flip};
  }
  // Joins the sets of a and b so that a and b flip alike (or oppositely); false when they are
  // already in one set.
  bool join(std::uint32_t a, std::uint32_t b, bool opposite) {
    const auto [ra, fa] = find(a);
    const auto [rb, fb] = find(b);
    if (ra == rb) return false;
    const auto [big, small] = size_[ra] >= size_[rb] ? std::pair{ra, rb} : std::pair{rb, ra};
    parent_[small] = big;
    flip_[small] = std::uint8_t(fa ^ fb ^ (opposite ? 1 : 0));
    size_[big] += size_[small];
    return true;
  }

 private:
  std::vector<std::uint32_t> parent_;
  std::vector<std::uint8_t> flip_;
  std::vector<std::uint32_t> size_;
};

// Evidence between two components of different pieces: the sum of n_u·n_v over the neighbour
// edges that join them (positive: their normals agree as oriented so far).
struct Link {
  std::uint32_t a, b;  // a < b
  double sum;
};

// Sorts links by pair and sums each pair's evidence, in the order given (stable).
void merge_links(std::vector<Link>& links) {
  std::stable_sort(links.begin(), links.end(), [](const Link& x, const Link& y) {
    return x.a < y.a || (x.a == y.a && x.b < y.b);
  });
  std::size_t out = 0;
  for (std::size_t i = 0; i < links.size(); ++i) {
    if (out > 0 && links[out - 1].a == links[i].a && links[out - 1].b == links[i].b) {
      links[out - 1].sum += links[i].sum;
    } else {
      links[out++] = links[i];
    }
  }
  links.resize(out);
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
  const Vec3f c = centre ? *centre : centroid(p, pool);

  // 1. Each piece (a run of kPiece points in Morton order, a compact block of space) grows
  // Prim's trees over the edges inside it, in parallel: a point is oriented when it joins the
  // tree, from its parent. Each tree is a component of the piece, seeded at its first point.
  std::vector<std::uint32_t> component(n);        // each point's component in its piece
  const std::size_t pieces = (n + kPiece - 1) / kPiece;
  std::vector<std::vector<double>> votes(pieces);  // per component: sum of n·(p - c)
  pool.run(pieces, [&](std::size_t piece) {
    const auto lo = static_cast<std::uint32_t>(piece * kPiece);
    const auto size = static_cast<std::uint32_t>(std::min(kPiece, n - lo));
    std::vector<Node> nodes(size);  // indexed from lo
    PieceInEdges in_edges;
    in_edges.build(cloud, m, lo, size);
    FrontierHeap heap(nodes);
    const auto relax = [&](std::uint32_t u, std::uint32_t v) {
      const std::uint32_t local = v - lo;
      if (local >= size) return;  // outside the piece
      Node& to = nodes[local];
      if (to.slot == kInTree) return;
      const float w = std::max(0.0f, 1.0f - std::abs(dot(normals[u], normals[v])));
      if (w < to.key) {
        to.key = w;
        to.parent = u;
        if (to.slot == kNone) {
          heap.push(local);
        } else {
          heap.decreased(local);
        }
      }
    };
    std::vector<double>& vote = votes[piece];
    for (std::uint32_t seed = 0; seed < size; ++seed) {
      if (nodes[seed].slot == kInTree) continue;
      const auto id = static_cast<std::uint32_t>(vote.size());
      double sum = 0;
      nodes[seed].key = 0.0f;
      heap.push(seed);
      while (!heap.empty()) {
        const std::uint32_t u = lo + heap.pop();
        const std::uint32_t parent = nodes[u - lo].parent;
        if (parent != kNone && dot(normals[u], normals[parent]) < 0.0f) normals[u] = -normals[u];
        component[u] = id;
        sum += double(dot(normals[u], p[u] - c));
        for (const std::uint32_t v : cloud.row(u).first(m)) relax(u, v);
        for (const std::uint32_t v : in_edges.of(u)) relax(u, v);
      }
      vote.push_back(sum);
    }
    phase.advance(size / 2);
  });

  // 2. Components of different pieces are joined through the edges between them: per pair,
  // the sum of n_u·n_v over those edges says whether they agree. Pairs are joined strongest
  // evidence first (Kruskal's rule on the graph of components), so a few edges across a crease
  // cannot overrule many along a smooth surface.
  std::vector<std::size_t> first(pieces + 1, 0);
  for (std::size_t piece = 0; piece < pieces; ++piece) {
    first[piece + 1] = first[piece] + votes[piece].size();
  }
  const std::size_t count = first[pieces];
  const auto global = [&](std::uint32_t u) {
    return static_cast<std::uint32_t>(first[u / kPiece] + component[u]);
  };
  std::vector<std::vector<Link>> piece_links(pieces);
  pool.run(pieces, [&](std::size_t piece) {
    const std::size_t lo = piece * kPiece, hi = std::min(n, lo + kPiece);
    std::vector<Link>& links = piece_links[piece];
    for (std::size_t u = lo; u < hi; ++u) {
      for (const std::uint32_t v : cloud.row(u).first(m)) {
        if (v / kPiece == piece) continue;
        const std::uint32_t a = global(std::uint32_t(u)), b = global(v);
        links.push_back({std::min(a, b), std::max(a, b),
                         double(dot(normals[u], normals[v]))});
      }
    }
    merge_links(links);
    phase.advance((hi - lo) - (hi - lo) / 2);
  });
  std::vector<Link> links;
  for (auto& l : piece_links) {
    links.insert(links.end(), l.begin(), l.end());
    l = {};
  }
  merge_links(links);  // piece order within a pair: the same sums for any thread count
  std::sort(links.begin(), links.end(), [](const Link& x, const Link& y) {
    const double sx = std::abs(x.sum), sy = std::abs(y.sum);
    return sx > sy || (sx == sy && (x.a < y.a || (x.a == y.a && x.b < y.b)));
  });
  ParityForest forest(count);
  for (const Link& l : links) {
    if (l.sum != 0) forest.join(l.a, l.b, l.sum < 0);  // no evidence either way: no link
  }

  // 3. Each joined surface's points vote: its normals are made to point away from the centroid
  // where, summed over the surface, they most do (each point weighted by how squarely its
  // normal faces away from or toward the centroid). One seed alone can sit where "away" is
  // ambiguous (the edge of a ground plane) and turn a whole scan inside out.
  std::vector<double> vote(count);
  for (std::size_t piece = 0; piece < pieces; ++piece) {
    std::copy(votes[piece].begin(), votes[piece].end(), vote.begin() + std::ptrdiff_t(first[piece]));
  }
  votes = {};
  std::vector<std::uint8_t> flip(count);
  std::vector<std::uint32_t> root(count);
  std::vector<double> surface_vote(count, 0.0);
  for (std::uint32_t g = 0; g < count; ++g) {
    const auto [r, f] = forest.find(g);
    root[g] = r;
    flip[g] = f;
    surface_vote[r] += f ? -vote[g] : vote[g];  // in component order: the same bits always
  }
  // Surfaces are numbered in the order of their first point.
  std::vector<std::uint32_t> number(count, kNone);
  std::uint32_t surfaces = 0;
  for (std::uint32_t g = 0; g < count; ++g) {
    if (number[root[g]] == kNone) number[root[g]] = surfaces++;
    number[g] = number[root[g]];
    flip[g] ^= surface_vote[root[g]] < 0 ? 1 : 0;
  }
  if (components) components->resize(n);
  parallel_for(pool, n, kGrain, [&](std::size_t begin, std::size_t end) {
    for (std::size_t u = begin; u < end; ++u) {
      const std::uint32_t g = global(std::uint32_t(u));
      if (flip[g]) normals[u] = -normals[u];
      if (components) (*components)[u] = number[g];
    }
  });
}

}  // namespace pointillist::prep_detail
