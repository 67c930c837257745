// The stages of a chunked conversion that every pass shares (private to pipeline; see
// chunked_convert.cpp): the plan's levels, chunk workers, what rank 0 tells every rank, the
// step that settles the ranks, scan-plan-distribute, and the outlier pass of --drop-outliers.
#pragma once

#include <cstdint>
#include <exception>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "chunk_files.hpp"
#include "chunk_inputs.hpp"
#include "chunk_plan.hpp"
#include "pointillist/core/progress.hpp"
#include "pointillist/core/thread_pool.hpp"
#include "pointillist/pipeline/chunk_jobs.hpp"
#include "pointillist/pipeline/convert.hpp"

namespace pointillist::chunking {

// Binary levels of the plan: enough chunks for `max_points` each, paired as the hierarchy's
// levels pair (sphere_tree_root_halves), at least one level.
std::uint32_t plan_levels(std::uint64_t n, std::uint64_t max_points);

// Calls fn(chunk, pool) for each of `chunks`, `workers` chunks at a time, each worker with a
// pool of its own (one thread): the serial parts of preparing a chunk (its orientation tree)
// then overlap. Results go to per-chunk slots, so they do not depend on the worker count.
void for_each_chunk(std::span<const std::size_t> chunks, ThreadPool& pool,
                    const std::function<void(std::size_t, ThreadPool&)>& fn);

// What rank 0 learns from the inputs and the plan, and every rank needs.
struct Shared {
  std::uint64_t n = 0;
  RecordLayout layout;
  bool colors = false;
  Vec3f centroid;
  ChunkPlan plan;
  std::vector<float> reach;  // halo reach of each chunk
  std::string input_name;    // for messages
};

void broadcast_shared(ChunkJobs& jobs, Shared& s);

// The chunks this rank prepares (c % size == rank) and their share of the points.
struct RankChunks {
  std::vector<std::size_t> chunks;
  std::uint64_t points = 0;
};
RankChunks rank_chunks(const ChunkJobs& jobs, const ChunkPlan& plan);

// Runs fn, then settles with the other ranks: every rank throws when one failed.
template <class Fn>
void step(ChunkJobs& jobs, Fn&& fn) {
  std::exception_ptr error;
  try {
    fn();
  } catch (...) {
    error = std::current_exception();
  }
  jobs.settle(error);
}

// Rank 0: the inputs scanned, the plan made, and the chunk files (with halos reaching
// halo_factor times kHaloSpacings point spacings) written.
void scan_plan_distribute(MergedInputs& in, const WorkFolder& folder, const ConvertOptions& o,
                          std::uint64_t budget, std::uint32_t levels, float halo_factor,
                          ThreadPool& pool, Progress& progress, Shared& sh, ConvertResult& result);

// The outlier pass of --drop-outliers, before the real one: the inputs are planned and
// distributed with a halo twice as wide (kOutlierHaloFactor), each chunk judges its own points
// among its and its halo's (find_outliers), and rank 0 learns the outliers' input indices, in
// order; their chunk files are gone afterwards. The real pass then skips them, so the chunks
// are cut from the points the conversion in one piece keeps (MergedInputs::drop).
// `in`: rank 0's inputs (null elsewhere); `input_name` names them in messages.
std::vector<std::uint64_t> find_outliers_in_chunks(ChunkJobs& jobs, MergedInputs* in,
                                                   const WorkFolder& folder,
                                                   const ConvertOptions& o,
                                                   std::uint64_t max_chunk_points,
                                                   const std::string& input_name,
                                                   ThreadPool& pool, Progress& progress);

}  // namespace pointillist::chunking
