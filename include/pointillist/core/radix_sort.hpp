// Stable least-significant-digit radix sort of a small run of records by an integer key, for
// runs that sit in cache (a bucket of a Morton sort, a page's triangles): each pass counts one
// 11-bit digit and scatters, passes whose digit every record shares are skipped, and records
// with equal keys keep their order.
#pragma once

#include <algorithm>
#include <array>
#include <cassert>
#include <cstdint>
#include <limits>
#include <span>
#include <utility>
#include <vector>

namespace pointillist {

// Sorts `items` by key(item) (a std::uint64_t whose bits from key_bits up are the same in every
// item), stably; `scratch` is working memory, kept by the caller between calls. At most 2^32 - 1
// items (the digit counters are 32-bit).
template <class T, class Key>
void stable_radix_sort(std::span<T> items, std::vector<T>& scratch, int key_bits, Key&& key) {
  constexpr int kDigitBits = 11;
  constexpr std::size_t kDigits = std::size_t{1} << kDigitBits;
  const std::size_t n = items.size();
  assert(n <= std::numeric_limits<std::uint32_t>::max());
  if (n < 2) return;
  scratch.resize(n);
  std::span<T> from = items, to = scratch;
  std::array<std::uint32_t, kDigits> count;
  for (int shift = 0; shift < key_bits; shift += kDigitBits) {
    const auto digit = [&](const T& item) { return (key(item) >> shift) & (kDigits - 1); };
    count.fill(0);
    for (const T& item : from) ++count[digit(item)];
    if (count[digit(from[0])] == n) continue;  // one digit: already in order
    std::uint32_t total = 0;
    for (std::uint32_t& c : count) total += std::exchange(c, total);
    for (const T& item : from) to[count[digit(item)]++] = item;
    std::swap(from, to);
  }
  if (from.data() != items.data()) std::copy(from.begin(), from.end(), items.begin());
}

}  // namespace pointillist
