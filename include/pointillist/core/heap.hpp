// Touching fresh memory ahead of use, on every thread. The first write to a page the system has
// just handed out makes the kernel zero it, which on virtual machines costs about 1 s a GB even
// in 2 MB pages; a conversion that fills its vectors on one thread pays that serially. When the
// process keeps freed memory (no trimming, no mmap for large blocks: the CLI's
// keep_freed_memory), a block allocated, touched in parallel and freed again stays in the heap
// with its pages in place, and the conversion's vectors reuse it without faulting.
#pragma once

#include <cstdint>

#include "pointillist/core/thread_pool.hpp"

namespace pointillist {

// Allocates `bytes`, writes one byte of every 4 KB page on the pool's threads, frees it. Does
// nothing when the allocation fails. Only useful in a process that keeps freed memory.
void prefault_heap(std::uint64_t bytes, ThreadPool& pool);

}  // namespace pointillist
