// Occlusion culling (shared/specs/occlusion-simplification-hybrid.md §1): occlusion queries
// behind an interface, their software backend over a hierarchical max-depth pyramid, and the
// culling methods that use them: hierarchical stop-and-wait, CHC (Bittner, Wimmer, Piringer &
// Purgathofer 2004) and CHC++ (Mattausch, Bittner & Wimmer 2008).
//
// On a CPU, "latency" is the render queue: a query can only be answered after the splats queued
// before it are drawn and the pyramid refreshed (a flush). Queries here are answered against the
// depth at the time they are issued (the render queue is flushed first, CHC++ rule R3); their
// result becomes available after `latency` further flushes, so decisions never depend on
// wall-clock time or the thread count.
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "pointillist/core/camera.hpp"
#include "pointillist/core/math.hpp"

namespace pointillist {

enum class OcclusionMethod {
  None,         // draw everything the frustum, backface and detail tests keep
  StopAndWait,  // query every node and wait for the answer (spec §1.2)
  Chc,          // coherent hierarchical culling (§1.3)
  ChcPlusPlus,  // CHC with batching, multiqueries, randomized re-queries, tight bounds (§1.4)
};
constexpr const char* name(OcclusionMethod m) {
  return m == OcclusionMethod::None          ? "none"
         : m == OcclusionMethod::StopAndWait ? "stop-and-wait"
         : m == OcclusionMethod::Chc         ? "chc"
                                             : "chc++";
}

struct OcclusionSettings {
  OcclusionMethod method = OcclusionMethod::None;
  // Flushes after its issue before a query's answer may be used (0: at once).
  unsigned query_latency = 0;
  // A model's hierarchy is culled down to subtrees of at most this many points (culling leaves).
  std::uint32_t leaf_points = 4096;
  // Nodes expected to draw fewer splats than this are drawn without a query.
  std::uint32_t min_query_splats = 32;
  // CHC++ rules, each of which can be switched off (the ablation of spec §1.8 check 4).
  bool batching = true;      // R1: previously invisible nodes queried in batches of `batch`
  unsigned batch = 50;
  bool multiqueries = true;  // R4: batches grouped into multiqueries by the cost model
  // R4, ours: a failed multiquery whose nodes are likely to stay hidden is queried again as its
  // two halves (group testing) instead of node by node; the cost model counts that.
  bool split_failed = true;
  bool randomized = true;    // R5: the first re-query of a node turned visible after r ∈ [0, n_av]
  unsigned requery_frames = 5;  // n_av: visible leaves are re-queried every n_av frames
  // Ours: each re-query that finds a leaf still visible doubles its interval, up to
  // n_av · 2^requery_doublings frames (0: every n_av frames, the paper's rule).
  unsigned requery_doublings = 2;
  bool tight_bounds = true;  // R6: a node's query is its descendants' spheres, d_max levels down
  unsigned tight_depth = 3;  // d_max
  float tight_area_ratio = 1.4f;  // refinement stops when Σ r_child² > ratio · r²
  std::uint64_t seed = 1;    // of R5's random re-query offsets (hashed with node and frame)
};

// Counts of one frame (RenderStats::occlusion).
struct OcclusionStats {
  std::uint64_t nodes_visited = 0;     // culling-hierarchy nodes taken from the traversal queue
  std::uint64_t leaves_drawn = 0;      // culling leaves drawn (whole or as one coarse splat)
  std::uint64_t leaves_culled = 0;     // culling leaves under nodes a query found hidden
  std::uint64_t instances_drawn = 0;   // instances with at least one leaf drawn
  std::uint64_t queries_single = 0;    // queries on one node (its bound or its tight bounds)
  std::uint64_t queries_multi = 0;     // multiqueries (several nodes, CHC++ R4)
  std::uint64_t multiquery_nodes = 0;  // nodes in them
  std::uint64_t multiquery_failed = 0; // multiqueries answered visible (each node re-queried)
  std::uint64_t v_queries = 0;         // queries of previously visible leaves (result next frame)
  std::uint64_t queries_skipped = 0;   // visible leaves not re-queried this frame (n_av)
  std::uint64_t flushes = 0;           // render-queue flushes that drew something
  std::uint64_t stalls = 0;            // results asked before they were available
  std::uint64_t tiles_tested = 0;      // pyramid tiles and pixels tested by queries
  // Paged models: subtrees in other pages found hidden while a visible instance selected its
  // splats (neither drawn nor requested).
  std::uint64_t paged_subtrees_culled = 0;
  double ms_query = 0, ms_hiz = 0;     // answering queries; refreshing the pyramid
};

// A query volume: a sphere in world space.
struct QueryBound {
  Vec3f center;
  float radius = 0;
};

// What a query must assume of the splats inside a bound: every splat of the node lies within the
// sphere grown `footprint_scale` times (splat scale; in quality mode also the disc radius
// scale), covers at most the pixels of that sphere's screen box plus one, and `pad_px` more
// (the quality mode's screen low-pass); its fragments are nowhere nearer than the sphere's
// centre depth less `depth_scale` radii (1 for the fast mode's centre-depth splats; the
// quality mode's reconstruction keys reach further forward, spec §1.7).
struct QueryFootprint {
  float footprint_scale = 1.0f;
  float depth_scale = 1.0f;
  float pad_px = 0.0f;
};

// The hierarchical max-depth pyramid over a depth buffer (eye depth, +∞ where empty). Level 0
// is the depth buffer itself; level k holds the maximum over 2^k × 2^k pixels.
class DepthPyramid {
 public:
  // Starts a frame of width × height pixels over `depth` (which the caller keeps and draws into);
  // every level is rebuilt from it.
  void reset(std::span<const float> depth, int width, int height);
  // Rebuilds the levels above the pixels [x0, x1) × [y0, y1) after they were drawn.
  void refresh(int x0, int y0, int x1, int y1);
  // Whether some pixel of [x0, x1] × [y0, y1] (inclusive, clipped to the image) has depth ≥
  // z_min, i.e. a fragment at z_min could still be drawn there. `tested` counts the tiles and
  // pixels looked at.
  bool any_at_or_behind(int x0, int y0, int x1, int y1, float z_min,
                        std::uint64_t& tested) const;
  int levels() const { return static_cast<int>(level_.size()) + 1; }

 private:
  float at(int level, int x, int y) const;
  bool descend(int level, int tx, int ty, int x0, int y0, int x1, int y1, float z_min,
               std::uint64_t& tested) const;
  std::span<const float> depth_;
  int width_ = 0, height_ = 0;
  struct Level {
    int width = 0, height = 0;
    std::vector<float> max;
  };
  std::vector<Level> level_;  // level_[k - 1] is level k
};

// Whether a node inside `bound` may draw a visible pixel: false only when every pixel its splats
// could cover already holds something strictly nearer than the nearest point of the sphere. A
// sphere reaching the eye's plane (nearest depth ≤ 0) is visible without a test. `tested` counts
// pyramid tiles and pixels.
bool bound_may_be_visible(const DepthPyramid& pyramid, const CameraFrame& camera,
                          const QueryBound& bound, const QueryFootprint& footprint,
                          std::uint64_t& tested);

using QueryId = std::uint32_t;

// Occlusion queries (ARCHITECTURE.md): issue a query on one or several bounds, poll whether its
// answer is available, read it; a render queue whose contents are drawn before any query is
// answered (flush).
class OcclusionQueries {
 public:
  virtual ~OcclusionQueries() = default;
  // Draws the render queue, then queries `bounds` (visible when any of them is).
  virtual QueryId issue(std::span<const QueryBound> bounds) = 0;
  virtual bool poll(QueryId id) const = 0;
  // 1 when some bound may be visible, else 0 (an upper bound on visible pixels, clamped to 1).
  // Flushes until the answer is available when it is not yet (a stall).
  virtual std::uint32_t result(QueryId id) = 0;
  // Queues a culling node's splats to be drawn at the next flush.
  virtual void enqueue_render(std::uint32_t node) = 0;
  // Draws the render queue (possibly nothing) and counts one flush toward pending answers.
  virtual void flush() = 0;
  // The frame's last flush: no query follows, so a backend need not make what it draws
  // testable (the software one skips refreshing its pyramid).
  virtual void finish() { flush(); }
};

// The software backend: the render queue is handed to `draw` (which draws the nodes' splats into
// the depth buffer the pyramid reads and returns the pixel rectangle it touched, [x0, x1) ×
// [y0, y1)), the pyramid is refreshed there, and queries are answered from it. At finish(),
// `draw` is told (`last`) that nothing will test what it draws.
class SoftwareQueries final : public OcclusionQueries {
 public:
  struct Rect {  // pixels [x0, x1) × [y0, y1)
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    bool empty() const { return x1 <= x0 || y1 <= y0; }
    // Grows to hold `r` too (an empty `r` changes nothing).
    void add(const Rect& r) {
      if (r.empty()) return;
      x0 = std::min(x0, r.x0), y0 = std::min(y0, r.y0);
      x1 = std::max(x1, r.x1), y1 = std::max(y1, r.y1);
    }
  };
  using Draw = std::function<Rect(std::span<const std::uint32_t> nodes, bool last)>;
  SoftwareQueries(DepthPyramid& pyramid, const CameraFrame& camera, QueryFootprint footprint,
                  unsigned latency, Draw draw, OcclusionStats& stats);
  QueryId issue(std::span<const QueryBound> bounds) override;
  bool poll(QueryId id) const override;
  std::uint32_t result(QueryId id) override;
  void enqueue_render(std::uint32_t node) override { queue_.push_back(node); }
  void flush() override;
  void finish() override;

 private:
  void draw_queue(bool last = false);
  DepthPyramid& pyramid_;
  const CameraFrame& camera_;
  QueryFootprint footprint_;
  unsigned latency_;
  Draw draw_;
  OcclusionStats& stats_;
  std::vector<std::uint32_t> queue_;
  std::uint64_t flushes_ = 0;
  struct Answer {
    std::uint64_t available_at;  // flush count
    std::uint32_t visible;
  };
  std::vector<Answer> answers_;
};

// CHC++'s cost model (spec §1.4, R4): the probability that a node invisible for i frames stays
// invisible, pkeep(i) = 0.99 − 0.7·e^(−i).
double keep_probability(std::uint64_t frames_invisible);

// R4's grouping of previously invisible nodes, given each one's pkeep already sorted in the
// order they are grouped: the sizes of consecutive groups, each the longest prefix of what is
// left along which V(M) = |M| / C(M) does not decrease, where C(M) = 1 + (1 − Π pkeep)·|M| is
// the expected number of queries when a failed group re-queries each node (the paper's rule).
// With `split`, a failed group may instead be queried again as its two halves (the first
// ⌈|M|/2⌉ nodes and the rest), each half planned alike: C(M) is split_query_cost, and each
// group is the prefix of largest V(M).
std::vector<std::size_t> multiquery_groups(std::span<const double> keep, bool split = false);
// The expected number of queries of a multiquery on nodes of these pkeep (in group order) under
// its best plan for failure: re-query each node, or query both halves and plan each alike (a
// query is made only when its parent group failed, so C = 1 + Σ over failed-group plans).
double split_query_cost(std::span<const double> keep);
// Whether that plan queries the halves of this group when it fails (else each node).
bool split_failed_group(std::span<const double> keep);

// The culling hierarchy a method traverses: nodes with a bounding sphere, children, and per frame
// a classification from the caller (frustum, detail) and a distance for front-to-back order.
struct CullHierarchy {
  struct Node {
    QueryBound bound;
    std::uint32_t parent = UINT32_MAX;
    std::uint32_t first_child = 0, child_count = 0;  // into `children`
    std::uint32_t culling_leaves = 1;                // culling leaves in the subtree
  };
  std::vector<Node> nodes;                // node 0 is the root
  std::vector<std::uint32_t> children;    // child lists
};

// What the traversal asks of the scene for one frame.
struct CullCallbacks {
  enum class Kind : std::uint8_t {
    Outside,  // culled by the frustum or backface test (not visited further)
    Leaf,     // drawn as a whole when visible (a culling leaf, or where the detail stops)
    Interior  // opened into its children when visible
  };
  struct Visit {
    Kind kind = Kind::Outside;
    float distance = 0;       // front-to-back order
    bool near = false;        // reaches the eye's plane: visible without a query
    bool small = false;       // expected to draw fewer than min_query_splats: drawn unqueried
  };
  std::function<Visit(std::uint32_t node)> visit;
  // The query volumes of a node: its sphere, or with tight bounds its descendants' spheres.
  std::function<void(std::uint32_t node, std::vector<QueryBound>& out)> bounds;
};

// The persistent state of a hierarchy's nodes across frames.
struct CullState {
  struct Node {
    bool visible = false;
    std::uint64_t last_visited = 0;  // frame
    std::uint64_t last_visible = 0;  // frame
    // First frame of the node's current run of frames visited and found hidden (R4's
    // persistence i = frame − hidden_since + 1; a node seen for the first time has i = 1).
    std::uint64_t hidden_since = 0;
    std::uint64_t next_query = 0;    // frame at which a visible leaf is queried again
    std::uint8_t still_visible = 0;  // re-queries in a row that found the leaf visible
  };
  std::vector<Node> nodes;
  std::uint64_t frame = 0;
  // Work buffers of a frame, kept for the next.
  std::vector<CullCallbacks::Visit> visits;
  std::vector<std::uint8_t> was_visible;
};

// One frame of `settings.method` (not None) over `h`: visible leaves are queued on `queries`
// (enqueue_render) and flushed; returns when every queued leaf is drawn. `state` carries
// visibility between frames (sized to h on first use).
void cull_frame(const CullHierarchy& h, const CullCallbacks& callbacks,
                const OcclusionSettings& settings, OcclusionQueries& queries, CullState& state,
                OcclusionStats& stats);

}  // namespace pointillist
