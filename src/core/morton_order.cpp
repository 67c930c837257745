// Morton (Z-order) sort: 21 bits per axis interleaved into 63-bit codes, then a two-level sort
// (scatter into buckets by the top 12 bits, sort each bucket) that runs in parallel.
#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "pointillist/core/morton.hpp"
#include "pointillist/core/radix_sort.hpp"

namespace pointillist {
namespace {

constexpr int kBitsPerAxis = MortonFrame::kBits;
constexpr int kBucketBits = 12;  // the top 4 octree levels
constexpr std::size_t kBucketCount = std::size_t{1} << kBucketBits;
constexpr std::size_t kGrain = 1 << 16;
constexpr std::size_t kSmall = 1 << 16;  // below this a plain sort is faster than bucketing

struct Keyed {
  std::uint64_t code;
  std::uint32_t index;
};
// Equal codes keep index order, so the permutation depends only on the points.
inline bool operator<(const Keyed& a, const Keyed& b) {
  return a.code < b.code || (a.code == b.code && a.index < b.index);
}

// Sorts one bucket (its codes share the top kBucketBits bits; its entries in index order) by
// code, equal codes in index order.
void sort_bucket(std::span<Keyed> keys, std::vector<Keyed>& scratch) {
  constexpr int kLowBits = 3 * kBitsPerAxis - kBucketBits;
  if (keys.size() < 256) {
    std::sort(keys.begin(), keys.end());
  } else {
    stable_radix_sort(keys, scratch, kLowBits, [](const Keyed& k) { return k.code; });
  }
}

}  // namespace

MortonFrame MortonFrame::of(std::span<const Vec3f> points) {
  // Finite points only, so one stray NaN or inf cannot collapse every other code to 0.
  Aabb box;
  for (const Vec3f& p : points) {
    if (is_finite(p)) box.extend(p);
  }
  if (box.empty()) box.extend(Vec3f{});
  const Vec3f extent = box.extent();
  const float longest = std::max({extent.x, extent.y, extent.z});
  MortonFrame f;
  f.lo = box.lo;
  // One scale for all axes keeps cells cubic, so Z-order neighbours are spatial neighbours.
  f.scale = longest > 0.0f ? static_cast<float>(kMaxCell) / longest : 0.0f;
  return f;
}

std::vector<std::uint32_t> morton_order(std::span<const Vec3f> points, ThreadPool& pool) {
  const std::size_t n = points.size();
  assert(n <= std::size_t{UINT32_MAX});
  std::vector<std::uint32_t> order(n);
  if (n == 0) return order;

  const MortonFrame frame = MortonFrame::of(points);

  std::vector<Keyed> keyed(n);
  parallel_for(pool, n, kGrain, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const Vec3f p = points[i];
      keyed[i] = {frame.code(p), static_cast<std::uint32_t>(i)};
    }
  });

  if (n < kSmall) {
    std::sort(keyed.begin(), keyed.end());
    for (std::size_t i = 0; i < n; ++i) order[i] = keyed[i].index;
    return order;
  }

  // Bucket by the top bits: per-chunk histograms, then a stable scatter (chunk boundaries
  // depend only on n, so the layout is the same for any thread count).
  constexpr int kShift = 3 * kBitsPerAxis - kBucketBits;
  const std::size_t chunk_count = (n + kGrain - 1) / kGrain;
  std::vector<std::uint32_t> counts(chunk_count * kBucketCount, 0);
  pool.run(chunk_count, [&](std::size_t c) {
    std::uint32_t* h = &counts[c * kBucketCount];
    const std::size_t end = std::min(n, (c + 1) * kGrain);
    for (std::size_t i = c * kGrain; i < end; ++i) ++h[keyed[i].code >> kShift];
  });
  std::vector<std::size_t> bucket_begin(kBucketCount + 1, 0);
  {
    std::size_t total = 0;
    for (std::size_t b = 0; b < kBucketCount; ++b) {
      bucket_begin[b] = total;
      for (std::size_t c = 0; c < chunk_count; ++c) {
        const std::uint32_t count = counts[c * kBucketCount + b];
        counts[c * kBucketCount + b] = static_cast<std::uint32_t>(total);  // now a cursor
        total += count;
      }
    }
    bucket_begin[kBucketCount] = total;
  }
  std::vector<Keyed> bucketed(n);
  pool.run(chunk_count, [&](std::size_t c) {
    std::uint32_t* cursor = &counts[c * kBucketCount];
    const std::size_t end = std::min(n, (c + 1) * kGrain);
    for (std::size_t i = c * kGrain; i < end; ++i) {
      bucketed[cursor[keyed[i].code >> kShift]++] = keyed[i];
    }
  });
  keyed = {};

  // Sort buckets in groups of about kGrain points so tiny buckets do not cost a task each.
  std::vector<std::size_t> group_begin{0};
  for (std::size_t b = 0; b < kBucketCount; ++b) {
    if (bucket_begin[b + 1] - bucket_begin[group_begin.back()] >= kGrain) {
      group_begin.push_back(b + 1);
    }
  }
  if (group_begin.back() != kBucketCount) group_begin.push_back(kBucketCount);
  pool.run(group_begin.size() - 1, [&](std::size_t g) {
    std::vector<Keyed> scratch;
    for (std::size_t b = group_begin[g]; b < group_begin[g + 1]; ++b) {
      sort_bucket(std::span<Keyed>(bucketed).subspan(bucket_begin[b], bucket_begin[b + 1] - bucket_begin[b]),
                  scratch);
    }
    const std::size_t begin = bucket_begin[group_begin[g]], end = bucket_begin[group_begin[g + 1]];
    for (std::size_t i = begin; i < end; ++i) order[i] = bucketed[i].index;
  });
  return order;
}

}  // namespace pointillist
