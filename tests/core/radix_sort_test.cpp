// The small stable radix sort against std::stable_sort by the same key.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <vector>

#include "pointillist/core/radix_sort.hpp"

using namespace pointillist;

namespace {

struct Record {
  std::uint64_t key;
  std::uint32_t place;  // input position: equal keys must keep their order
  bool operator==(const Record&) const = default;
};

}  // namespace

TEST(StableRadixSort, MatchesAStableComparisonSortForEveryKeyWidth) {
  std::uint64_t state = 7;
  const auto next = [&] {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return state >> 11;
  };
  std::vector<Record> scratch;
  for (const int bits : {1, 5, 11, 12, 22, 23, 40, 51, 53}) {
    for (const std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{2}, std::size_t{300},
                                std::size_t{20'000}}) {
      std::vector<Record> items;
      for (std::uint32_t i = 0; i < n; ++i) {
        // Few distinct keys in some runs (many ties), keys spread over every bit in others;
        // the top bit of the width is set in some keys.
        const std::uint64_t mask = (std::uint64_t{1} << bits) - 1;
        const std::uint64_t key = (bits % 2 ? next() % 7 * (mask / 7) : next()) & mask;
        items.push_back({key, i});
      }
      std::vector<Record> expected = items;
      std::stable_sort(expected.begin(), expected.end(),
                       [](const Record& a, const Record& b) { return a.key < b.key; });
      stable_radix_sort(std::span(items), scratch, bits, [](const Record& r) { return r.key; });
      EXPECT_EQ(items, expected) << bits << " bits, " << n << " records";
    }
  }
}

TEST(StableRadixSort, RecordsOfOneKeyStayInTheirOrder) {
  std::vector<Record> items;
  for (std::uint32_t i = 0; i < 5'000; ++i) items.push_back({42, i});
  const std::vector<Record> before = items;
  std::vector<Record> scratch;
  stable_radix_sort(std::span(items), scratch, 20, [](const Record& r) { return r.key; });
  EXPECT_EQ(items, before);
}
