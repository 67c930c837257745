// The paged QSplat traversal over decoded or packed pages (see paged.hpp); the page cache and
// its loader are lod's PageCache.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <string>
#include <vector>

#include "pointillist/core/error.hpp"
#include "pointillist/render/paged.hpp"
#include "frame_pass.hpp"
#include "shading.hpp"
#include "select/qsplat_traversal.hpp"
#include "select/stream_features.hpp"

namespace pointillist {
namespace {

using namespace render_detail;

using PageTable = PageCache::PageTable;

struct PageRecord {
  std::uint32_t page, index;
};

// The chunk's surface ids and clip planes (model space, the model's own ids) from the features
// of the pages its splats' nodes lie in; `where` is indexed by the splats' node ids.
void fill_page_features(const PageTable& pages, const std::vector<PageRecord>& where,
                        SplatChunk& chunk) {
  fill_features(chunk, [&](std::size_t i, std::uint32_t& surface, ClipMode& mode) {
    const PageRecord w = where[chunk.node[i]];
    const PageFeatures& f = pages[w.page]->features;
    if (f.empty()) {
      surface = kMixedSurface;
      mode = ClipMode::None;
      return std::span<const ClipPlane>{};
    }
    surface = f.surface[w.index];
    return f.planes_of(w.index, mode);
  });
}

// The traversal's view of decoded pages: nodes are used where they lie; a splat's node id is the
// index of its node's address in the task's list (a stand-in lit from the front is a copy).
class DecodedAccess {
 public:
  static constexpr bool kPaged = true;
  struct Item {
    std::uint32_t page, node;
    std::uint8_t tests;
  };
  struct Kept {
    std::vector<const SphereNode*> emitted;
    std::deque<SphereNode> flipped;
    std::vector<PageRecord> where;  // with features: the page and index of each
  };
  DecodedAccess(const PageTable& pages, bool features) : pages_(pages), features_(features) {}
  Item root(std::uint8_t tests) const { return {0, 0, tests}; }
  const SphereNode& node(const Item& p) const { return pages_[p.page]->nodes[p.node]; }
  std::uint32_t page(const Item& p) const { return p.page; }
  std::uint32_t index(const Item& p) const { return p.node; }
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
  std::uint32_t keep(Kept& kept, const SphereNode& n, bool flip, std::uint32_t page,
                     std::uint32_t index) const {
    if (flip) {
      kept.flipped.push_back(n);
      kept.flipped.back().normal = -n.normal;
      kept.emitted.push_back(&kept.flipped.back());
    } else {
      kept.emitted.push_back(&n);
    }
    if (features_) kept.where.push_back({page, index});
    return static_cast<std::uint32_t>(kept.emitted.size() - 1);
  }
  const SphereNode& kept(const Kept& kept, std::uint32_t id) const { return *kept.emitted[id]; }
  static void clear(Kept& kept) {
    kept.emitted.clear();
    kept.flipped.clear();
    kept.where.clear();
  }
  void finish(const Kept& kept, SplatChunk& chunk) const {
    if (features_) fill_page_features(pages_, kept.where, chunk);
  }

 private:
  const PageTable& pages_;
  bool features_;
};

// The traversal's view of packed pages: each node is decoded from its record against its
// decoded parent when the parent is refined, and travels by value; a splat keeps a copy.
class PackedAccess {
 public:
  static constexpr bool kPaged = true;
  struct Item {
    SphereNode node;
    std::uint32_t page, index;
    std::uint8_t tests;
  };
  struct Kept {
    std::vector<SphereNode> nodes;
    std::vector<PageRecord> where;  // with features: the page and index of each
  };
  PackedAccess(const PageTable& pages, bool has_colors, bool features)
      : pages_(pages), has_colors_(has_colors), features_(features) {}
  Item root(std::uint8_t tests) const {
    const PackedPage& pk = pages_[0]->packed;
    Item root{{}, 0, 0, tests};
    decode(pk, 0, pk.root_parent, root.node);
    return root;
  }
  const SphereNode& node(const Item& p) const { return p.node; }
  std::uint32_t page(const Item& p) const { return p.page; }
  std::uint32_t index(const Item& p) const { return p.index; }
  ChildRef children(const Item& p, const SphereNode&) const {
    const PackedPage& pk = pages_[p.page]->packed;
    const std::uint32_t link = pk.link(p.index);
    // In this page (not loaded yet when the page is resident in part), or in a child page.
    if (p.index < pk.last_level_begin) return {p.page, link, link < pk.records.size()};
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
  std::uint32_t keep(Kept& kept, const SphereNode& n, bool flip, std::uint32_t page,
                     std::uint32_t index) const {
    kept.nodes.push_back(n);
    if (flip) kept.nodes.back().normal = -n.normal;
    if (features_) kept.where.push_back({page, index});
    return static_cast<std::uint32_t>(kept.nodes.size() - 1);
  }
  const SphereNode& kept(const Kept& kept, std::uint32_t id) const { return kept.nodes[id]; }
  static void clear(Kept& kept) {
    kept.nodes.clear();
    kept.where.clear();
  }
  void finish(const Kept& kept, SplatChunk& chunk) const {
    if (features_) fill_page_features(pages_, kept.where, chunk);
  }

 private:
  template <class Parent>
  void decode(const PackedPage& pk, std::uint32_t i, const Parent& parent, SphereNode& out) const {
    quant::decode_node_into(tables_, pk.records[i], has_colors_ ? pk.colors[i] : 0, has_colors_,
                            pk.leaf_trim, parent, out);
  }

  const PageTable& pages_;
  bool has_colors_;
  bool features_;
  quant::DecodeTables tables_;
};

}  // namespace

struct PagedRenderer::Tasks {
  std::vector<TaskState<DecodedAccess>> decoded;
  std::vector<TaskState<PackedAccess>> packed;
};

PagedRenderer::PagedRenderer(const PageSource& source, std::uint64_t memory_cap, ThreadPool& pool)
    : cache_(source, memory_cap, pool), summary_(source.summary()),
      tasks_(std::make_unique<Tasks>()) {}
PagedRenderer::~PagedRenderer() = default;

struct PagedRenderer::Selection {
  const ViewConstants& v;
  std::uint8_t tests;  // tests of the root
  bool with_colors;
  std::uint64_t expected;  // splats, for sizing new chunks
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
                                    ThreadPool& pool, SplatStream& stream, bool same_frame,
                                    bool features, const SubtreeOcclusion* occlusion) {
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
  ViewConstants v = make_view_constants(shader, cam, settings, stream.with_discs);
  v.occlusion = occlusion;
  Selection selection{
      v,
      static_cast<std::uint8_t>((settings.frustum_culling ? kTestFrustum : 0) |
                                (settings.culls_backfaces() ? kTestBackface : 0)),
      with_colors, 0, stream, {}};
  // Splats expected, for sizing new chunks: at most what the model's sphere covers on screen (an
  // instance far away draws few; sizing each of thousands of instances for the whole model
  // took gigabytes).
  const Sphere root = root_sphere();
  selection.expected =
      expected_splats(summary_.leaf_count, cam, &root, settings.threshold_px);
  if (!pages.empty() && pages[0]) {
    if (pages[0]->is_packed()) {
      select_pages(PackedAccess(pages, with_colors, features), selection, pool, tasks_->packed);
    } else {
      select_pages(DecodedAccess(pages, features), selection, pool, tasks_->decoded);
    }
  }
  cache_.end_frame();
  const Counters& counters = selection.counters;
  std::uint64_t splats = 0;
  for (std::size_t t = 0; t < stream.chunk_count; ++t) splats += stream.chunks[t].count;
  return {.splats = splats, .nodes_visited = counters.visited,
          .culled_frustum = counters.culled_frustum,
          .culled_backface = counters.culled_backface,
          .culled_occluded = counters.culled_occluded};
}

void PagedRenderer::begin_frame() {
  cache_.begin_frame();
  cache_.end_frame();
}

Sphere PagedRenderer::root_sphere() const {
  if (root_) return *root_;
  const PageTable& pages = cache_.pages();
  // Page 0 stays resident (begin_frame keeps it in use); a sphere holding anything otherwise.
  if (pages.empty() || !pages[0]) return {summary_.view_sphere.center, 1e30f};
  if (!pages[0]->is_packed()) {
    root_ = Sphere{pages[0]->nodes[0].center, pages[0]->nodes[0].radius};
  } else {
    const SphereNode root = PackedAccess(pages, summary_.has_colors, false).root(0).node;
    root_ = Sphere{root.center, root.radius};
  }
  return *root_;
}

void PagedRenderer::render_frame(const Camera& camera, const RenderSettings& settings,
                                 const QualitySettings* quality, QualityScratch* scratch,
                                 ThreadPool& pool, Frame& frame) {
  render_detail::frame_pass(camera, settings, quality, scratch, pool, frame,
                            [&](const CameraFrame& cam, SplatStream& stream) {
                              return select(cam, settings, pool, stream);
                            });
}

template <class Access, class TaskStates>
void PagedRenderer::select_pages(const Access& access, Selection& s, ThreadPool& pool,
                                 TaskStates& tasks) {
  std::vector<std::uint32_t> top_pages;
  select_qsplat(access, s.v, s.tests, s.with_colors, s.expected, pool, s.stream, tasks,
                s.counters, top_pages);
  for (const std::uint32_t page : top_pages) cache_.mark_used(page);
  for (std::size_t t = 0; t < s.stream.chunk_count; ++t) {
    const auto& out = tasks[t];
    s.counters.visited += out.counters.visited;
    s.counters.culled_frustum += out.counters.culled_frustum;
    s.counters.culled_backface += out.counters.culled_backface;
    s.counters.culled_occluded += out.counters.culled_occluded;
    for (const std::uint32_t page : out.touched) cache_.mark_used(page);
    for (const PageRequest& r : out.requests) cache_.request(r);
  }
}

}  // namespace pointillist
