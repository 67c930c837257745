// The chunks of a chunked conversion (private to pipeline): the top binary levels of the very
// median splits build_sphere_tree makes over all the points (longest axis of the range's box,
// the first n/2 points by (coordinate, input index) to the left), so each chunk holds exactly
// the points of one subtree of the hierarchy a conversion in one piece builds, and the chunked
// file decodes to the same hierarchy.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <string>

#include "pointillist/core/math.hpp"
#include "pointillist/core/progress.hpp"
#include "pointillist/core/thread_pool.hpp"

namespace pointillist::chunking {

// A binary split: a point (coordinate c on `axis`, input index i) goes left when
// (c, i) < (value, index), c taken with -0 as +0.
struct Split {
  std::uint8_t axis = 0;
  float value = 0;
  std::uint64_t index = 0;
};

struct ChunkPlan {
  std::uint32_t levels = 0;         // binary levels; 2^levels chunks
  std::vector<Split> splits;        // heap order: node j's children are 2j + 1 and 2j + 2
  std::vector<std::uint64_t> counts;  // points per chunk, chunk order (left to right)
  std::vector<Aabb> boxes;          // box of each chunk's points

  std::size_t chunk_count() const { return counts.size(); }
  // Whether the point (coordinate c on the split's axis, -0 taken as +0; input index) goes left.
  static bool goes_left(const Split& s, float c, std::uint64_t index) {
    return (c < s.value) | ((c == s.value) & (index < s.index));
  }
  // Whether points within `reach` of coordinate c may lie left of the split, and right of it.
  static bool reaches_left(const Split& s, float c, float reach) { return c - reach <= s.value; }
  static bool reaches_right(const Split& s, float c, float reach) { return c + reach >= s.value; }
  // The chunk of a point.
  std::uint32_t chunk_of(const Vec3f& p, std::uint64_t index) const {
    return static_cast<std::uint32_t>(node_below(p, index, levels) - splits.size());
  }
  // The heap index of the range that the point (p, index) lies in `depth` levels of splits
  // below the range `from` (the root: 0), which holds it. Without branches on the data: the
  // sides are a coin toss for the branch predictor, and every point of a chunked conversion
  // comes this way.
  std::size_t node_below(const Vec3f& p, std::uint64_t index, std::uint32_t depth,
                         std::size_t from = 0) const {
    const float q[3] = {p.x + 0.0f, p.y + 0.0f, p.z + 0.0f};
    std::size_t j = from;
    for (std::uint32_t l = 0; l < depth; ++l) {
      const Split& s = splits[j];
      const float c = q[s.axis];
      j = 2 * j + 2 - std::size_t{goes_left(s, c, index)};
    }
    return j;
  }
  // chunk_of for the `count` (at most kBatch) points p[0..count) with the input indices
  // first, first + 1, ..., into chunk[]; and, in the same descent, whether each lies within
  // `max_reach` of a split on its way, into near_a_split[] (else for_near_chunks with that
  // max_reach finds no chunk: it would follow only the point's own way down). The points go down
  // together, level by level, so that their chains of dependent loads overlap.
  static constexpr std::size_t kBatch = 8;
  void chunks_of(const Vec3f* p, std::size_t count, std::uint64_t first, float max_reach,
                 std::uint32_t* chunk, bool* near_a_split) const {
    float q[kBatch][3];
    std::size_t j[kBatch];
    bool near[kBatch];
    for (std::size_t b = 0; b < kBatch; ++b) {
      const Vec3f& v = p[b < count ? b : 0];
      q[b][0] = v.x + 0.0f, q[b][1] = v.y + 0.0f, q[b][2] = v.z + 0.0f;
      j[b] = 0;
      near[b] = false;
    }
    for (std::uint32_t l = 0; l < levels; ++l) {
      for (std::size_t b = 0; b < kBatch; ++b) {
        const Split& s = splits[j[b]];
        const float c = q[b][s.axis];
        // for_near_chunks' two tests (its coordinates keep -0, equal to +0 in every comparison)
        near[b] |= reaches_left(s, c, max_reach) & reaches_right(s, c, max_reach);
        j[b] = 2 * j[b] + 2 - std::size_t{goes_left(s, c, first + b)};
      }
    }
    for (std::size_t b = 0; b < count; ++b) {
      chunk[b] = static_cast<std::uint32_t>(j[b] - splits.size());
      near_a_split[b] = near[b];
    }
  }
  // Calls fn(chunk) for every chunk other than `own` whose box is nearer than `reach[chunk]`
  // to `p` (a halo point for it); `max_reach` bounds every reach.
  template <class Fn>
  void for_near_chunks(const Vec3f& p, std::uint32_t own, std::span<const float> reach,
                       float max_reach, Fn&& fn) const {
    visit_near(0, 0, p, own, reach, max_reach, fn);
  }

 private:
  template <class Fn>
  void visit_near(std::size_t j, std::uint32_t level, const Vec3f& p, std::uint32_t own,
                  std::span<const float> reach, float max_reach, Fn& fn) const {
    if (level == levels) {
      const auto chunk = static_cast<std::uint32_t>(j - splits.size());
      if (chunk == own) return;
      const Aabb& b = boxes[chunk];
      float d2 = 0;
      for (int a = 0; a < 3; ++a) {
        const float below = b.lo[a] - p[a], above = p[a] - b.hi[a];
        const float d = std::max({below, above, 0.0f});
        d2 += d * d;
      }
      if (d2 < reach[chunk] * reach[chunk]) fn(chunk);
      return;
    }
    const Split& s = splits[j];
    const float c = p[s.axis];
    if (reaches_left(s, c, max_reach)) {
      visit_near(2 * j + 1, level + 1, p, own, reach, max_reach, fn);
    }
    if (reaches_right(s, c, max_reach)) {
      visit_near(2 * j + 2, level + 1, p, own, reach, max_reach, fn);
    }
  }
};

// From this many points on, a level with fewer ranges than threads (the first) splits each
// range on two threads.
constexpr std::size_t kSplitOnTwoThreads = std::size_t{1} << 17;

// A point of the plan: its position and input index.
struct PlanPoint {
  Vec3f position;
  std::uint32_t index;
};

// The plan with `levels` binary levels over `points` (each with its input index; their order
// does not matter), which it reorders: the selections move the points themselves, so they read
// memory in order. Chunk members: `members` (when not null) gets each chunk's input indices,
// increasing. Parallel; the same plan for any thread count.
ChunkPlan plan_chunks(std::vector<PlanPoint> points, std::uint32_t levels, ThreadPool& pool,
                      std::vector<std::vector<std::uint32_t>>* members = nullptr);
// The same over `positions` in input order.
ChunkPlan plan_chunks(std::span<const Vec3f> positions, std::uint32_t levels, ThreadPool& pool,
                      std::vector<std::vector<std::uint32_t>>* members = nullptr);

// What plan_chunks_on_disk may hold in memory.
struct DiskPlanMemory {
  std::size_t max_candidates = 1 << 20;  // points kept for selection (32 bytes each)
  // The counts of the ranges' next digits: 256 KiB a range and thread. Ranges beyond what
  // this holds are counted in further passes over the file (at least one range a pass).
  std::size_t histogram_bytes = std::size_t{1} << 30;
  std::size_t window_points = std::size_t{1} << 21;  // positions read at a time (12 bytes each)
  // Each point's range between passes (a byte a point up to 512 chunks, two up to 2^17), when
  // this holds them; else each pass finds the ranges again from the splits.
  std::size_t range_id_bytes = std::size_t{1} << 30;
};

// The plan of plan_chunks without the positions in memory: `path` holds the `n` positions
// (Vec3f records, 12 bytes each, in index order), `box` is their box. Each level reads the file
// about twice (a count of the split coordinates' top 16 bits for every range, then the points of
// the bucket holding each median, selected in memory); more when a bucket holds more than
// `max_candidates` points (the level's ranges together), as with many equal coordinates, or
// when the level's counts do not fit `histogram_bytes`. The same plan for any thread count and
// memory. Reports n / levels to `progress` after each level. Throws IoError.
ChunkPlan plan_chunks_on_disk(const std::string& path, std::uint64_t n, const Aabb& box,
                              std::uint32_t levels, const DiskPlanMemory& memory,
                              ThreadPool& pool, Progress& progress);

}  // namespace pointillist::chunking
