// The shared stages of a chunked conversion (see chunk_stages.hpp).
#include "chunk_stages.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>

#include "chunk_messages.hpp"
#include "chunked.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/lod/sphere_tree.hpp"
#include "pointillist/prep/outliers.hpp"

namespace pointillist::chunking {

// Binary levels of the plan: enough chunks for `max_points` each, paired as the hierarchy's
// levels pair (sphere_tree_root_halves), at least one level.
std::uint32_t plan_levels(std::uint64_t n, std::uint64_t max_points) {
  std::uint32_t levels = 1;
  while ((n >> levels) > max_points && levels < 20) ++levels;
  const bool odd = sphere_tree_root_halves(n);
  if ((levels % 2 == 1) != odd) ++levels;
  while (levels > 1 && (n >> levels) < 2) levels -= 2;
  return levels;
}

// Calls fn(chunk, pool) for each of `chunks`, `workers` chunks at a time, each worker with a
// pool of its own (one thread): the serial parts of preparing a chunk (its orientation tree)
// then overlap. Results go to per-chunk slots, so they do not depend on the worker count.
void for_each_chunk(std::span<const std::size_t> chunks, ThreadPool& pool,
                    const std::function<void(std::size_t, ThreadPool&)>& fn) {
  const std::size_t workers = std::min<std::size_t>(pool.thread_count(), chunks.size());
  if (workers <= 1) {
    for (const std::size_t c : chunks) fn(c, pool);
    return;
  }
  std::vector<std::unique_ptr<ThreadPool>> pools;
  for (std::size_t w = 0; w < workers; ++w) pools.push_back(std::make_unique<ThreadPool>(1));
  std::atomic<std::size_t> next{0};
  pool.run(workers, [&](std::size_t w) {
    for (std::size_t k; (k = next.fetch_add(1)) < chunks.size();) fn(chunks[k], *pools[w]);
  });
}

void broadcast_shared(ChunkJobs& jobs, Shared& s) {
  MessageWriter w;
  if (jobs.rank() == 0) {
    w.put(s.n);
    w.put(s.layout);
    w.put(s.colors);
    w.put(s.centroid);
    w.put(s.plan.levels);
    w.put_vector(s.plan.splits);
    w.put_vector(s.plan.counts);
    w.put_vector(s.plan.boxes);
    w.put_vector(s.reach);
    w.put_vector(std::vector<char>(s.input_name.begin(), s.input_name.end()));
  }
  jobs.broadcast(w.bytes());
  if (jobs.rank() == 0) return;
  MessageReader r(w.bytes());
  s.n = r.get<std::uint64_t>();
  s.layout = r.get<RecordLayout>();
  s.colors = r.get<bool>();
  s.centroid = r.get<Vec3f>();
  s.plan.levels = r.get<std::uint32_t>();
  s.plan.splits = r.get_vector<Split>();
  s.plan.counts = r.get_vector<std::uint64_t>();
  s.plan.boxes = r.get_vector<Aabb>();
  s.reach = r.get_vector<float>();
  const auto name = r.get_vector<char>();
  s.input_name.assign(name.begin(), name.end());
}

// Rank 0: the inputs scanned, the plan made, and the chunk files (with halos) written.
void scan_plan_distribute(MergedInputs& in, const WorkFolder& folder, const ConvertOptions& o,
                          std::uint64_t budget, std::uint32_t levels, float halo_factor,
                          ThreadPool& pool, Progress& progress, Shared& sh, ConvertResult& result) {
  const std::uint64_t n = sh.n;
  // The plan holds every position in memory when the budget allows, else it works from a file
  // of them.
  const bool plan_on_disk = n * kPlanBytesPerPoint > budget / 2;

  // The disk must hold the conversion's files at their peak: the positions (for a plan on
  // disk), then the chunk files (each point once, plus its halo copies), which become the
  // prepared splats (43 bytes each), then the splats in split order (31 bytes) as the output is
  // written.
  {
    const double halo_share = 0.1;  // a generous bound: chunks of 1 M points have about 2 %
    const RecordLayout records{in.has_normals(), in.has_radii()};  // at most, before the scan
    const double per_point = std::max({plan_on_disk ? 12.0 : 0.0,
                                       double(records.size()) * (1 + halo_share), 43.0,
                                       31.0 + 12});
    const std::uint64_t chunk = n >> levels;
    const auto need = std::uint64_t(double(n) * per_point + double(chunk) * 43);
    std::error_code error;
    const std::filesystem::space_info space =
        std::filesystem::space(std::filesystem::path(folder.file("")).parent_path(), error);
    if (!error && space.available < need) {
      throw IoError(folder.file("") + ": the chunked conversion needs about " +
                    std::to_string(need / 1000000) + " MB of free disk beside the output, " +
                    std::to_string(space.available / 1000000) +
                    " MB are free; free some space or write the output to another disk");
    }
  }

  // 1. Positions, their box and centroid.
  std::vector<PlanPoint> positions;
  std::optional<ChunkFiles> position_file;
  if (plan_on_disk) {
    position_file.emplace(folder, 1, "positions", std::size_t{1} << 22);
  } else {
    positions.reserve(n);
  }
  double sum[3] = {0, 0, 0};
  Aabb box;
  {
    ProgressPhase phase(progress, "scan", n);
    std::uint64_t seen = 0;
    in.for_each_batch(progress, [&](const PointSet& b, std::uint64_t) {
      for (const Vec3f& p : b.positions) {
        if (!is_finite(p)) {
          throw Error(sh.input_name + ": vertex " + std::to_string(seen) +
                      " has a non-finite position; remove it from the file");
        }
        if (plan_on_disk) {
          position_file->append(0, &p, sizeof p);
        } else {
          positions.push_back({p, static_cast<std::uint32_t>(seen)});
        }
        ++seen;
        box.extend(p);
        sum[0] += p.x;
        sum[1] += p.y;
        sum[2] += p.z;
      }
      phase.advance(b.size());
    });
    if (position_file) position_file->flush_all();
  }
  in.drop_unusable_normals();
  sh.layout = {in.has_normals(), in.has_radii()};
  sh.centroid = {float(sum[0] / double(n)), float(sum[1] / double(n)), float(sum[2] / double(n))};

  // 2. The plan.
  {
    ProgressPhase phase(progress, "plan", n);
    if (plan_on_disk) {
      const std::string path = folder.file(ChunkFiles::name("positions", 0));
      // A quarter of the budget for the selections' candidates (32 bytes each), an eighth for
      // the digit counts (256 KiB a range and thread: 1 B points in 4,096 chunks would count
      // 2 GB at once), a sixteenth for the reads, an eighth for the points' ranges (a byte
      // each up to 512 chunks, else two: 100 M points under 1G, 1 B under 16G).
      const DiskPlanMemory memory{
          .max_candidates = std::max<std::uint64_t>(budget / 4 / 32, 1024),
          .histogram_bytes = budget / 8,
          .window_points = std::clamp<std::uint64_t>(budget / 16 / sizeof(Vec3f), 1 << 16, 1 << 21),
          .range_id_bytes = budget / 8};
      sh.plan = plan_chunks_on_disk(path, n, box, levels, memory, pool, progress);
      std::filesystem::remove(path);
    } else {
      sh.plan = plan_chunks(std::move(positions), levels, pool);
      phase.advance(n);
    }
  }
  std::vector<PlanPoint>().swap(positions);
  const ChunkPlan& plan = sh.plan;
  const std::size_t chunks = plan.chunk_count();
  // Halo reach: a multiple of the chunk's point spacing (its box's two largest extents over its
  // point count, as for a surface), scaled with the neighbourhood size.
  sh.reach.assign(chunks, 0.0f);
  float max_reach = 0;
  const float neighbourhood = std::sqrt(std::max(16.0f, float(o.prepare.k)) / 16.0f);
  for (std::size_t c = 0; c < chunks; ++c) {
    const Vec3f e = plan.boxes[c].hi - plan.boxes[c].lo;
    float x[3] = {e.x, e.y, e.z};
    std::sort(x, x + 3);
    const float spacing = std::sqrt(x[2] * x[1] / float(std::max<std::uint64_t>(plan.counts[c], 1)));
    sh.reach[c] = kHaloSpacings * spacing * neighbourhood * halo_factor;
    max_reach = std::max(max_reach, sh.reach[c]);
  }

  // 3. Distribute.
  ChunkFiles files(folder, chunks, "chunk",
                   ChunkFiles::buffer_bytes(chunks, std::uint64_t{256} << 20, budget));
  // On every thread, in two steps a slice of a batch at a time: each thread finds the chunks of
  // a part of the slice and encodes their records; then each appends the records of its own
  // chunks (c % threads), the parts in order, so that a chunk file holds its points in input
  // order whatever the thread count. A slice's records and their chunks (size + 4 bytes each,
  // halo copies too) take about a 400th of the budget, at most 64 K points' (4-6 MB).
  ProgressPhase phase(progress, "distribute", n);
  const std::size_t threads = pool.thread_count(), size = sh.layout.size();
  struct Staged {
    std::vector<std::uint32_t> chunk;  // of each record
    std::vector<char> records;
    std::uint64_t halo = 0;
  };
  std::vector<Staged> staged(threads);
  const auto slice = static_cast<std::size_t>(
      std::clamp<std::uint64_t>(budget / 512 / (size + 4), 4096, std::size_t{1} << 16));
  in.for_each_batch(progress, [&](const PointSet& b, std::uint64_t first) {
    for (std::size_t lo = 0; lo < b.size(); lo += slice) {
      const std::size_t count = std::min(slice, b.size() - lo);
      pool.run(threads, [&](std::size_t t) {
        Staged& s = staged[t];
        s.chunk.clear();
        s.records.clear();
        const std::size_t begin = lo + count * t / threads, end = lo + count * (t + 1) / threads;
        s.records.reserve((end - begin) * size);  // kept from slice to slice
        const auto add = [&](std::uint32_t c) {  // the new record's offset
          s.chunk.push_back(c);
          s.records.resize(s.records.size() + size);
          return s.records.size() - size;
        };
        std::uint32_t own[ChunkPlan::kBatch];
        bool near_a_split[ChunkPlan::kBatch];
        for (std::size_t i0 = begin; i0 < end; i0 += ChunkPlan::kBatch) {
          const std::size_t batch = std::min(ChunkPlan::kBatch, end - i0);
          plan.chunks_of(&b.positions[i0], batch, first + i0, max_reach, own, near_a_split);
          for (std::size_t e = 0; e < batch; ++e) {
            const std::size_t i = i0 + e;
            const std::size_t at = add(own[e]);
            encode_record(sh.layout, b, i, first + i, false, &s.records[at]);
            if (!near_a_split[e]) continue;
            plan.for_near_chunks(b.positions[i], own[e], sh.reach, max_reach, [&](std::uint32_t c) {
              const std::size_t copy = add(c);
              std::memcpy(&s.records[copy], &s.records[at], size);
              s.records[copy + 15] = 1;  // a halo point
              ++s.halo;
            });
          }
        }
      });
      pool.run(threads, [&](std::size_t t) {
        for (const Staged& s : staged) {
          for (std::size_t k = 0; k < s.chunk.size(); ++k) {
            if (s.chunk[k] % threads == t) files.append(s.chunk[k], &s.records[k * size], size);
          }
        }
      });
    }
    phase.advance(b.size());
  });
  for (const Staged& s : staged) result.halo_points += s.halo;
  files.flush_all();
}

RankChunks rank_chunks(const ChunkJobs& jobs, const ChunkPlan& plan) {
  RankChunks r;
  const std::size_t chunks = plan.chunk_count();
  for (std::size_t c = std::size_t(jobs.rank()); c < chunks; c += std::size_t(jobs.size())) {
    r.chunks.push_back(c);
    r.points += plan.counts[c];
  }
  return r;
}

std::vector<std::uint64_t> find_outliers_in_chunks(ChunkJobs& jobs, MergedInputs* in,
                                                   const WorkFolder& folder,
                                                   const ConvertOptions& o,
                                                   std::uint64_t max_chunk_points,
                                                   const std::string& input_name,
                                                   ThreadPool& pool, Progress& progress) {
  const bool root = jobs.rank() == 0;
  const std::uint64_t budget = o.memory_budget ? o.memory_budget : default_memory_budget();
  Shared sh;
  sh.input_name = input_name;
  step(jobs, [&] {
    if (!root) return;
    sh.n = in->count();
    const std::uint32_t levels = plan_levels(sh.n, std::max<std::uint64_t>(max_chunk_points, 2));
    ConvertResult scratch;  // this pass's halo is not the conversion's
    scan_plan_distribute(*in, folder, o, budget, levels, kOutlierHaloFactor, pool, progress, sh,
                         scratch);
  });
  broadcast_shared(jobs, sh);
  const std::size_t chunks = sh.plan.chunk_count();
  const RankChunks rank_share = rank_chunks(jobs, sh.plan);
  const std::vector<std::size_t>& mine = rank_share.chunks;
  const std::uint64_t my_points = rank_share.points;
  std::vector<std::vector<std::uint64_t>> dropped(chunks);
  step(jobs, [&] {
    ProgressPhase phase(progress, "outliers", my_points);
    for_each_chunk(mine, pool, [&](std::size_t c, ThreadPool& chunk_pool) {
      const std::string path = folder.file(ChunkFiles::name("chunk", c));
      std::vector<std::uint8_t> own;
      std::vector<std::uint64_t> index;
      const PointSet points = read_chunk(path, sh.layout, sh.colors, own, index);
      std::filesystem::remove(path);
      const std::vector<std::uint8_t> outlier = find_outliers(
          points.positions, chunk_pool, Progress::none(), {.ratio = o.prepare.outlier_ratio_drop});
      for (std::size_t i = 0; i < outlier.size(); ++i) {
        if (own[i] && outlier[i]) dropped[c].push_back(index[i]);
      }
      phase.advance(sh.plan.counts[c]);
    });
  });
  MessageWriter w;
  for (const std::size_t c : mine) w.put_vector(dropped[c]);
  const std::vector<std::vector<char>> all = jobs.gather(w.bytes());
  std::vector<std::uint64_t> out;
  step(jobs, [&] {
    if (!root) return;
    for (const std::size_t c : mine) out.insert(out.end(), dropped[c].begin(), dropped[c].end());
    for (std::size_t r = 1; r < all.size(); ++r) {
      MessageReader m(all[r]);
      while (!m.done()) {
        const std::vector<std::uint64_t> part = m.get_vector<std::uint64_t>();
        for (const std::uint64_t i : part) {
          if (i >= sh.n) throw Error("chunked conversion: a rank sent an outlier out of range");
          out.push_back(i);
        }
      }
    }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
  });
  return out;
}

}  // namespace pointillist::chunking
