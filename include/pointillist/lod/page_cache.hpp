// The resident pages of a paged hierarchy (pages.hpp): what a traversal may read, what it asked
// for, loads on a thread pool or on a background loader thread, and least-recently-used eviction
// under a cap on resident memory. A traversal reads pages() during a frame and reports the
// pages it used (mark_used) and the ones it wanted (request); between frames the requested pages
// are loaded, coarsest (largest on screen) first.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "pointillist/core/thread_pool.hpp"
#include "pointillist/lod/pages.hpp"

namespace pointillist {

struct PageCacheStats {
  std::uint64_t pages_requested = 0;  // distinct non-resident pages the last frame wanted
  std::uint64_t bytes_read = 0;       // storage bytes read so far (open_bytes + loaded pages)
  std::uint64_t resident_bytes = 0;   // memory of the resident pages now
  std::uint64_t resident_bytes_peak = 0;
  std::uint64_t resident_pages = 0;
  // Storage bytes of the resident pages read whole (what loading them whole would have read;
  // they may be resident in part, see pages.hpp).
  std::uint64_t resident_page_bytes = 0;
  std::uint64_t pages_loaded = 0;     // loads so far (a page dropped and loaded again counts twice)
  std::uint64_t pages_deepened = 0;   // loads of more levels of a page resident in part
  std::uint64_t pages_evicted = 0;
};

// A page a traversal wants: the page holding the children of a node drawn as a stand-in. The
// page may be resident with only its first levels (pages.hpp): it is then deepened.
struct PageRequest {
  std::uint32_t page;
  std::uint32_t parent_page;  // the page holding that node
  float priority;             // the node's projected radius (r / z): larger loads first
  std::uint32_t first = 0;    // the record of `page` holding the node's first child
  // Levels below the children's that the view will want too (from the node's size on screen).
  std::uint32_t extra_levels = 0;
};

// Not thread-safe, except that the loader thread works on its own; one frame at a time.
class PageCache {
 public:
  using PageTable = std::vector<std::unique_ptr<HierarchyPage>>;

  // Loads page 0. Throws OptionError when page 0 alone needs more than `memory_cap` bytes (the
  // message gives the size needed), and what the source throws. The source must outlive the
  // cache.
  PageCache(const PageSource& source, std::uint64_t memory_cap, ThreadPool& pool);
  ~PageCache();  // stops the loader thread, if one was started
  PageCache(const PageCache&) = delete;
  PageCache& operator=(const PageCache&) = delete;

  // Starts a frame: takes in the pages the loader has finished (rethrowing what loading threw),
  // forgets the last frame's requests and marks page 0 used.
  void begin_frame();
  // Ends a frame: its requests are what load_requested / request_in_background will load.
  void end_frame() { stats_.pages_requested = requests_.size(); }
  // Resident pages (null where not resident), indexed by page number.
  const PageTable& pages() const { return pages_; }
  // The frame used `page` (resident): it is evicted last.
  void mark_used(std::uint32_t page) { last_used_[page] = frame_number_; }
  // The frame wants `r.page` (not resident, or resident without record r.first); a page on its
  // way is ignored, one already requested keeps the largest priority and record.
  void request(const PageRequest& r) {
    if (in_flight_[r.page]) return;
    if (const std::uint32_t k = requested_[r.page]) {
      PageRequest& q = requests_[k - 1];
      q.priority = std::max(q.priority, r.priority);
      q.first = std::max(q.first, r.first);
      q.extra_levels = std::max(q.extra_levels, r.extra_levels);
      return;
    }
    requests_.push_back(r);
    requested_[r.page] = static_cast<std::uint32_t>(requests_.size());
  }

  // A page is loaded (and deepened, reading only what it lacks) by whole levels: through the
  // children asked for and the levels the view will want below them, and at least this many
  // records (the first levels of a page are small). A view whose detail ends in a page's first
  // levels reads no more of it. Page 0 is loaded whole.
  static constexpr std::uint32_t kMinLoadNodes = 256;

  // Loads the pages the last frame requested, largest on screen first, at most `max_pages` of
  // them and at most `max_storage_bytes` read (at least one page is always loaded when one
  // fits in memory, however large), in parallel on `pool`: each from its first level down to
  // the levels asked for (see kMinLoadNodes; all of page 0). A page is loaded only
  // when the whole of it fits under the cap after evicting pages the last frame did not use
  // (least recently used first; only pages without resident child pages, never page 0); what it
  // takes short of that is given back once loaded. Returns the number of pages loaded.
  std::size_t load_requested(ThreadPool& pool, std::size_t max_pages = SIZE_MAX,
                             std::uint64_t max_storage_bytes = UINT64_MAX);
  // Background loading, as an interactive viewer does it: hands the pages the last frame
  // requested (chosen as load_requested chooses them, their memory reserved under the cap) to a
  // loader thread, which decodes them while the next frames render; begin_frame() takes in the
  // pages that are ready. A page on its way is not requested again. Returns the number of pages
  // handed over. Frames then depend on timing; load_requested() does not.
  std::size_t request_in_background(std::size_t max_pages = SIZE_MAX,
                                    std::uint64_t max_storage_bytes = UINT64_MAX);
  // Waits until the loader has decoded every page handed to it (they are taken in by the next
  // begin_frame()). Rethrows what loading a page threw.
  void wait_for_loader();

  // True when the last frame requested nothing and no page is on its way: what is resident is
  // all that view needs.
  bool complete() const { return stats_.pages_requested == 0 && in_flight_count_ == 0; }
  // True while pages handed to the loader have not been taken in by a begin_frame().
  bool loading() const { return in_flight_count_ > 0; }
  const PageCacheStats& stats() const { return stats_; }
  const PageSource& source() const { return source_; }
  std::uint64_t memory_cap() const { return cap_; }

 private:
  // Evicts least recently used pages until `bytes` more fit under the cap; false when not
  // enough can be (pages used this frame, with resident child pages, on their way, and page 0
  // stay).
  bool make_room(std::uint64_t bytes);
  bool evictable(std::uint32_t page) const;
  // What to load of a requested page.
  static PagePrefix load_prefix(const PageRequest& r) {
    if (r.page == 0) return {};
    return {.node = r.first, .extra_levels = r.extra_levels, .min_nodes = kMinLoadNodes};
  }
  // Chooses requests to load (see load_requested), reserving their memory; clears requests_.
  std::vector<PageRequest> choose(std::size_t max_pages, std::uint64_t max_storage_bytes);
  // A page to load `page` into: empty, or a copy of what is resident of it (continued).
  std::unique_ptr<HierarchyPage> start_page(std::uint32_t page) const;
  // Makes a loaded page resident (its memory was reserved by choose).
  void adopt(const PageRequest& r, std::unique_ptr<HierarchyPage> page);
  void take_ready();
  void loader_loop();
  struct Loader;

  const PageSource& source_;
  std::uint64_t cap_;
  PageTable pages_;                              // resident pages, null elsewhere
  std::vector<std::uint32_t> parent_;            // parent page of each resident page
  std::vector<std::uint32_t> resident_children_;  // resident child pages of each page
  std::vector<std::uint64_t> last_used_;         // frame number of the last use
  std::vector<std::uint64_t> memory_;            // memory of each resident page (0 elsewhere)
  std::vector<std::uint64_t> reserved_;          // memory reserved for a page being loaded
  std::vector<PageRequest> requests_;
  std::vector<std::uint32_t> requested_;         // per page: 1 + its index in requests_, or 0
  std::vector<std::uint8_t> in_flight_;          // per page: handed to the loader
  // Eviction candidates of the current choice, a heap by (last use, page); see make_room.
  std::vector<std::pair<std::uint64_t, std::uint32_t>> victims_;
  bool victims_ready_ = false;
  std::size_t in_flight_count_ = 0;
  std::uint64_t frame_number_ = 0;
  PageCacheStats stats_;
  std::unique_ptr<Loader> loader_;
};

}  // namespace pointillist
