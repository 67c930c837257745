// Out-of-core and progressive rendering: a hierarchy stored as pages that are loaded on demand,
// as QSplat streams a model in (Rusinkiewicz & Levoy 2000, section 4.3). The traversal draws
// from the pages that are resident; where a node's children are in a page that is not, it draws
// the node as a splat and requests the page. Between frames the requested pages are loaded
// (coarsest first), within a cap on resident memory.
#pragma once

#include <cstdint>
#include <deque>
#include <memory>
#include <vector>

#include "pointillist/core/camera.hpp"
#include "pointillist/core/thread_pool.hpp"
#include "pointillist/lod/quantization.hpp"
#include "pointillist/lod/sphere_tree.hpp"
#include "pointillist/render/quality.hpp"
#include "pointillist/render/render.hpp"

namespace pointillist {

inline constexpr std::uint32_t kNoPage = 0xffffffffu;

// Where the children of a node are when another page holds them: nodes [first, first +
// child_count) of page `page`.
struct PageLink {
  std::uint32_t page = kNoPage;
  std::uint32_t first = 0;
};

// A page kept in the packed form of a quantized model file (lod/quantization.hpp) and decoded
// during the traversal, each node against its decoded parent: 4 bytes a node (6 with colour)
// and about 1.06 bytes of links, where decoded nodes take 44.
struct PackedPage {
  static constexpr unsigned kBlockShift = 6;  // links are stored as 64-node blocks
  std::vector<std::uint32_t> records;  // packed node records, breadth-first over the page
  std::vector<std::uint16_t> colors;   // RGB 565, one per record, when the model has colours
  // Records [0, last_level_begin) have their children (if any) in this page; the interior
  // records of the last level have theirs in child pages, links[k] for the k-th of them.
  std::uint32_t last_level_begin = 0;
  std::vector<PageLink> links;
  // Page 0: the sphere its first record (the root) decodes against.
  Sphere root_parent;
  quant::LeafTrim leaf_trim = quant::LeafTrim::Eighths;
  // link(i) for an interior record i: its first child's index in this page (i <
  // last_level_begin: the first level's size plus the children of the records before it, by
  // breadth-first order), or its index in `links` (i >= last_level_begin). Stored as a 32-bit
  // base per block of 64 records (blocks start afresh at last_level_begin) plus an 8-bit step
  // per record: within a block the value grows by at most 4 a record.
  std::vector<std::uint32_t> link_base;
  std::vector<std::uint8_t> link_step;

  std::uint32_t link(std::uint32_t i) const {
    const std::uint32_t block =
        i < last_level_begin ? i >> kBlockShift
                             : first_last_level_block() + ((i - last_level_begin) >> kBlockShift);
    return link_base[block] + link_step[i];
  }
  std::uint32_t first_last_level_block() const {
    return (last_level_begin + (1u << kBlockShift) - 1) >> kBlockShift;
  }
  // Fills link_base and link_step from the records, last_level_begin and the number of records
  // in the page's first level (the children of its roots).
  void index_links(std::uint32_t first_level_count);

  // Bytes of memory a packed page of `node_count` nodes and `link_count` links takes.
  static std::uint64_t memory_bytes(std::uint64_t node_count, std::uint64_t link_count,
                                    bool has_colors) {
    return node_count * (sizeof(std::uint32_t) + (has_colors ? sizeof(std::uint16_t) : 0) +
                         sizeof(std::uint8_t)) +
           ((node_count >> kBlockShift) + 2) * sizeof(std::uint32_t) +
           link_count * sizeof(PageLink);
  }
};

// One page: a connected part of the hierarchy. Page 0 holds the root and the levels below it;
// any other page holds the children of one or more nodes of another page (its anchors), then
// their descendants.
//
// Decoded form (`nodes` not empty): a node's children are nodes[first_child .. first_child +
// child_count) of its own page when child_page[i] is kNoPage, and of page child_page[i]
// otherwise. Packed form (`nodes` empty): see PackedPage.
struct HierarchyPage {
  std::vector<SphereNode> nodes;
  std::vector<std::uint32_t> child_page;  // one per node; kNoPage: children (if any) are here
  PackedPage packed;

  bool is_packed() const { return nodes.empty(); }
  std::uint32_t node_count() const {
    return static_cast<std::uint32_t>(is_packed() ? packed.records.size() : nodes.size());
  }
  // What a decoded page of `node_count` nodes costs in memory while it is resident.
  static std::uint64_t memory_bytes(std::uint64_t node_count) {
    return node_count * (sizeof(SphereNode) + sizeof(std::uint32_t));
  }
  // What this page costs in memory while it is resident.
  std::uint64_t memory_bytes() const {
    return is_packed() ? PackedPage::memory_bytes(packed.records.size(), packed.links.size(),
                                                  !packed.colors.empty())
                       : memory_bytes(nodes.size());
  }
};

// Where pages come from: a paged model file, or (tests) an in-memory hierarchy cut into pages.
class PageSource {
 public:
  virtual ~PageSource() = default;
  virtual std::uint32_t page_count() const = 0;
  // Bytes read from storage to load the page.
  virtual std::uint64_t page_storage_bytes(std::uint32_t page) const = 0;
  // Nodes in the page.
  virtual std::uint32_t page_node_count(std::uint32_t page) const = 0;
  // Memory the loaded page takes while resident (HierarchyPage::memory_bytes()).
  virtual std::uint64_t page_memory_bytes(std::uint32_t page) const = 0;
  // Bytes read to open the model (header, page table), before any page.
  virtual std::uint64_t open_bytes() const = 0;
  // Counts and boxes of the whole model (nodes stays empty): leaf_count, depth, bounds,
  // view_sphere (for the camera) and has_colors.
  virtual SphereTreeView summary() const = 0;
  // Loads page `page` into `out`, decoded or packed (every page of a source in the same form).
  // Safe to call concurrently for different pages. Throws FormatError or IoError.
  virtual void load(std::uint32_t page, HierarchyPage& out) const = 0;
};

// `tree` cut into pages: page 0 takes the root and then whole sibling groups breadth-first while
// it stays within `page_bytes` (at 40 bytes a node, the .ptl v1 node size); each node whose
// children do not fit starts a new page, filled the same way but with at most `max_levels`
// levels. Shallow pages make a model stream in coarse to fine everywhere rather than region by
// region; a full first page makes the first frame a good one. The
// pages are copies; summary() keeps `tree`'s bounds and counts. Throws OptionError when
// page_bytes cannot hold a node and 4 children (200 bytes) or max_levels is 0.
std::unique_ptr<PageSource> paginate(const SphereTreeView& tree, std::uint64_t page_bytes,
                                     std::uint32_t max_levels = 64);

struct PagedRenderStats {
  std::uint64_t pages_requested = 0;  // distinct non-resident pages the last frame wanted
  std::uint64_t bytes_read = 0;       // storage bytes read so far (open_bytes + loaded pages)
  std::uint64_t resident_bytes = 0;   // memory of the resident pages now
  std::uint64_t resident_bytes_peak = 0;
  std::uint64_t resident_pages = 0;
  std::uint64_t pages_loaded = 0;     // loads so far (a page dropped and loaded again counts twice)
  std::uint64_t pages_evicted = 0;
};

// Renders a paged model. Not thread-safe: one frame at a time; the pool parallelises page loads
// and rasterization, and an optional loader thread decodes pages in the background.
class PagedRenderer {
 public:
  // Loads page 0. Throws OptionError when page 0 alone needs more than `memory_cap` bytes (the
  // message gives the size needed), and what the source throws.
  PagedRenderer(const PageSource& source, std::uint64_t memory_cap, ThreadPool& pool);
  ~PagedRenderer();  // stops the loader thread, if one was started
  PagedRenderer(const PagedRenderer&) = delete;
  PagedRenderer& operator=(const PagedRenderer&) = delete;

  // The QSplat traversal of render() (same tests, threshold and culling, same splats where the
  // pages are resident) over the resident pages. A node whose children are in a page that is
  // not resident is drawn as a splat whatever its size, and the page is requested. Selection
  // and rasterization run on the pool; the image does not depend on the thread count.
  void render(const Camera& camera, const RenderSettings& settings, ThreadPool& pool,
              Frame& frame);
  // The same selection drawn by the quality rasterizer (rasterize_quality: Gaussian surface
  // splatting, per-pixel shading), so models larger than memory render in the quality mode too.
  // With every page the view needs resident, the image is render_quality's on the whole
  // hierarchy. Throws OptionError for invalid settings.
  void render_quality(const Camera& camera, const RenderSettings& settings,
                      const QualitySettings& quality, ThreadPool& pool, Frame& frame,
                      QualityScratch& scratch);

  // Loads the pages the last render requested, largest on screen first, at most `max_pages` of
  // them and at most `max_storage_bytes` read (at least one page is always loaded when one
  // fits in memory, however large), in parallel on `pool`. A page is loaded only when it fits under
  // the cap after evicting pages the last frame did not use (least recently used first; only
  // pages without resident child pages, never page 0). Returns the number of pages loaded.
  std::size_t load_requested(ThreadPool& pool, std::size_t max_pages = SIZE_MAX,
                             std::uint64_t max_storage_bytes = UINT64_MAX);

  // Background loading, as an interactive viewer does it: hands the pages the last render
  // requested (chosen as load_requested chooses them, their memory reserved under the cap) to
  // a loader thread, which decodes them while the next frames render; every render() first
  // takes in the pages that are ready. A page on its way is not requested again. Returns the
  // number of pages handed over. Frames then depend on timing; load_requested() does not.
  std::size_t request_in_background(std::size_t max_pages = SIZE_MAX,
                                    std::uint64_t max_storage_bytes = UINT64_MAX);
  // Waits until the loader has decoded every page handed to it (they are taken in by the next
  // render()). Rethrows what loading a page threw.
  void wait_for_loader();

  // True when the last frame requested nothing and no page is on its way: what is resident is
  // all that view needs.
  bool complete() const { return stats_.pages_requested == 0 && in_flight_count_ == 0; }
  const PagedRenderStats& stats() const { return stats_; }
  // Counts and boxes of the model (PageSource::summary), for the camera.
  const SphereTreeView& summary() const { return summary_; }

 private:
  struct Request {
    std::uint32_t page;
    std::uint32_t parent_page;
    float priority;  // the projected radius of the node standing in for it: larger first
  };
  void render_frame(const Camera& camera, const RenderSettings& settings,
                    const QualitySettings* quality, QualityScratch* scratch, ThreadPool& pool,
                    Frame& frame);
  struct Selection;
  // The traversal over decoded or packed pages (Access: see paged_render.cpp).
  template <class Access>
  void select(const Access& access, Selection& selection, ThreadPool& pool);
  bool make_room(std::uint64_t bytes);
  // Chooses requests to load (see load_requested), reserving their memory; clears requests_.
  std::vector<Request> choose(std::size_t max_pages, std::uint64_t max_storage_bytes);
  // Makes a loaded page resident (its memory was reserved by choose).
  void adopt(const Request& r, std::unique_ptr<HierarchyPage> page);
  void take_ready();
  void loader_loop();
  struct Loader;

  const PageSource& source_;
  std::uint64_t cap_;
  SphereTreeView summary_;
  std::vector<std::unique_ptr<HierarchyPage>> pages_;  // resident pages, null elsewhere
  std::vector<std::uint32_t> parent_;                  // parent page of each resident page
  std::vector<std::uint32_t> resident_children_;       // resident child pages of each page
  std::vector<std::uint64_t> last_used_;               // frame number of the last use
  std::vector<Request> requests_;
  std::vector<std::uint8_t> requested_;                // per page: already in requests_
  // What each selection task produced in the last frame.
  struct TaskOut {
    std::vector<const SphereNode*> emitted;  // the nodes of its splats, in its chunk's order
    std::vector<SphereNode> values;          // the same for packed pages: decoded copies
    std::deque<SphereNode> stand_ins;        // copies of stand-ins lit from the front
    std::vector<Request> requests;     // pages it wanted, in traversal order
    std::vector<std::uint32_t> touched;  // resident pages it used below the top
  };
  std::vector<TaskOut> task_out_;
  std::vector<SphereNode> gathered_;  // quality mode: the last frame's nodes in stream order
  std::vector<std::uint8_t> in_flight_;                // per page: handed to the loader
  std::size_t in_flight_count_ = 0;
  std::uint64_t frame_number_ = 0;
  PagedRenderStats stats_;
  std::unique_ptr<Loader> loader_;
};

}  // namespace pointillist
