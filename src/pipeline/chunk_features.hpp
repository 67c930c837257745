// Sharp features of a model converted in chunks (private to pipeline; see chunk_features.cpp).
#pragma once

#include <string>
#include <vector>

#include "chunk_files.hpp"
#include "pointillist/core/progress.hpp"
#include "pointillist/core/thread_pool.hpp"
#include "pointillist/features/features.hpp"
#include "pointillist/format/ptl_v2.hpp"

namespace pointillist::chunking {

// Finds the sharp features of the file `writer` laid out and finished uncommitted, on its leaves
// as they decode (as the conversion in one piece does), part by part: each subtree below the top
// page is a part, with a halo of other parts' leaves found by walking the pages; then writes them
// after `metadata` (which gains the line the conversion in one piece writes) and commits the
// file. Per-leaf results wait in `folder` between the passes. Adds the noisy-features warning to
// `warnings` when it applies. Throws what reading and writing throw.
void add_features_in_parts(PtlV2PartWriter& writer, const WorkFolder& folder,
                           const std::string& metadata, const FeatureOptions& options,
                           ThreadPool& pool, Progress& progress,
                           std::vector<std::string>& warnings);

}  // namespace pointillist::chunking
