// The page cache: residency under the memory cap, least recently used eviction, synchronous
// loads on the pool and the background loader thread (see page_cache.hpp).
#include <algorithm>
#include <condition_variable>
#include <deque>
#include <exception>
#include <mutex>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "pointillist/core/error.hpp"
#include "pointillist/lod/page_cache.hpp"

namespace pointillist {

struct PageCache::Loader {
  std::mutex mutex;
  std::condition_variable wake, idle;
  // Handed over, not yet decoded: each with what is resident of the page (a copy), continued.
  std::deque<std::pair<PageRequest, std::unique_ptr<HierarchyPage>>> queue;
  std::vector<std::pair<PageRequest, std::unique_ptr<HierarchyPage>>> ready;
  std::exception_ptr error;
  std::size_t busy = 0;  // pages being decoded now
  bool stopping = false;
  std::thread thread;
};

PageCache::~PageCache() {
  if (!loader_) return;
  {
    std::lock_guard<std::mutex> lock(loader_->mutex);
    loader_->stopping = true;
  }
  loader_->wake.notify_all();
  loader_->thread.join();
}

void PageCache::loader_loop() {
  Loader& l = *loader_;
  std::unique_lock<std::mutex> lock(l.mutex);
  for (;;) {
    l.wake.wait(lock, [&] { return l.stopping || !l.queue.empty(); });
    if (l.stopping) return;
    const PageRequest r = l.queue.front().first;
    std::unique_ptr<HierarchyPage> page = std::move(l.queue.front().second);
    l.queue.pop_front();
    ++l.busy;
    lock.unlock();
    std::exception_ptr error;
    try {
      source_.load(r.page, *page, load_prefix(r));
    } catch (...) {
      error = std::current_exception();
    }
    lock.lock();
    --l.busy;
    if (error) {
      if (!l.error) l.error = error;
    } else {
      l.ready.emplace_back(r, std::move(page));
    }
    if (l.queue.empty() && l.busy == 0) l.idle.notify_all();
  }
}

std::size_t PageCache::request_in_background(std::size_t max_pages,
                                                 std::uint64_t max_storage_bytes) {
  std::vector<PageRequest> chosen = choose(max_pages, max_storage_bytes);
  if (chosen.empty()) return 0;
  if (!loader_) {
    loader_ = std::make_unique<Loader>();
    loader_->thread = std::thread([this] { loader_loop(); });
  }
  {
    std::lock_guard<std::mutex> lock(loader_->mutex);
    for (const PageRequest& r : chosen) {
      in_flight_[r.page] = 1;
      loader_->queue.emplace_back(r, start_page(r.page));
    }
    in_flight_count_ += chosen.size();
  }
  loader_->wake.notify_all();
  return chosen.size();
}

void PageCache::wait_for_loader() {
  if (!loader_) return;
  std::unique_lock<std::mutex> lock(loader_->mutex);
  loader_->idle.wait(lock, [&] { return loader_->queue.empty() && loader_->busy == 0; });
  if (loader_->error) std::rethrow_exception(loader_->error);
}

void PageCache::begin_frame() {
  take_ready();
  ++frame_number_;
  for (const PageRequest& r : requests_) requested_[r.page] = 0;
  requests_.clear();
  if (!pages_.empty() && pages_[0]) last_used_[0] = frame_number_;
}

void PageCache::take_ready() {
  if (!loader_) return;
  std::vector<std::pair<PageRequest, std::unique_ptr<HierarchyPage>>> ready;
  {
    std::lock_guard<std::mutex> lock(loader_->mutex);
    if (loader_->error) std::rethrow_exception(loader_->error);
    ready.swap(loader_->ready);
  }
  for (auto& [r, page] : ready) {
    in_flight_[r.page] = 0;
    --in_flight_count_;
    adopt(r, std::move(page));
  }
  stats_.resident_bytes_peak = std::max(stats_.resident_bytes_peak, stats_.resident_bytes);
}

PageCache::PageCache(const PageSource& source, std::uint64_t memory_cap, ThreadPool& pool)
    : source_(source), cap_(memory_cap) {
  const std::uint32_t n = source.page_count();
  pages_.resize(n);
  parent_.assign(n, kNoPage);
  resident_children_.assign(n, 0);
  last_used_.assign(n, 0);
  memory_.assign(n, 0);
  reserved_.assign(n, 0);
  requested_.assign(n, 0);
  in_flight_.assign(n, 0);
  stats_.bytes_read = source.open_bytes();
  if (n == 0) return;
  const std::uint64_t first = source.page_memory_bytes(0);
  if (first > cap_) {
    throw OptionError("memory cap of " + std::to_string(cap_) + " bytes is smaller than the " +
                      "model's first page (" + std::to_string(first) +
                      " bytes in memory); give at least that much");
  }
  requests_.push_back({0, kNoPage, 0.0f});
  load_requested(pool);
}

bool PageCache::evictable(std::uint32_t p) const {
  return p != 0 && pages_[p] && resident_children_[p] == 0 && last_used_[p] < frame_number_ &&
         !in_flight_[p];
}

namespace {
// Heap order of eviction candidates (last use, page): the top is the least recently used, the
// highest page number among equals.
bool later_victim(const std::pair<std::uint64_t, std::uint32_t>& a,
                  const std::pair<std::uint64_t, std::uint32_t>& b) {
  return a.first > b.first || (a.first == b.first && a.second < b.second);
}
}  // namespace

bool PageCache::make_room(std::uint64_t bytes) {
  if (stats_.resident_bytes + bytes <= cap_) return true;
  // The candidates, gathered once a choice (choosing only takes pages out of them, and an
  // eviction can only add the victim's parent).
  if (!victims_ready_) {
    victims_.clear();
    for (std::uint32_t p = 1; p < pages_.size(); ++p) {
      if (evictable(p)) victims_.emplace_back(last_used_[p], p);
    }
    std::make_heap(victims_.begin(), victims_.end(), later_victim);
    victims_ready_ = true;
  }
  while (stats_.resident_bytes + bytes > cap_) {
    std::uint32_t victim = kNoPage;
    while (!victims_.empty()) {
      std::pop_heap(victims_.begin(), victims_.end(), later_victim);
      const std::uint32_t p = victims_.back().second;
      victims_.pop_back();
      if (evictable(p)) {
        victim = p;
        break;
      }
    }
    if (victim == kNoPage) return false;
    stats_.resident_bytes -= memory_[victim];
    memory_[victim] = 0;
    stats_.resident_page_bytes -= source_.page_storage_bytes(victim);
    pages_[victim].reset();
    const std::uint32_t parent = parent_[victim];
    parent_[victim] = kNoPage;
    --stats_.resident_pages;
    ++stats_.pages_evicted;
    if (parent != kNoPage && --resident_children_[parent] == 0 && evictable(parent)) {
      victims_.emplace_back(last_used_[parent], parent);
      std::push_heap(victims_.begin(), victims_.end(), later_victim);
    }
  }
  return true;
}

std::vector<PageRequest> PageCache::choose(std::size_t max_pages,
                                           std::uint64_t max_storage_bytes) {
  std::stable_sort(requests_.begin(), requests_.end(), [](const PageRequest& a,
                                                          const PageRequest& b) {
    return a.priority > b.priority;
  });
  // Choose what fits, reserving its memory (pages chosen now are marked used in this frame, so
  // they are not evicted for each other).
  std::vector<PageRequest> chosen;
  std::uint64_t storage = 0;
  // Once no page can be evicted, none can for the rest of this choice (choosing only marks
  // pages used and parents busy), so later requests fit without eviction or not at all: the
  // search over every page is not repeated for each of them (with 263 K pages and the cap
  // full, that repeated search is the likely cause of a 133 s billion-point frame).
  bool no_victims = false;
  for (const PageRequest& r : requests_) {
    if (chosen.size() >= max_pages) break;
    if (in_flight_[r.page]) continue;
    // A resident page is deepened (it holds only its first levels), from where it is used.
    const HierarchyPage* have = pages_[r.page].get();
    if (have != nullptr && r.first < have->node_count()) continue;
    const std::uint64_t read = source_.page_storage_bytes(r.page);
    if (!chosen.empty() && storage + read > max_storage_bytes) break;
    if (have == nullptr && r.parent_page != kNoPage && !pages_[r.parent_page]) continue;
    const std::uint64_t full = source_.page_memory_bytes(r.page);
    const std::uint64_t bytes = full - std::min(full, memory_[r.page]);
    // The page being deepened is in use this frame: make_room leaves it alone.
    if (have != nullptr) last_used_[r.page] = frame_number_;
    if (no_victims ? stats_.resident_bytes + bytes > cap_ : !make_room(bytes)) {
      no_victims = true;
      continue;
    }
    stats_.resident_bytes += bytes;
    reserved_[r.page] = bytes;
    // Keep the parent from being evicted while the page is on its way.
    if (have == nullptr && r.parent_page != kNoPage) {
      ++resident_children_[r.parent_page];
      last_used_[r.parent_page] = std::max(last_used_[r.parent_page], frame_number_);
    }
    last_used_[r.page] = frame_number_;
    storage += read;
    chosen.push_back(r);
  }
  for (const PageRequest& r : requests_) requested_[r.page] = 0;
  requests_.clear();
  victims_ready_ = false;
  stats_.resident_bytes_peak = std::max(stats_.resident_bytes_peak, stats_.resident_bytes);
  return chosen;
}

std::unique_ptr<HierarchyPage> PageCache::start_page(std::uint32_t page) const {
  // A page resident in part is continued from a copy of what it holds (the source does not
  // read that again); the resident one stays in use until the new one is adopted.
  const HierarchyPage* have = pages_[page].get();
  return have != nullptr ? std::make_unique<HierarchyPage>(*have)
                         : std::make_unique<HierarchyPage>();
}

void PageCache::adopt(const PageRequest& r, std::unique_ptr<HierarchyPage> page) {
  const bool packed = pages_[0] ? pages_[0]->is_packed() : page->is_packed();
  const std::uint64_t memory = page->memory_bytes(), full = source_.page_memory_bytes(r.page);
  const HierarchyPage* had = pages_[r.page].get();
  // A page comes whole, or (packed) as its first levels: more records than it had, fewer than
  // the page table's, at most the page's memory.
  const bool whole = page->node_count() == source_.page_node_count(r.page);
  if ((whole ? memory != full
             : !packed || page->node_count() > source_.page_node_count(r.page) ||
                   memory > full) ||
      (had != nullptr && page->node_count() <= had->node_count()) ||
      page->is_packed() != packed || (!packed && page->child_page.size() != page->nodes.size())) {
    throw FormatError("page " + std::to_string(r.page) + " loaded as " +
                      std::to_string(page->node_count()) + " nodes in " +
                      std::to_string(page->memory_bytes()) + " bytes where the page table says " +
                      std::to_string(source_.page_node_count(r.page)) + " nodes in " +
                      std::to_string(source_.page_memory_bytes(r.page)) +
                      "; the model file is corrupt (convert it again)");
  }
  // The reservation was for the whole page beyond what it held; keep what it takes.
  stats_.resident_bytes = stats_.resident_bytes - reserved_[r.page] - memory_[r.page] + memory;
  reserved_[r.page] = 0;
  memory_[r.page] = memory;
  stats_.bytes_read += page->storage_bytes;
  if (had != nullptr) {
    ++stats_.pages_deepened;
  } else {
    parent_[r.page] = r.parent_page;
    ++stats_.pages_loaded;
    ++stats_.resident_pages;
    stats_.resident_page_bytes += source_.page_storage_bytes(r.page);
  }
  pages_[r.page] = std::move(page);
  last_used_[r.page] = std::max(last_used_[r.page], frame_number_);
}

std::size_t PageCache::load_requested(ThreadPool& pool, std::size_t max_pages,
                                          std::uint64_t max_storage_bytes) {
  const std::vector<PageRequest> chosen = choose(max_pages, max_storage_bytes);
  std::vector<std::unique_ptr<HierarchyPage>> loaded(chosen.size());
  pool.run(chosen.size(), [&](std::size_t i) {
    const PageRequest& r = chosen[i];
    std::unique_ptr<HierarchyPage> page = start_page(r.page);
    source_.load(r.page, *page, load_prefix(r));
    loaded[i] = std::move(page);
  });
  for (std::size_t i = 0; i < chosen.size(); ++i) adopt(chosen[i], std::move(loaded[i]));
  return chosen.size();
}

}  // namespace pointillist
