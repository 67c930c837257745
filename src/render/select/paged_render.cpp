// The paged QSplat traversal over decoded or packed pages (see paged.hpp); the page cache and
// its loader are lod's PageCache.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <vector>

#include "pointillist/core/error.hpp"
#include "pointillist/render/paged.hpp"
#include "frame_timing.hpp"
#include "shading.hpp"
#include "select/traversal_common.hpp"

namespace pointillist {
namespace {

using namespace render_detail;

using PageTable = PageCache::PageTable;

// Where the children of a refined node are: nodes [first, first + child_count) of `page`, which
// may not be resident.
struct ChildRef {
  std::uint32_t page, first;
  bool resident;
};

// The traversal's view of decoded pages: nodes are used where they lie.
class DecodedAccess {
 public:
  static constexpr bool kPacked = false;
  struct Item {
    std::uint32_t page, node;
    std::uint8_t tests;
  };
  explicit DecodedAccess(const PageTable& pages) : pages_(pages) {}
  Item root(std::uint8_t tests) const { return {0, 0, tests}; }
  const SphereNode& node(const Item& p) const { return pages_[p.page]->nodes[p.node]; }
  ChildRef children(const Item& p, const SphereNode& n) const {
    const std::uint32_t cp = pages_[p.page]->child_page[p.node];
    if (cp == kNoPage) return {p.page, n.first_child, true};
    return {cp, n.first_child, pages_[cp] != nullptr};
  }
  // The children of `n`, which are at `c` (resident).
  const SphereNode* load_children(ChildRef c, const SphereNode&, SphereNode*) const {
    return pages_[c.page]->nodes.data() + c.first;
  }
  Item item(ChildRef c, std::uint32_t k, const SphereNode*, std::uint8_t tests) const {
    return {c.page, c.first + k, tests};
  }

 private:
  const PageTable& pages_;
};

// The traversal's view of packed pages: each node is decoded from its record against its
// decoded parent when the parent is refined, and travels by value.
class PackedAccess {
 public:
  static constexpr bool kPacked = true;
  struct Item {
    SphereNode node;
    std::uint32_t page, index;
    std::uint8_t tests;
  };
  PackedAccess(const PageTable& pages, bool has_colors)
      : pages_(pages), has_colors_(has_colors) {}
  Item root(std::uint8_t tests) const {
    const PackedPage& pk = pages_[0]->packed;
    Item root{{}, 0, 0, tests};
    decode(pk, 0, pk.root_parent, root.node);
    return root;
  }
  const SphereNode& node(const Item& p) const { return p.node; }
  ChildRef children(const Item& p, const SphereNode&) const {
    const PackedPage& pk = pages_[p.page]->packed;
    const std::uint32_t link = pk.link(p.index);
    if (p.index < pk.last_level_begin) return {p.page, link, true};
    const PageLink& l = pk.links[link];
    return {l.page, l.first, pages_[l.page] != nullptr};
  }
  const SphereNode* load_children(ChildRef c, const SphereNode& n, SphereNode* scratch) const {
    const PackedPage& pk = pages_[c.page]->packed;
    for (std::uint32_t k = 0; k < n.child_count; ++k) decode(pk, c.first + k, n, scratch[k]);
    return scratch;
  }
  Item item(ChildRef c, std::uint32_t k, const SphereNode* kids, std::uint8_t tests) const {
    return {kids[k], c.page, c.first + k, tests};
  }

 private:
  template <class Parent>
  void decode(const PackedPage& pk, std::uint32_t i, const Parent& parent, SphereNode& out) const {
    quant::decode_node_into(tables_, pk.records[i], has_colors_ ? pk.colors[i] : 0, has_colors_,
                            pk.leaf_trim, parent, out);
  }

  const PageTable& pages_;
  bool has_colors_;
  quant::DecodeTables tables_;
};

}  // namespace

struct PagedRenderer::Selection {
  const ViewConstants& v;
  std::uint8_t tests;  // tests of the root
  bool with_colors;
  SplatStream& stream;
  Counters counters;
};

void PagedRenderer::render(const Camera& camera, const RenderSettings& settings, ThreadPool& pool,
                           Frame& frame) {
  render_frame(camera, settings, nullptr, nullptr, pool, frame);
}

void PagedRenderer::render_quality(const Camera& camera, const RenderSettings& settings,
                                   const QualitySettings& quality, ThreadPool& pool, Frame& frame,
                                   QualityScratch& scratch) {
  validate_quality_settings(quality);
  render_frame(camera, settings, &quality, &scratch, pool, frame);
}

SelectionStats PagedRenderer::select(const CameraFrame& cam, const RenderSettings& settings,
                                    ThreadPool& pool, SplatStream& stream, bool same_frame) {
  if (!(settings.threshold_px > 0.0f) || !std::isfinite(settings.threshold_px)) {
    throw OptionError("splat size threshold " + std::to_string(settings.threshold_px) +
                      " px is invalid; give a positive number of pixels (1 draws every detail)");
  }
  if (!same_frame) cache_.begin_frame();
  const PageTable& pages = cache_.pages();
  const bool with_colors = summary_.has_colors;
  stream.has_colors = with_colors;
  stream.chunk_count = 0;
  const Shader shader(settings, cam);
  const ViewConstants v = make_view_constants(shader, cam, settings, stream.with_discs);
  Selection selection{
      v,
      static_cast<std::uint8_t>((settings.frustum_culling ? kTestFrustum : 0) |
                                (settings.backface_culling ? kTestBackface : 0)),
      with_colors, stream, {}};
  if (!pages.empty() && pages[0]) {
    if (pages[0]->is_packed()) {
      select_pages(PackedAccess(pages, with_colors), selection, pool);
    } else {
      select_pages(DecodedAccess(pages), selection, pool);
    }
  }
  cache_.end_frame();
  const Counters& counters = selection.counters;
  std::uint64_t splats = 0;
  for (std::size_t t = 0; t < stream.chunk_count; ++t) splats += stream.chunks[t].count;
  return {.splats = splats, .nodes_visited = counters.visited,
          .culled_frustum = counters.culled_frustum,
          .culled_backface = counters.culled_backface};
}

void PagedRenderer::render_frame(const Camera& camera, const RenderSettings& settings,
                                 const QualitySettings* quality, QualityScratch* scratch,
                                 ThreadPool& pool, Frame& frame) {
  const auto start = Clock::now();
  const CameraFrame cam = make_camera_frame(camera);
  size_frame(frame, cam);
  SplatStream& stream = frame.splats;
  stream.with_discs = quality != nullptr;
  const SelectionStats selection = select(cam, settings, pool, stream);
  const auto selected = Clock::now();
  if (quality) {
    rasterize_quality(stream, cam, settings, *quality, pool, *scratch, frame.color,
                      frame.depth);
  } else {
    rasterize_splats(stream, cam, settings, pool, frame.scratch, frame.color, frame.depth);
  }
  fill_stats(frame, selection, cam, pool.thread_count(), start, selected, Clock::now());
}

template <class Access>
void PagedRenderer::select_pages(const Access& access, Selection& s, ThreadPool& pool) {
  using Item = typename Access::Item;
  const ViewConstants& v = s.v;
  const bool with_colors = s.with_colors;
  SplatStream& stream = s.stream;
  Counters& counters = s.counters;

  // The top of the hierarchy expanded level by level (as the in-memory traversal does) into
  // subtrees walked in parallel, each into its own chunk; chunks in order give the depth-first
  // order whatever the thread count. A node is expanded here only when its children are
  // resident; anything else is left for its task to visit.
  std::vector<Item> items{access.root(s.tests)};
  std::vector<Item> next;
  SphereNode scratch[4];
  while (items.size() < kTargetTasks) {
    bool expanded = false;
    next.clear();
    for (const Item& p : items) {
      const SphereNode& n = access.node(p);
      Counters trial;
      Vec3f d;
      float z;
      std::uint8_t tests = p.tests;
      const Decision decision = visit(n, v, tests, trial, d, z);
      const ChildRef c = decision == Decision::Refine ? access.children(p, n) : ChildRef{};
      if (decision == Decision::Cull || (decision == Decision::Refine && c.resident)) {
        counters.visited += trial.visited;
        counters.culled_frustum += trial.culled_frustum;
        counters.culled_backface += trial.culled_backface;
        if (decision == Decision::Cull) continue;
        if (c.page != p.page) cache_.mark_used(c.page);
        const SphereNode* kids = access.load_children(c, n, scratch);
        for (std::uint32_t k = 0; k < n.child_count; ++k) {
          next.push_back(access.item(c, k, kids, tests));
        }
        expanded = true;
      } else {
        next.push_back(p);  // drawn, or a stand-in: its task visits it
      }
    }
    items.swap(next);
    if (!expanded) break;
  }

  if (stream.chunks.size() < items.size()) stream.chunks.resize(items.size());
  stream.chunk_count = items.size();
  if (task_out_.size() < items.size()) task_out_.resize(items.size());
  std::vector<Counters> task_counters(items.size());
  pool.run(items.size(), [&](std::size_t t) {
    TaskOut& out = task_out_[t];
    Counters task_count;  // local: the hot loop keeps it in registers
    out.emitted.clear();
    out.values.clear();
    out.stand_ins.clear();
    out.requests.clear();
    out.touched.clear();
    SplatChunk& chunk = stream.chunks[t];
    chunk.count = 0;
    chunk.reserve(kInitialChunkCapacity, with_colors);
    {
      Emitter emitter(chunk, with_colors);
      std::uint32_t emitted = 0;
      // A stand-in is drawn even when its mean normal faces away (its subtree may hold surfaces
      // facing the eye); it is then lit from the front, not drawn black.
      const auto emit = [&](const SphereNode& n, Vec3f d, float z, bool stand_in) {
        emitter.emit(n, emitted++, d, z, v, task_count, !stand_in);
        const bool flip = stand_in && dot(d, n.normal) > 0;
        if constexpr (Access::kPacked) {
          out.values.push_back(n);
          if (flip) out.values.back().normal = -n.normal;
        } else if (flip) {
          out.stand_ins.push_back(n);
          out.stand_ins.back().normal = -n.normal;
          out.emitted.push_back(&out.stand_ins.back());
        } else {
          out.emitted.push_back(&n);
        }
      };
      SphereNode kid_scratch[4];
      std::vector<Item> stack{items[t]};
      while (!stack.empty()) {
        const Item p = stack.back();
        stack.pop_back();
        const SphereNode& n = access.node(p);
        Vec3f d;
        float z;
        std::uint8_t tests = p.tests;
        const Decision decision = visit(n, v, tests, task_count, d, z);
        if (decision == Decision::Draw) emit(n, d, z, false);
        if (decision != Decision::Refine) continue;
        const ChildRef c = access.children(p, n);
        if (!c.resident) {
          // Not resident: this node stands in for its subtree, and the page is wanted.
          emit(n, d, z, true);
          out.requests.push_back({c.page, p.page, z > 0 ? n.radius / z : 0.0f});
          continue;
        }
        if (c.page != p.page) out.touched.push_back(c.page);
        // Leading leaf children are visited right here (most nodes near the bottom have only
        // leaves), in order; the rest go on the stack last to first.
        const SphereNode* kids = access.load_children(c, n, kid_scratch);
        std::uint32_t k = 0;
        for (; k < n.child_count && kids[k].child_count == 0; ++k) {
          std::uint8_t leaf_tests = tests;
          if (visit(kids[k], v, leaf_tests, task_count, d, z) == Decision::Draw) {
            emit(kids[k], d, z, false);
          }
        }
        for (std::uint32_t j = n.child_count; j-- > k;) {
          stack.push_back(access.item(c, j, kids, tests));
        }
      }
    }
    if constexpr (Access::kPacked) {
      finish_chunk([&](std::uint32_t i) -> const SphereNode& { return out.values[i]; }, v,
                   with_colors, chunk);
    } else {
      finish_chunk([&](std::uint32_t i) -> const SphereNode& { return *out.emitted[i]; }, v,
                   with_colors, chunk);
    }
    task_counters[t] = task_count;
  });
  for (std::size_t t = 0; t < items.size(); ++t) {
    const TaskOut& out = task_out_[t];
    counters.visited += task_counters[t].visited;
    counters.culled_frustum += task_counters[t].culled_frustum;
    counters.culled_backface += task_counters[t].culled_backface;
    for (const std::uint32_t page : out.touched) cache_.mark_used(page);
    for (const PageRequest& r : out.requests) cache_.request(r);
  }
}

}  // namespace pointillist
