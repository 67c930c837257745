// Hierarchical stop-and-wait, CHC and CHC++ over a culling hierarchy (shared/specs/
// occlusion-simplification-hybrid.md §1.2–1.4; the pseudocode of §1.4 is followed line by line).
#include <algorithm>
#include <deque>
#include <queue>
#include <vector>

#include "pointillist/render/occlusion.hpp"

namespace pointillist {

namespace {

using Kind = CullCallbacks::Kind;

// R5's random offset in [0, n], a hash of the seed, node and frame (no state, so the same for
// any thread count and order of evaluation).
std::uint64_t random_offset(std::uint64_t seed, std::uint32_t node, std::uint64_t frame,
                            unsigned n) {
  std::uint64_t x = seed ^ (static_cast<std::uint64_t>(node) << 32) ^ (frame * 0x9E3779B97F4A7C15ull);
  x ^= x >> 30;
  x *= 0xBF58476D1CE4E5B9ull;
  x ^= x >> 27;
  x *= 0x94D049BB133111EBull;
  x ^= x >> 31;
  return x % (static_cast<std::uint64_t>(n) + 1);
}

class Culler {
 public:
  Culler(const CullHierarchy& h, const CullCallbacks& cb, const OcclusionSettings& s,
         OcclusionQueries& q, CullState& state, OcclusionStats& stats)
      : h_(h), cb_(cb), s_(s), q_(q), st_(state.nodes), stats_(stats), f_(state.frame),
        visit_(state.visits), was_(state.was_visible) {
    visit_.resize(h.nodes.size());
    was_.resize(h.nodes.size());  // written for each node visited before it is read
  }

  void run() {
    push(0);
    const bool plus = s_.method == OcclusionMethod::ChcPlusPlus;
    while (!heap_.empty() || !pending_.empty()) {
      while (!pending_.empty() && q_.poll(pending_.front().id)) handle_front();
      if (!heap_.empty()) {
        const std::uint32_t n = heap_.top().node;
        heap_.pop();
        visit_node(n);
      } else if (!pending_.empty()) {
        if (plus && !v_queue_.empty()) {
          const std::uint32_t n = v_queue_.front();  // R2: fill the wait
          v_queue_.pop_front();
          issue_single(n, true);
        } else {
          handle_front();  // waits (result() flushes: a stall)
        }
      }
      if (heap_.empty() && !i_queue_.empty()) issue_batch();
    }
    while (!v_queue_.empty()) {
      issue_single(v_queue_.front(), true);
      v_queue_.pop_front();
    }
    while (!pending_.empty()) handle_front();
    q_.finish();
  }

 private:
  struct Entry {
    float distance;
    std::uint32_t node;
    bool operator>(const Entry& o) const {
      return distance > o.distance || (distance == o.distance && node > o.node);
    }
  };
  struct Pending {
    QueryId id;
    std::vector<std::uint32_t> nodes;
    bool v_query;
    std::vector<double> keep;  // a multiquery's pkeep per node (for the halving rule)
  };

  void push(std::uint32_t n) {
    const CullCallbacks::Visit v = cb_.visit(n);
    if (v.kind == Kind::Outside) return;
    visit_[n] = v;
    heap_.push({v.distance, n});
  }

  void pull_up(std::uint32_t n) {
    while (n != UINT32_MAX && !st_[n].visible) {
      st_[n].visible = true;
      st_[n].last_visible = f_;
      n = h_.nodes[n].parent;
    }
  }

  void traverse(std::uint32_t n) {
    if (visit_[n].kind == Kind::Leaf) {
      q_.enqueue_render(n);
      ++stats_.leaves_drawn;
      return;
    }
    const CullHierarchy::Node& node = h_.nodes[n];
    for (std::uint32_t k = 0; k < node.child_count; ++k) push(h_.children[node.first_child + k]);
  }

  void visit_node(std::uint32_t n) {
    ++stats_.nodes_visited;
    const CullCallbacks::Visit& v = visit_[n];
    CullState::Node& s = st_[n];
    const bool seen_last_frame = s.last_visited + 1 == f_;
    const bool was = s.visible && seen_last_frame;
    was_[n] = was;
    // A run of hidden frames goes on only from a frame that visited it and found it hidden.
    if (was || !seen_last_frame) s.hidden_since = f_;
    s.last_visited = f_;
    s.visible = false;  // CHC: visited nodes start invisible; pull-up marks the visible
    if (v.near || v.small) {
      pull_up(n);
      traverse(n);
      return;
    }
    switch (s_.method) {
      case OcclusionMethod::StopAndWait: {
        const QueryId id = issue(n);
        if (q_.result(id) > 0) {
          pull_up(n);
          traverse(n);
        } else {
          stats_.leaves_culled += h_.nodes[n].culling_leaves;
        }
        return;
      }
      case OcclusionMethod::Chc:
      case OcclusionMethod::ChcPlusPlus:
      case OcclusionMethod::None:
        break;
    }
    const bool plus = s_.method == OcclusionMethod::ChcPlusPlus;
    if (!was) {
      if (plus && s_.batching) {
        i_queue_.push_back(n);  // R1
        if (i_queue_.size() >= s_.batch) issue_batch();
      } else {
        issue_single(n, false);
      }
      return;
    }
    if (v.kind == Kind::Leaf) {
      if (f_ >= s.next_query) {
        if (plus) {
          v_queue_.push_back(n);  // R2: queried when there is nothing else to do
        } else {
          issue_single(n, true);
        }
      } else {
        ++stats_.queries_skipped;  // assumed visible until its next query
        pull_up(n);
      }
    }
    traverse(n);  // a visible leaf is drawn at once; a visible interior node is opened
  }

  // The node's query volume: its sphere, or with CHC++'s tight bounds (R6) its descendants'.
  void add_bounds(std::uint32_t n, std::vector<QueryBound>& out) const {
    if (s_.method == OcclusionMethod::ChcPlusPlus && s_.tight_bounds && cb_.bounds) {
      cb_.bounds(n, out);
    } else {
      out.push_back(h_.nodes[n].bound);
    }
  }

  QueryId issue(std::uint32_t n) {
    bounds_.clear();
    add_bounds(n, bounds_);
    ++stats_.queries_single;
    return q_.issue(bounds_);
  }

  void issue_single(std::uint32_t n, bool v_query) {
    if (v_query) ++stats_.v_queries;
    pending_.push_back({issue(n), {n}, v_query, {}});
  }

  // R1 + R4: the batch of previously invisible nodes, grouped by their chance of staying hidden.
  void issue_batch() {
    if (!s_.multiqueries) {
      for (const std::uint32_t n : i_queue_) issue_single(n, false);
      i_queue_.clear();
      return;
    }
    keyed_.clear();
    for (const std::uint32_t n : i_queue_) {
      keyed_.push_back({keep_probability(f_ - st_[n].hidden_since + 1), n});
    }
    std::sort(keyed_.begin(), keyed_.end(), [](const auto& a, const auto& b) {
      return a.first > b.first || (a.first == b.first && a.second < b.second);
    });
    keep_.clear();
    for (const auto& k : keyed_) keep_.push_back(k.first);
    std::size_t start = 0;
    group_.clear();
    for (const auto& k : keyed_) group_.push_back(k.second);
    for (const std::size_t size : multiquery_groups(keep_, s_.split_failed)) {
      issue_group(std::span<const std::uint32_t>(group_).subspan(start, size),
                  std::span<const double>(keep_).subspan(start, size));
      start += size;
    }
    i_queue_.clear();
  }

  // One query on previously invisible nodes: a single query, or a multiquery on several.
  void issue_group(std::span<const std::uint32_t> nodes, std::span<const double> keep) {
    if (nodes.size() == 1) {
      issue_single(nodes[0], false);
      return;
    }
    Pending p{0, {nodes.begin(), nodes.end()}, false, {keep.begin(), keep.end()}};
    bounds_.clear();
    for (const std::uint32_t n : nodes) add_bounds(n, bounds_);
    ++stats_.queries_multi;
    stats_.multiquery_nodes += nodes.size();
    p.id = q_.issue(bounds_);
    pending_.push_back(std::move(p));
  }

  void handle_front() {
    Pending p = std::move(pending_.front());
    pending_.pop_front();
    const bool visible = q_.result(p.id) > 0;
    if (!visible) {
      for (const std::uint32_t n : p.nodes) {
        if (!was_[n]) stats_.leaves_culled += h_.nodes[n].culling_leaves;
      }
      return;
    }
    if (p.nodes.size() > 1) {
      ++stats_.multiquery_failed;
      if (s_.split_failed && split_failed_group(p.keep)) {  // its two halves
        const std::span<const std::uint32_t> nodes(p.nodes);
        const std::span<const double> keep(p.keep);
        const std::size_t half = (nodes.size() + 1) / 2;
        issue_group(nodes.first(half), keep.first(half));
        issue_group(nodes.subspan(half), keep.subspan(half));
      } else {  // one query per node
        for (const std::uint32_t n : p.nodes) issue_single(n, false);
      }
      return;
    }
    const std::uint32_t n = p.nodes[0];
    CullState::Node& s = st_[n];
    if (!was_[n]) {
      traverse(n);
      s.next_query = f_ + (s_.randomized && s_.method == OcclusionMethod::ChcPlusPlus
                               ? random_offset(s_.seed, n, f_, s_.requery_frames)
                               : s_.requery_frames);
      s.still_visible = 0;
    } else {
      const unsigned doublings =
          s_.method == OcclusionMethod::ChcPlusPlus
              ? std::min<unsigned>(s.still_visible, s_.requery_doublings)
              : 0;
      s.next_query = f_ + (static_cast<std::uint64_t>(s_.requery_frames) << doublings);
      if (s.still_visible < 255) ++s.still_visible;
    }
    pull_up(n);
  }

  const CullHierarchy& h_;
  const CullCallbacks& cb_;
  const OcclusionSettings& s_;
  OcclusionQueries& q_;
  std::vector<CullState::Node>& st_;
  OcclusionStats& stats_;
  const std::uint64_t f_;
  std::vector<CullCallbacks::Visit>& visit_;
  std::vector<std::uint8_t>& was_;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> heap_;
  std::deque<Pending> pending_;
  std::vector<std::uint32_t> i_queue_;
  std::deque<std::uint32_t> v_queue_;
  std::vector<QueryBound> bounds_;
  std::vector<std::pair<double, std::uint32_t>> keyed_;
  std::vector<double> keep_;
  std::vector<std::uint32_t> group_;
};

}  // namespace

void cull_frame(const CullHierarchy& h, const CullCallbacks& callbacks,
                const OcclusionSettings& settings, OcclusionQueries& queries, CullState& state,
                OcclusionStats& stats) {
  if (h.nodes.empty()) return;
  if (state.nodes.size() != h.nodes.size()) state.nodes.assign(h.nodes.size(), {});
  ++state.frame;
  Culler(h, callbacks, settings, queries, state, stats).run();
}

}  // namespace pointillist
