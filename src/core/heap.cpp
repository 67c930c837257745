#include "pointillist/core/heap.hpp"

#include <cstdlib>

namespace pointillist {

void prefault_heap(std::uint64_t bytes, ThreadPool& pool) {
  constexpr std::uint64_t kPage = 4096;
  if (bytes < kPage) return;
  auto* block = static_cast<volatile unsigned char*>(std::malloc(bytes));
  if (!block) return;
  const std::uint64_t pages = bytes / kPage;
  parallel_for(pool, pages, 512, [&](std::size_t begin, std::size_t end) {
    for (std::size_t p = begin; p < end; ++p) block[p * kPage] = 0;
  });
  std::free(const_cast<unsigned char*>(block));
}

}  // namespace pointillist
