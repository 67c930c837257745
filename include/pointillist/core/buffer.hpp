// Buffer<T>: a std::vector for large scratch arrays of plain values that are written before they
// are read, such as a frame's splat stream:
// - new elements are left uninitialised (default-initialised): growing a buffer does not zero
//   it;
// - its memory comes from regions the kernel may back with 2 MiB pages (madvise
//   MADV_HUGEPAGE), so a first frame writing megabytes of fresh buffers takes a few hundred
//   page faults instead of thousands (a one-shot frame of the dragon spent a third of its time
//   in them). Blocks are kept for reuse when freed, not returned to the system.
// Under AddressSanitizer the memory comes from the ordinary allocator, so that it is checked.
#pragma once

#include <cstddef>
#include <memory>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

namespace pointillist {

// Blocks of at least `bytes` from the huge-page regions (thread-safe); huge_page_free takes the
// same byte count back.
void* huge_page_allocate(std::size_t bytes);
void huge_page_free(void* p, std::size_t bytes) noexcept;

template <class T>
class BufferAllocator {
 public:
  using value_type = T;
  BufferAllocator() = default;
  template <class U>
  BufferAllocator(const BufferAllocator<U>&) noexcept {}

  T* allocate(std::size_t n) {
    if (n > SIZE_MAX / sizeof(T)) throw std::bad_array_new_length();
    return static_cast<T*>(huge_page_allocate(n * sizeof(T)));
  }
  void deallocate(T* p, std::size_t n) noexcept { huge_page_free(p, n * sizeof(T)); }

  // Value-initialisation (vector::resize(n)) becomes default-initialisation.
  template <class U>
  void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }

  template <class U>
  bool operator==(const BufferAllocator<U>&) const noexcept {
    return true;
  }
};

template <class T>
using Buffer = std::vector<T, BufferAllocator<T>>;

}  // namespace pointillist
