// plan_chunks_on_disk (see chunk_plan.hpp): the plan of plan_chunks without the positions in
// memory. Each split is a radix selection on the key (coordinate, input index), read 16 bits at a
// time (the coordinate as an order-preserving unsigned integer, then the index): a pass over the
// file counts, for every range of the level, the keys that share the digits chosen so far by
// their next digit, and the digit holding the median is chosen; once the keys sharing the chosen
// digits are few enough, the next pass keeps them and the median is selected among them in
// memory. Points whose key already differs from a range's chosen digits are on a known side:
// they extend the box of that side, so the boxes of the next level need no pass of their own.
#include <algorithm>
#include <array>
#include <cstdio>
#include <cstring>
#include <memory>

#include "chunk_plan.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/core/float_order.hpp"

namespace pointillist::chunking {
namespace {

constexpr int kDigits = 6;  // 2 of the coordinate, 4 of the index
constexpr std::size_t kBuckets = 1 << 16;

// The coordinate as an unsigned integer in the same order (-0 as +0; no NaN here).
std::uint32_t ordered(float c) { return ordered_key(c + 0.0f); }

std::uint32_t digit(std::uint32_t key, std::uint64_t index, int d) {
  if (d == 0) return key >> 16;
  if (d == 1) return key & 0xffff;
  return static_cast<std::uint32_t>(index >> (16 * (kDigits - 1 - d))) & 0xffff;
}

struct Candidate {
  std::uint32_t key;
  std::uint64_t index;
  Vec3f p;
};

bool before(const Candidate& a, const Candidate& b) {
  return a.key < b.key || (a.key == b.key && a.index < b.index);
}

// One range of the level being split.
struct Range {
  int axis = 0;
  std::uint64_t rank = 0;  // of the split point among the keys sharing `prefix`
  int depth = 0;           // digits chosen
  std::array<std::uint32_t, kDigits> prefix{};
  bool collecting = false, done = false;
  Aabb side[2];  // left, right
};

// What one thread gathers in a pass, per range.
struct Gathered {
  std::vector<std::vector<std::uint32_t>> histogram;  // n < 2^32
  std::vector<std::vector<Candidate>> candidates;
  std::vector<std::array<Aabb, 2>> side;
};

class PositionFile {
 public:
  explicit PositionFile(const std::string& path) : path_(path), f_(std::fopen(path.c_str(), "rb")) {
    if (!f_) throw IoError(path + ": cannot open the conversion's position file; check the folder");
  }
  ~PositionFile() { std::fclose(f_); }
  PositionFile(const PositionFile&) = delete;
  PositionFile& operator=(const PositionFile&) = delete;
  void rewind() { std::rewind(f_); }
  void read(Vec3f* out, std::size_t count) {
    if (std::fread(out, sizeof(Vec3f), count, f_) != count) {
      throw IoError(path_ + ": the conversion's position file ends early or cannot be read; "
                    "check the disk and convert again");
    }
  }

 private:
  std::string path_;
  std::FILE* f_;
};

// Each point's range within the level being split (below 2^(levels - 1)), in one byte up to 9
// levels and two up to 17; none kept (kept() false) beyond, for one level (its range is the
// root) or when n of them would take more than `bytes`.
class RangeIds {
 public:
  RangeIds(std::uint64_t n, std::uint32_t levels, std::size_t bytes)
      : wide_(levels > 9) {
    const std::uint64_t width = wide_ ? 2 : 1;
    if (levels >= 2 && levels <= 17 && n * width <= bytes) {
      ids_.resize(static_cast<std::size_t>(n * width), 0);
    }
  }
  bool kept() const { return !ids_.empty(); }
  std::size_t get(std::uint64_t i) const {
    if (!wide_) return ids_[i];
    return ids_[2 * i] | std::size_t{ids_[2 * i + 1]} << 8;
  }
  void set(std::uint64_t i, std::size_t id) {
    if (!wide_) {
      ids_[i] = static_cast<std::uint8_t>(id);
    } else {
      ids_[2 * i] = static_cast<std::uint8_t>(id);
      ids_[2 * i + 1] = static_cast<std::uint8_t>(id >> 8);
    }
  }

 private:
  bool wide_;
  std::vector<std::uint8_t> ids_;
};

}  // namespace

ChunkPlan plan_chunks_on_disk(const std::string& path, std::uint64_t n, const Aabb& box,
                              std::uint32_t levels, const DiskPlanMemory& memory,
                              ThreadPool& pool, Progress& progress) {
  if (n == 0 || n >= (std::uint64_t{1} << 32) || levels > 20 || (levels > 0 && (n >> levels) < 2)) {
    throw Error("cannot plan " + std::to_string(std::size_t{1} << levels) + " chunks over " +
                std::to_string(n) + " points");
  }
  ChunkPlan plan;
  plan.levels = levels;
  plan.splits.resize((std::size_t{1} << levels) - 1);
  PositionFile file(path);
  const std::size_t threads = pool.thread_count();
  const std::size_t window = std::max<std::size_t>(memory.window_points, 1);
  std::vector<Vec3f> buffer(static_cast<std::size_t>(std::min<std::uint64_t>(n, window)));
  const std::size_t max_candidates = std::max<std::size_t>(memory.max_candidates, 1);
  // Ranges whose digits one pass can count (at least one).
  const std::size_t counted_at_once =
      std::max<std::size_t>(memory.histogram_bytes / (threads * kBuckets * 4), 1);

  // Each point's range in its level, kept between passes when it fits: the descent through the
  // splits above, a chain of dependent loads, is most of a pass's time otherwise.
  RangeIds range_of(n, levels, memory.range_id_bytes);
  std::vector<Aabb> boxes{box};
  std::vector<std::uint64_t> counts{n};
  for (std::uint32_t level = 0; level < levels; ++level) {
    const std::size_t ranges = boxes.size();
    const std::size_t first = ranges - 1;  // heap index of the level's first range
    // The level's first pass moves each point's range down from the level above.
    bool ranges_known = level == 0;
    std::vector<Range> r(ranges);
    for (std::size_t j = 0; j < ranges; ++j) {
      r[j].axis = boxes[j].longest_axis();
      r[j].rank = counts[j] / 2;
    }
    for (std::size_t active = ranges; active > 0;) {
      // Candidates kept in one pass, shared among the ranges still open.
      const std::size_t limit = std::max<std::size_t>(max_candidates / active, 1);
      // The ranges this pass serves: every one collecting, and the first ones counting that
      // fit the histograms' memory; the others wait for a later pass.
      std::vector<std::uint8_t> in_pass(ranges, 0);
      for (std::size_t j = 0, counting = 0; j < ranges; ++j) {
        if (r[j].done) continue;
        if (r[j].collecting) {
          in_pass[j] = 1;
        } else if (counting < counted_at_once) {
          in_pass[j] = 1;
          ++counting;
        }
      }
      std::vector<Gathered> g(threads);
      for (Gathered& t : g) {
        t.histogram.resize(ranges);
        t.candidates.resize(ranges);
        t.side.resize(ranges);
        for (std::size_t j = 0; j < ranges; ++j) {
          if (in_pass[j] && !r[j].collecting) t.histogram[j].assign(kBuckets, 0);
        }
      }
      file.rewind();
      for (std::uint64_t at = 0; at < n;) {
        const auto count = static_cast<std::size_t>(std::min<std::uint64_t>(window, n - at));
        file.read(buffer.data(), count);
        pool.run(threads, [&](std::size_t t) {
          Gathered& mine = g[t];
          const std::size_t b = count * t / threads, e = count * (t + 1) / threads;
          for (std::size_t i = b; i < e; ++i) {
            const Vec3f& p = buffer[i];
            const std::uint64_t index = at + i;
            std::size_t j;
            if (!range_of.kept()) {
              j = plan.node_below(p, index, level) - first;
            } else if (ranges_known) {
              j = range_of.get(index);
            } else {
              j = plan.node_below(p, index, 1, (first - 1) / 2 + range_of.get(index)) - first;
              range_of.set(index, j);
            }
            if (!in_pass[j]) continue;
            const Range& range = r[j];
            const float q[3] = {p.x, p.y, p.z};  // indexed without branches on the axis
            const std::uint32_t key = ordered(q[range.axis]);
            int side = -1;  // -1: shares the chosen digits
            for (int d = 0; d < range.depth && side < 0; ++d) {
              const std::uint32_t x = digit(key, index, d);
              if (x != range.prefix[d]) side = x < range.prefix[d] ? 0 : 1;
            }
            if (side >= 0) {
              mine.side[j][side].extend(p);
            } else if (range.collecting) {
              mine.candidates[j].push_back({key, index, p});
            } else {
              ++mine.histogram[j][digit(key, index, range.depth)];
            }
          }
        });
        at += count;
      }
      ranges_known = true;
      // Merge, then choose a digit or select the split for each open range.
      for (std::size_t j = 0; j < ranges; ++j) {
        if (!in_pass[j]) continue;
        Range& range = r[j];
        for (Gathered& t : g) {
          range.side[0].extend(t.side[j][0]);
          range.side[1].extend(t.side[j][1]);
        }
        if (range.collecting) {
          std::vector<Candidate> all;
          for (Gathered& t : g) all.insert(all.end(), t.candidates[j].begin(), t.candidates[j].end());
          if (range.rank >= all.size()) throw Error("chunk plan: the position file changed");
          std::nth_element(all.begin(), all.begin() + std::ptrdiff_t(range.rank), all.end(),
                           before);
          const Candidate& mid = all[range.rank];
          plan.splits[first + j] = {static_cast<std::uint8_t>(range.axis),
                                    mid.p[range.axis] + 0.0f, mid.index};
          for (const Candidate& c : all) range.side[before(c, mid) ? 0 : 1].extend(c.p);
          range.done = true;
          --active;
          continue;
        }
        std::vector<std::uint64_t> h(kBuckets, 0);
        for (Gathered& t : g) {
          for (std::size_t b = 0; b < kBuckets; ++b) h[b] += t.histogram[j][b];
        }
        std::size_t b = 0;
        while (b < kBuckets && range.rank >= h[b]) range.rank -= h[b++];
        if (b == kBuckets) throw Error("chunk plan: the position file changed");
        range.prefix[range.depth++] = static_cast<std::uint32_t>(b);
        // The keys are unique once every digit is chosen, so the last bucket holds one.
        range.collecting = h[b] <= limit || range.depth == kDigits;
      }
    }
    std::vector<Aabb> next_boxes(2 * ranges);
    std::vector<std::uint64_t> next_counts(2 * ranges);
    for (std::size_t j = 0; j < ranges; ++j) {
      next_boxes[2 * j] = r[j].side[0];
      next_boxes[2 * j + 1] = r[j].side[1];
      next_counts[2 * j] = counts[j] / 2;
      next_counts[2 * j + 1] = counts[j] - counts[j] / 2;
    }
    boxes = std::move(next_boxes);
    counts = std::move(next_counts);
    progress.advance(n / levels);
  }
  plan.counts = std::move(counts);
  plan.boxes = std::move(boxes);
  return plan;
}

}  // namespace pointillist::chunking
