// The chunk plans, in memory and on disk, against a brute-force oracle: every range sorted by
// (coordinate, input index) on the longest axis of its box and cut at its middle, as the
// hierarchy's median splits cut it. Coordinates with many equal values make the on-disk
// selection read the index digits too.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <random>

#include "chunk_plan.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/core/point_set.hpp"
#include "testing/testing.hpp"

namespace pointillist::chunking {
namespace {

struct Oracle {
  std::vector<Split> splits;
  std::vector<std::uint64_t> counts;
  std::vector<Aabb> boxes;
};

Oracle brute_force(const std::vector<Vec3f>& p, std::uint32_t levels) {
  std::vector<std::vector<std::uint32_t>> ranges(1);
  for (std::uint32_t i = 0; i < p.size(); ++i) ranges[0].push_back(i);
  Oracle o;
  for (std::uint32_t level = 0; level < levels; ++level) {
    std::vector<std::vector<std::uint32_t>> next;
    for (auto& r : ranges) {
      Aabb box;
      for (std::uint32_t i : r) box.extend(p[i]);
      const int axis = box.longest_axis();
      std::sort(r.begin(), r.end(), [&](std::uint32_t a, std::uint32_t b) {
        const float ca = p[a][axis] + 0.0f, cb = p[b][axis] + 0.0f;
        return ca < cb || (ca == cb && a < b);
      });
      const std::size_t mid = r.size() / 2;
      o.splits.push_back({std::uint8_t(axis), p[r[mid]][axis] + 0.0f, r[mid]});
      next.emplace_back(r.begin(), r.begin() + std::ptrdiff_t(mid));
      next.emplace_back(r.begin() + std::ptrdiff_t(mid), r.end());
    }
    ranges = std::move(next);
  }
  for (const auto& r : ranges) {
    Aabb box;
    for (std::uint32_t i : r) box.extend(p[i]);
    o.counts.push_back(r.size());
    o.boxes.push_back(box);
  }
  return o;
}

void expect_plan(const ChunkPlan& plan, const Oracle& o, const std::vector<Vec3f>& p) {
  ASSERT_EQ(plan.splits.size(), o.splits.size());
  for (std::size_t j = 0; j < o.splits.size(); ++j) {
    EXPECT_EQ(plan.splits[j].axis, o.splits[j].axis) << "split " << j;
    EXPECT_EQ(plan.splits[j].value, o.splits[j].value) << "split " << j;
    EXPECT_EQ(plan.splits[j].index, o.splits[j].index) << "split " << j;
  }
  EXPECT_EQ(plan.counts, o.counts);
  ASSERT_EQ(plan.boxes.size(), o.boxes.size());
  for (std::size_t c = 0; c < o.boxes.size(); ++c) {
    for (int a = 0; a < 3; ++a) {
      EXPECT_EQ(plan.boxes[c].lo[a], o.boxes[c].lo[a]) << "chunk " << c;
      EXPECT_EQ(plan.boxes[c].hi[a], o.boxes[c].hi[a]) << "chunk " << c;
    }
  }
  // chunk_of agrees with the oracle's counts.
  std::vector<std::uint64_t> seen(o.counts.size(), 0);
  for (std::size_t i = 0; i < p.size(); ++i) ++seen[plan.chunk_of(p[i], i)];
  EXPECT_EQ(seen, o.counts);
}

// A slab with few distinct coordinates along x (ties), -0 and +0 among them, and a spread in y.
std::vector<Vec3f> tied_points(std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> coarse(-4, 4);
  std::uniform_real_distribution<float> fine(-1.0f, 1.0f);
  std::vector<Vec3f> p(n);
  for (Vec3f& x : p) {
    const int k = coarse(rng);
    x = {k == 0 ? (rng() % 2 ? -0.0f : 0.0f) : float(k), 0.5f * fine(rng), 0.01f * fine(rng)};
  }
  return p;
}

std::string write_positions(const testing::TempDir& dir, const std::vector<Vec3f>& p) {
  const std::string path = dir.file("positions");
  std::FILE* f = std::fopen(path.c_str(), "wb");
  EXPECT_NE(f, nullptr);
  EXPECT_EQ(std::fwrite(p.data(), sizeof(Vec3f), p.size(), f), p.size());
  std::fclose(f);
  return path;
}

// tied_points(n, seed) in a file of positions, as the chunked conversion writes it, and their box.
struct PositionsOnDisk {
  PositionsOnDisk(std::size_t n, unsigned seed)
      : p(tied_points(n, seed)), path(write_positions(dir, p)), box(bounding_box(p)) {}
  testing::TempDir dir;
  std::vector<Vec3f> p;
  std::string path;
  Aabb box;
};

TEST(ChunkPlan, InMemoryPlanIsTheHierarchysMedianSplits) {
  const std::vector<Vec3f> p = tied_points(6001, 3);
  ThreadPool pool(2);
  expect_plan(plan_chunks(p, 4, pool), brute_force(p, 4), p);
}

// From kSplitOnTwoThreads points on, the first level is split on two threads (a count of the
// coordinates' top bits, a selection in one bucket, two partitions and a swap): the same plan,
// with many ties at the median (x in steps of 1/1000), and when the median's bucket is too
// large to copy (nine distinct x: one std::nth_element instead).
TEST(ChunkPlan, FirstLevelOnTwoThreadsIsTheHierarchysMedianSplits) {
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> step(-5000, 5000);
  std::uniform_real_distribution<float> fine(-1.0f, 1.0f);
  std::vector<Vec3f> stepped(kSplitOnTwoThreads + 4321);
  for (Vec3f& x : stepped) x = {float(step(rng)) / 1000.0f, 0.5f * fine(rng), 0.01f * fine(rng)};
  for (const auto& p : {stepped, tied_points(kSplitOnTwoThreads + 77, 13)}) {
    ThreadPool pool(2);
    expect_plan(plan_chunks(p, 3, pool), brute_force(p, 3), p);
  }
}

TEST(ChunkPlan, OnDiskPlanIsTheSamePlanWhateverItsMemory) {
  const PositionsOnDisk file(6001, 5);
  const auto& [dir, p, path, box] = file;
  const Oracle o = brute_force(p, 4);
  for (unsigned threads : {1u, 2u}) {
    ThreadPool pool(threads);
    const std::size_t range_counts = std::size_t{threads} << 18;  // 256 KiB a thread
    const std::vector<DiskPlanMemory> memories = {
        // All candidates at once; a few (coordinate digits); one (every index digit too).
        {.max_candidates = 1 << 20}, {.max_candidates = 400}, {.max_candidates = 1},
        // Counts for one range a pass, then for three, with reads of 97 positions (windows
        // that end inside ranges), with many candidates and with few.
        {.max_candidates = 1 << 20, .histogram_bytes = 1, .window_points = 97},
        {.max_candidates = 50, .histogram_bytes = 1, .window_points = 97},
        {.max_candidates = 50, .histogram_bytes = 3 * range_counts, .window_points = 97},
        // Each pass finding the points' ranges from the splits (no room to keep them).
        {.max_candidates = 400, .range_id_bytes = 0},
        {.max_candidates = 50, .histogram_bytes = 1, .window_points = 97, .range_id_bytes = 0}};
    for (const DiskPlanMemory& m : memories) {
      SCOPED_TRACE(::testing::Message() << threads << " threads, " << m.max_candidates
                                        << " candidates, counts of " << m.histogram_bytes
                                        << " bytes, reads of " << m.window_points
                                        << ", range ids of " << m.range_id_bytes << " bytes");
      expect_plan(plan_chunks_on_disk(path, p.size(), box, 4, m, pool, Progress::none()), o, p);
    }
  }
}

// Ten levels (1,024 chunks): each point's range takes two bytes between passes.
TEST(ChunkPlan, OnDiskPlanOfManyLevelsIsTheSamePlan) {
  const PositionsOnDisk file(6001, 9);
  const auto& [dir, p, path, box] = file;
  ThreadPool pool(2);
  const Oracle o = brute_force(p, 10);
  for (const std::size_t id_bytes : {std::size_t{1} << 20, std::size_t{0}}) {
    SCOPED_TRACE(::testing::Message() << "range ids of " << id_bytes << " bytes");
    expect_plan(plan_chunks_on_disk(path, p.size(), box, 10,
                                    {.max_candidates = 400, .range_id_bytes = id_bytes}, pool,
                                    Progress::none()),
                o, p);
  }
}

TEST(ChunkPlan, OnDiskPlanSaysWhenThePositionFileIsShort) {
  const PositionsOnDisk file(1000, 7);
  const auto& [dir, p, path, box] = file;
  ThreadPool pool(1);
  try {
    plan_chunks_on_disk(path, 2000, box, 2, {.max_candidates = 100}, pool, Progress::none());
    FAIL() << "a short file was accepted";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("ends early"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace pointillist::chunking
