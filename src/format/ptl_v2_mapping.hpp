// What a PtlV2File keeps of its file: the mapped bytes and, read on first use, the fixed fields
// of its sharp-features section. Private to the format module.
#pragma once

#include <atomic>
#include <cstdint>
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
  // Bytes of pages copied out since the mapping was last let go of (PtlV2File::forget_page).
  std::atomic<std::uint64_t> copied_since_forget{0};
};

// How many bytes of copied pages a PtlV2File lets stay mapped before it lets go of them all.
inline constexpr std::uint64_t kForgetBytes = 64 << 20;

}  // namespace pointillist
