// Morton (Z-order) codes and a deterministic parallel sort: the spatial order that neighbour
// queries (spatial), the normal passes (prep) and the Sequential Point Tree build (lod) share.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "pointillist/core/math.hpp"
#include "pointillist/core/thread_pool.hpp"

namespace pointillist {

// Spreads the low 21 bits of v so that two zero bits separate consecutive bits.
constexpr std::uint64_t spread_bits_21(std::uint64_t v) {
  v &= 0x1fffff;
  v = (v | (v << 32)) & 0x1f00000000ffffULL;
  v = (v | (v << 16)) & 0x1f0000ff0000ffULL;
  v = (v | (v << 8)) & 0x100f00f00f00f00fULL;
  v = (v | (v << 4)) & 0x10c30c30c30c30c3ULL;
  v = (v | (v << 2)) & 0x1249249249249249ULL;
  return v;
}

// The inverse of spread_bits_21: the bits of v at every third place, from the lowest.
constexpr std::uint32_t compact_bits_21(std::uint64_t v) {
  v &= 0x1249249249249249ULL;
  v = (v | (v >> 2)) & 0x10c30c30c30c30c3ULL;
  v = (v | (v >> 4)) & 0x100f00f00f00f00fULL;
  v = (v | (v >> 8)) & 0x1f0000ff0000ffULL;
  v = (v | (v >> 16)) & 0x1f00000000ffffULL;
  v = (v | (v >> 32)) & 0x1fffffULL;
  return static_cast<std::uint32_t>(v);
}

// The 63-bit Morton code of cell (a, b, c), 21 bits each: a takes the lowest bit of every
// triple, c the highest. Which axis goes where is the caller's convention.
constexpr std::uint64_t morton_code(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
  return spread_bits_21(a) | spread_bits_21(b) << 1 | spread_bits_21(c) << 2;
}
static_assert(compact_bits_21(morton_code(5, 9, 1u << 20) >> 1) == 9);

// The grid of morton_order: 2^21 cubic cells a side over the bounding box of the finite points
// (one scale for all axes). cell() is a coordinate's cell; NaN and values outside the box are
// clamped to it.
struct MortonFrame {
  static constexpr int kBits = 21;
  static constexpr std::uint32_t kMaxCell = (1u << kBits) - 1;
  Vec3f lo;
  float scale = 0;  // cells per unit of length
  static MortonFrame of(std::span<const Vec3f> points);
  std::uint32_t cell(float v, float lo_v) const {
    const float c = (v - lo_v) * scale;
    if (!(c >= 0.0f)) return 0;
    if (!(c < static_cast<float>(kMaxCell))) return kMaxCell;
    return static_cast<std::uint32_t>(c);
  }
  std::uint64_t code(Vec3f p) const {
    return morton_code(cell(p.x, lo.x), cell(p.y, lo.y), cell(p.z, lo.z));
  }
};

// Permutation that sorts points along a Morton (Z-order) curve over their bounding box (21 bits
// per axis, one scale for all three axes, x in the lowest bit): entry j is the index of the j-th
// point along the curve. Points in the same cell keep their index order; non-finite coordinates
// are clamped to the box. Neighbour queries and tree builds run several times faster on
// spatially ordered input. Parallel; the result does not depend on the thread count.
std::vector<std::uint32_t> morton_order(std::span<const Vec3f> points, ThreadPool& pool);

// Sorts `v` by `less` on the pool: blocks of `block` elements sorted in parallel, then runs
// merged pairwise level by level. `less` must be a strict total order (no two elements equal),
// so the result is the same for any thread count.
template <typename T, typename Less>
void parallel_sort(std::vector<T>& v, ThreadPool& pool, Less less,
                   std::size_t block = std::size_t{1} << 14) {
  const std::size_t n = v.size(), blocks = (n + block - 1) / block;
  if (blocks <= 1) {
    std::sort(v.begin(), v.end(), less);
    return;
  }
  const auto edge = [&](std::size_t b) { return std::min(n, b * block); };
  pool.run(blocks,
           [&](std::size_t b) { std::sort(v.data() + edge(b), v.data() + edge(b + 1), less); });
  std::vector<T> other(n);
  T* src = v.data();
  T* dst = other.data();
  for (std::size_t width = 1; width < blocks; width *= 2) {
    pool.run((blocks + 2 * width - 1) / (2 * width), [&](std::size_t pair) {
      const std::size_t lo = edge(2 * pair * width), mid = edge((2 * pair + 1) * width),
                        hi = edge((2 * pair + 2) * width);
      std::merge(src + lo, src + mid, src + mid, src + hi, dst + lo, less);
    });
    std::swap(src, dst);
  }
  if (src != v.data()) v.swap(other);
}

}  // namespace pointillist
