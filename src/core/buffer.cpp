// The huge-page regions behind Buffer (see buffer.hpp): 64 MiB regions mapped with
// MADV_HUGEPAGE, cut into power-of-two blocks of at least 4 KiB by a bump pointer; freed blocks
// wait in a list per size for the next request of that size. Blocks above a region's size are
// mapped (and unmapped) one by one.
#include "pointillist/core/buffer.hpp"

#include <sys/mman.h>

#include <array>
#include <bit>
#include <cstdint>
#include <cstdlib>
#include <mutex>

#if defined(__SANITIZE_ADDRESS__)
#define POINTILLIST_PLAIN_BUFFERS 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define POINTILLIST_PLAIN_BUFFERS 1
#endif
#endif

namespace pointillist {
namespace {

constexpr std::size_t kHugePage = std::size_t{2} << 20;
constexpr std::size_t kRegion = std::size_t{64} << 20;
constexpr unsigned kMinShift = 12;  // 4 KiB
constexpr unsigned kMaxShift = 25;  // blocks up to half a region

// A mapping of `bytes` (a multiple of kHugePage) aligned to kHugePage, advised for huge pages.
void* map_aligned(std::size_t bytes) {
  const std::size_t span = bytes + kHugePage;
  void* raw = mmap(nullptr, span, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (raw == MAP_FAILED) throw std::bad_alloc();
  const auto start = reinterpret_cast<std::uintptr_t>(raw);
  const std::uintptr_t aligned = (start + kHugePage - 1) & ~(kHugePage - 1);
  if (aligned > start) munmap(raw, aligned - start);
  const std::uintptr_t end = start + span, used_end = aligned + bytes;
  if (end > used_end) munmap(reinterpret_cast<void*>(used_end), end - used_end);
  void* p = reinterpret_cast<void*>(aligned);
  madvise(p, bytes, MADV_HUGEPAGE);  // advice only: without it the pages are 4 KiB
  return p;
}

class Regions {
 public:
  void* allocate(std::size_t bytes) {
    const unsigned shift = shift_for(bytes);
    if (shift > kMaxShift) {
      return map_aligned((bytes + kHugePage - 1) & ~(kHugePage - 1));
    }
    const std::size_t size = std::size_t{1} << shift;
    std::lock_guard lock(mutex_);
    auto& list = free_[shift - kMinShift];
    if (!list.empty()) {
      void* p = list.back();
      list.pop_back();
      return p;
    }
    // Each block starts a different number of cache lines into its slot: blocks of equal
    // power-of-two sizes would otherwise start at the same offset modulo 4 KiB, and the arrays
    // of one splat chunk, written at the same index together, would all compete for the same
    // cache sets (a third slower selection).
    const std::size_t slot = size + kColours * kLine;
    if (next_ + slot > end_) {
      next_ = reinterpret_cast<std::uintptr_t>(map_aligned(kRegion));
      end_ = next_ + kRegion;
    }
    void* p = reinterpret_cast<void*>(next_ + (colour_++ % kColours) * kLine);
    next_ += slot;
    return p;
  }

  void free(void* p, std::size_t bytes) noexcept {
    const unsigned shift = shift_for(bytes);
    if (shift > kMaxShift) {
      munmap(p, (bytes + kHugePage - 1) & ~(kHugePage - 1));
      return;
    }
    std::lock_guard lock(mutex_);
    try {
      free_[shift - kMinShift].push_back(p);
    } catch (...) {
      // The list could not grow: the block is lost to reuse, not to correctness.
    }
  }

 private:
  static unsigned shift_for(std::size_t bytes) {
    const std::size_t b = bytes < (std::size_t{1} << kMinShift) ? std::size_t{1} << kMinShift
                                                                 : bytes;
    return static_cast<unsigned>(std::bit_width(b - 1));
  }

  std::mutex mutex_;
  static constexpr std::size_t kLine = 64, kColours = 31;
  std::uintptr_t next_ = 0, end_ = 0;
  std::size_t colour_ = 0;
  std::array<std::vector<void*>, kMaxShift - kMinShift + 1> free_;
};

// Unused when ASan replaces the regions by plain new (POINTILLIST_PLAIN_BUFFERS).
[[maybe_unused]] Regions& regions() {
  static Regions* r = new Regions;  // never destroyed: buffers may be freed during exit
  return *r;
}

}  // namespace

void* huge_page_allocate(std::size_t bytes) {
#ifdef POINTILLIST_PLAIN_BUFFERS
  return ::operator new(bytes);
#else
  if (bytes == 0) bytes = 1;
  return regions().allocate(bytes);
#endif
}

void huge_page_free(void* p, std::size_t bytes) noexcept {
#ifdef POINTILLIST_PLAIN_BUFFERS
  ::operator delete(p);
  (void)bytes;
#else
  if (p) regions().free(p, bytes == 0 ? 1 : bytes);
#endif
}

}  // namespace pointillist
