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
// A point of a piece by its offset from the piece's first point.
using Local = std::uint16_t;
static_assert(kPiece < 0xffff);
constexpr Local kNoLocal = 0xffff;

// What Prim's algorithm keeps per point of a piece, together (8 bytes).
struct Node {
  // Lightest edge to the tree so far; -1 once in the tree, below every weight, so that relaxing
  // an edge needs no separate test (and no branch) for it.
  float key = std::numeric_limits<float>::infinity();
  Local parent = kNoLocal;  // its tree neighbour so far
  Local slot = kNoLocal;  // place in the heap; kNoLocal before the push (stale once in the tree)
  bool in_tree() const { return key < 0; }
};

// Min-heap of a piece's points ordered by (key, index), with decrease-key. The index breaks
// ties, so the pop order (and the tree) depends only on the keys, never on the order of
// relaxations or on the heap's shape. Entries pack the key's bits above the index: keys are
// >= 0, whose float bits order like integers, so one integer comparison orders entries and
// sifting reads only the heap array. Four children a node: half the levels of a binary heap,
// the least child found without branches (5 M cloud: orientation 0.93x the time of two). A
// push and a decrease are one operation, as whether a node is in the heap yet is hard to
// predict (0.94x the time of a branch between them).
class FrontierHeap {
 public:
  explicit FrontierHeap(std::span<Node> nodes) : nodes_(nodes), heap_(nodes.size()) {}

  bool empty() const { return size_ == 0; }

  // After nodes[i].key decreased: pushes i if it is not in the heap yet (without a branch on
  // which, since it is hard to predict), and restores the order.
  void lowered(Local i) {
    const bool fresh = nodes_[i].slot == kNoLocal;
    size_ += fresh ? 1 : 0;
    sift_up(fresh ? size_ - 1 : nodes_[i].slot, entry(i));
  }

  Local pop() {
    const auto top = static_cast<Local>(heap_[0]);
    const std::uint64_t last = heap_[--size_];
    if (size_ > 0) sift_down(0, last);
    nodes_[top].key = -1.0f;  // in the tree: below every weight, no edge relaxes it again
    return top;
  }

 private:
  std::uint64_t entry(Local i) const {
    return (std::uint64_t{std::bit_cast<std::uint32_t>(nodes_[i].key)} << 32) | i;
  }
  void place(std::size_t slot, std::uint64_t e) {
    heap_[slot] = e;
    nodes_[static_cast<Local>(e)].slot = static_cast<Local>(slot);
  }
  void sift_up(std::size_t slot, std::uint64_t item) {
    while (slot > 0) {
      const std::size_t up = (slot - 1) / 4;
      if (heap_[up] <= item) break;
      place(slot, heap_[up]);
      slot = up;
    }
    place(slot, item);
  }
  void sift_down(std::size_t slot, std::uint64_t item) {
    const std::size_t size = size_;
    for (;;) {
      const std::size_t first = 4 * slot + 1;
      if (first >= size) break;
      std::size_t child = first;
      std::uint64_t least = heap_[first];
      const std::size_t last = std::min(size, first + 4);
      for (std::size_t c = first + 1; c < last; ++c) {
        const bool less = heap_[c] < least;
        least = less ? heap_[c] : least;
        child = less ? c : child;
      }
      if (least >= item) break;
      place(slot, least);
      slot = child;
    }
    place(slot, item);
  }

  std::span<Node> nodes_;
  std::vector<std::uint64_t> heap_;  // room for every node of the piece
  std::size_t size_ = 0;
};

// The k-neighbour graph is directed (j near i does not make i near j). Prim's algorithm inside
// a piece needs the symmetric graph of the piece, built per piece, in cache, while its tree
// grows: per point, the entries of its own row that lie in the piece, in row order, then every
// other i of the piece whose row lists it, in increasing order, as 16-bit offsets in one array
// (a piece's lists take ~0.3 MB, its rows ~1 MB). The order matters: where two edges offer a
// node the same weight, the first one relaxed stays its parent. A point that both lists and is
// listed by i appears once, in the first part: relaxing the same edge again from the same end
// would change nothing (only a strictly lighter key replaces a node's), and most k-neighbour
// edges are mutual: leaving the repeats out saves 43 % of the relaxations (5 M cloud).
class PieceGraph {
 public:
  // Rebuilds the lists for the points [lo, lo + size) (all empty for graph_k = 0).
  void build(const OrderedCloud& cloud, std::size_t graph_k, std::uint32_t lo,
             std::uint32_t size) {
    begin_.assign(std::size_t{size} + 1, 0);
    edges_.clear();
    if (graph_k == 0) return;
    // Each point's row entries inside the piece (row order), and the degrees of both ends.
    own_.resize(std::size_t{size} * graph_k);
    own_count_.resize(size);
    for (std::uint32_t i = 0; i < size; ++i) {
      const std::uint32_t* row = cloud.neighbours.data() + std::size_t{lo + i} * cloud.k;
      Local* own = own_.data() + std::size_t{i} * graph_k;
      std::uint32_t n = 0;
      for (std::size_t t = 0; t < graph_k; ++t) {
        const std::uint32_t j = row[t] - lo;
        if (j < size && j != i) {
          own[n++] = static_cast<Local>(j);
          ++begin_[j + 1];
        }
      }
      begin_[i + 1] += n;
      own_count_[i] = static_cast<std::uint8_t>(n);
    }
    for (std::uint32_t j = 0; j < size; ++j) begin_[j + 1] += begin_[j];
    edges_.resize(begin_[size]);
    cursor_.resize(size);
    for (std::uint32_t i = 0; i < size; ++i) cursor_[i] = begin_[i] + own_count_[i];
    // Own entries at the front of each list, then the points that list it, increasing.
    for (std::uint32_t i = 0; i < size; ++i) {
      const Local* own = own_.data() + std::size_t{i} * graph_k;
      std::copy(own, own + own_count_[i], edges_.begin() + begin_[i]);
      for (std::uint32_t t = 0; t < own_count_[i]; ++t) {
        edges_[cursor_[own[t]]++] = static_cast<Local>(i);
      }
    }
    // Mutual pairs: a point's own row already lists it; dropped from the second part.
    stamp_.assign(size, kNoLocal);
    std::uint32_t out = 0;
    for (std::uint32_t i = 0; i < size; ++i) {
      const std::uint32_t from = begin_[i], own_end = from + own_count_[i], end = cursor_[i];
      begin_[i] = out;
      for (std::uint32_t e = from; e < own_end; ++e) {
        stamp_[edges_[e]] = static_cast<Local>(i);
        edges_[out++] = edges_[e];
      }
      for (std::uint32_t e = own_end; e < end; ++e) {
        const Local v = edges_[e];
        edges_[out] = v;
        out += stamp_[v] != i ? 1 : 0;
      }
    }
    begin_[size] = out;
  }
  // The neighbours of the piece's point i in the piece's symmetric graph.
  std::span<const Local> of(Local i) const {
    return std::span<const Local>(edges_).subspan(begin_[i], begin_[i + 1] - begin_[i]);
  }

 private:
  std::vector<std::uint32_t> begin_;  // size + 1 offsets into edges_
  std::vector<std::uint32_t> cursor_;
  std::vector<std::uint8_t> own_count_;
  std::vector<Local> own_;
  std::vector<Local> stamp_;
  std::vector<Local> edges_;
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
    PieceGraph graph;
    graph.build(cloud, m, lo, size);
    FrontierHeap heap(nodes);
    Vec3f* const nn = normals.data() + lo;
    std::vector<double>& vote = votes[piece];
    for (std::uint32_t seed = 0; seed < size; ++seed) {
      if (nodes[seed].in_tree()) continue;
      const auto id = static_cast<std::uint32_t>(vote.size());
      double sum = 0;
      nodes[seed].key = 0.0f;
      heap.lowered(static_cast<Local>(seed));
      while (!heap.empty()) {
        const Local ul = heap.pop();
        const std::uint32_t u = lo + ul;
        const Local parent = nodes[ul].parent;
        if (parent != kNoLocal && dot(nn[ul], nn[parent]) < 0.0f) nn[ul] = -nn[ul];
        component[u] = id;
        const Vec3f nu = nn[ul];
        sum += double(dot(nu, p[u] - c));
        for (const Local v : graph.of(ul)) {
          Node& to = nodes[v];
          const float w = std::max(0.0f, 1.0f - std::abs(dot(nu, nn[v])));
          if (w < to.key) {
            to.key = w;
            to.parent = ul;
            heap.lowered(v);
          }
        }
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
