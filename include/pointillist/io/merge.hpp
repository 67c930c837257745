// Several scans read as one point set: tiles of a survey, parts of a model.
#pragma once

#include <span>
#include <string>
#include <vector>

#include "pointillist/core/point_set.hpp"
#include "pointillist/core/progress.hpp"
#include "pointillist/core/thread_pool.hpp"

namespace pointillist {

struct MergeOptions {
  // Column layout for text inputs (e.g. "x,y,z,skip,r,g,b"); empty = detected per file.
  std::string columns;
};

// Reads and merges one or more scan files (any extension read_point_file knows: PLY, XYZ/PTS/CSV
// text, OBJ, LAS). Parts whose readers shifted coordinates to a local origin (LAS, large text
// coordinates) are moved into the first part's frame, so tiles of one scan line up; the merged
// set keeps the first part's "origin:" comment. An attribute (normals, radii) survives only when
// every part has it; colors survive when any part has them (parts without get a neutral grey,
// and `warnings`, when not null, says which). Comments repeated by several parts are kept once.
// Throws IoError for a missing file and what the readers throw.
PointSet merge_inputs(std::span<const std::string> paths, ThreadPool& pool, Progress& progress,
                      const MergeOptions& options = {},
                      std::vector<std::string>* warnings = nullptr);

}  // namespace pointillist
