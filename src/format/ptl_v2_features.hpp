// The sharp-features section of .ptl version 2 (docs/ptl-format.md, "Sharp features"): the
// leaves' surface ids (run-length coded) and clip planes, with the options and statistics they
// were computed with. Private to the format module.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "pointillist/features/features.hpp"
#include "pointillist/lod/sphere_tree.hpp"
#include "pointillist/lod/tree_features.hpp"

namespace pointillist::ptl2 {

// compat_flags bit 1: the header holds the offset and size of a features section (readers that
// do not know it read the file without features).
constexpr std::uint32_t kCompatFeatures = 1u << 1;
constexpr std::uint32_t kFeaturesOffsetAt = 232;  // u64
constexpr std::uint32_t kFeaturesSizeAt = 240;    // u64

// The section for the leaves of `nodes` (in node order) from per-node `features`.
std::vector<std::uint8_t> encode_features(std::span<const SphereNode> nodes,
                                          const TreeFeatures& features);

// The leaves' features from the section `bytes` (which starts at byte `at` of the file `path`),
// for a model of `leaf_count` leaves. Checks every count against the bytes left, ids against
// the surface count, leaf indices, plane counts and modes, finite planes. Throws FormatError
// "<path>: byte <offset>: <what>".
FeatureData decode_features(std::string_view bytes, std::uint64_t at, std::uint64_t leaf_count,
                            const std::string& path);

}  // namespace pointillist::ptl2
