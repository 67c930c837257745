// What a PtlV2File keeps of its file: the mapped bytes and, read on first use, the fixed fields
// of its sharp-features section. Private to the format module.
#pragma once

#include <mutex>

#include "ptl_v2_features.hpp"
#include "pointillist/core/file_bytes.hpp"
#include "pointillist/format/ptl_v2.hpp"

namespace pointillist {

struct PtlV2File::Mapping {
  FileBytes bytes;
  std::once_flag features_once;
  ptl2::FeatureSection features;
  TreeFeatures summary;  // surface count, options, statistics
};

}  // namespace pointillist
