// Private to prep: parallel loops over a mesh's faces where each task owns a range of vertices.
#pragma once

#include <algorithm>
#include <cstdint>

#include "pointillist/core/thread_pool.hpp"

namespace pointillist::prep_detail {

// Splits the vertices [0, vertex_count) into one contiguous range per thread and calls
// fn(lo, hi) for each range on the pool. Each task scans all faces but writes only to its own
// vertices, so no two tasks write the same slot and every vertex sees its faces in face order:
// the result is the same for any number of ranges. Scanning the face list is cheap next to the
// scattered vertex writes it splits.
template <class Fn>
void for_each_vertex_range(ThreadPool& pool, std::size_t vertex_count, Fn&& fn) {
  const std::size_t ranges =
      std::max<std::size_t>(1, std::min<std::size_t>(pool.thread_count(), vertex_count / 4096));
  pool.run(ranges, [&](std::size_t r) {
    fn(static_cast<std::uint32_t>(vertex_count * r / ranges),
       static_cast<std::uint32_t>(vertex_count * (r + 1) / ranges));
  });
}

}  // namespace pointillist::prep_detail
