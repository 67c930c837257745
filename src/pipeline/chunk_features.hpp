// Sharp features of a model converted in chunks (private to pipeline; see chunk_features.cpp).
#pragma once

#include <string>
#include <vector>

#include "chunk_files.hpp"
#include "pointillist/core/progress.hpp"
#include "pointillist/core/thread_pool.hpp"
#include "pointillist/features/features.hpp"
#include "pointillist/format/ptl_v2.hpp"
#include "pointillist/pipeline/chunk_jobs.hpp"

namespace pointillist::chunking {

// Finds the sharp features of the file `writer` laid out and finished uncommitted, on its leaves
// as they decode (as the conversion in one piece does), part by part: each subtree below the top
// page is a part, with a halo of other parts' leaves found by walking the pages; then writes them
// after `metadata` (which gains the line the conversion in one piece writes) and commits the
// file. Every rank of `jobs` calls it at the same step and finds the parts k with
// k % size == rank (rank 0 passes its writer, the others null; they read the file rank 0 synced,
// through the shared folder); rank 0 joins them and writes. Per-leaf results wait in `folder`
// between the passes. Adds the noisy-features warning to `warnings` (rank 0) when it applies.
// Throws what reading and writing throw; every rank throws when one fails.
void add_features_in_parts(ChunkJobs& jobs, PtlV2PartWriter* writer, const WorkFolder& folder,
                           const std::string& metadata, const FeatureOptions& options,
                           ThreadPool& pool, Progress& progress,
                           std::vector<std::string>& warnings);

}  // namespace pointillist::chunking
