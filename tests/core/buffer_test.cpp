// core::Buffer: a vector whose growth leaves new elements uninitialised, over huge-page regions
// with reuse. The oracles: std::vector holding the same values, and a brute-force overlap check
// of every live block.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <random>
#include <utility>
#include <vector>

#include "pointillist/core/buffer.hpp"
#include "pointillist/core/model_cache.hpp"

using namespace pointillist;

TEST(Buffer, GrowingKeepsTheValuesWrittenLikeAVector) {
  Buffer<float> b;
  std::vector<float> ref;
  std::mt19937 rng(7);
  for (int round = 0; round < 40; ++round) {
    const std::size_t old = b.size();
    const std::size_t n = old + 1 + rng() % 5000;
    b.resize(n);
    ref.resize(n);
    for (std::size_t i = old; i < n; ++i) b[i] = ref[i] = float(rng() % 1000) * 0.5f;
  }
  ASSERT_EQ(b.size(), ref.size());
  EXPECT_TRUE(std::equal(b.begin(), b.end(), ref.begin()));
  // Copies and element-wise construction behave as for a vector.
  const Buffer<float> copy = b;
  EXPECT_TRUE(std::equal(copy.begin(), copy.end(), ref.begin(), ref.end()));
  Buffer<int> filled(100, 42);
  EXPECT_TRUE(std::all_of(filled.begin(), filled.end(), [](int v) { return v == 42; }));
}

TEST(Buffer, LiveBlocksNeverOverlapAndFreedBlocksAreReused) {
  std::mt19937 rng(11);
  std::vector<std::pair<std::uintptr_t, std::size_t>> live;
  std::vector<std::pair<void*, std::size_t>> blocks;
  for (int i = 0; i < 600; ++i) {
    // Sizes from a few bytes to 40 MiB (above a region's half: mapped on its own).
    std::size_t bytes = std::size_t{1} << (rng() % 26);
    bytes += rng() % bytes;
    if (i % 97 == 0) bytes = std::size_t{40} << 20;
    void* p = huge_page_allocate(bytes);
    ASSERT_NE(p, nullptr);
    ASSERT_EQ(reinterpret_cast<std::uintptr_t>(p) % alignof(std::max_align_t), 0u);
    static_cast<unsigned char*>(p)[0] = 1;          // writable at both ends
    static_cast<unsigned char*>(p)[bytes - 1] = 2;
    blocks.push_back({p, bytes});
    if (rng() % 3 == 0) {  // free a random live block
      const std::size_t k = rng() % blocks.size();
      huge_page_free(blocks[k].first, blocks[k].second);
      blocks.erase(blocks.begin() + std::ptrdiff_t(k));
    }
  }
  for (const auto& [p, n] : blocks) live.push_back({reinterpret_cast<std::uintptr_t>(p), n});
  std::sort(live.begin(), live.end());
  for (std::size_t i = 1; i < live.size(); ++i) {
    EXPECT_GE(live[i].first, live[i - 1].first + live[i - 1].second) << "blocks overlap";
  }
  for (const auto& [p, n] : blocks) huge_page_free(p, n);
}

TEST(ModelCache, FollowsTheVariablesInOrder) {
  const char* saved[3] = {std::getenv("POINTILLIST_MODELS"), std::getenv("XDG_CACHE_HOME"),
                          std::getenv("HOME")};
  const std::string keep[3] = {saved[0] ? saved[0] : "", saved[1] ? saved[1] : "",
                               saved[2] ? saved[2] : ""};
  setenv("POINTILLIST_MODELS", "/m", 1);
  setenv("XDG_CACHE_HOME", "/x", 1);
  setenv("HOME", "/h", 1);
  EXPECT_EQ(model_cache_dir(), "/m");
  unsetenv("POINTILLIST_MODELS");
  EXPECT_EQ(model_cache_dir(), "/x/pointillist/models");
  unsetenv("XDG_CACHE_HOME");
  EXPECT_EQ(model_cache_dir(), "/h/.cache/pointillist/models");
  EXPECT_EQ(cached_model_path("no-such-model.ply"), "");
  const char* names[3] = {"POINTILLIST_MODELS", "XDG_CACHE_HOME", "HOME"};
  for (int i = 0; i < 3; ++i) {
    if (saved[i]) setenv(names[i], keep[i].c_str(), 1); else unsetenv(names[i]);
  }
}
