// The sharp-features section of .ptl version 2 (docs/ptl-format.md, "Sharp features"): the
// leaves' surface ids (run-length coded) and clip planes, with the options and statistics they
// were computed with. Private to the format module.
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "pointillist/features/features.hpp"
#include "pointillist/lod/pages.hpp"
#include "pointillist/lod/sphere_tree.hpp"
#include "pointillist/lod/tree_features.hpp"

namespace pointillist::ptl2 {

// compat_flags bit 1: the header holds the offset and size of a features section (readers that
// do not know it read the file without features).
constexpr std::uint32_t kCompatFeatures = 1u << 1;
constexpr std::uint32_t kFeaturesOffsetAt = 232;  // u64
constexpr std::uint32_t kFeaturesSizeAt = 240;    // u64

// The section (version 2) for the tree `nodes` with per-node `features`, written as pages
// whose node indices, in page order, are `pages[p]`.
std::vector<std::uint8_t> encode_features(std::span<const SphereNode> nodes,
                                          const TreeFeatures& features,
                                          std::span<const std::span<const std::uint32_t>> pages);

// The section's fixed fields and, in version 2, its block table; read once, then used to
// decode the leaves (version 1) or a page's block (version 2).
struct FeatureSection {
  std::uint32_t version = 0;  // 1: the leaves in node order; 2: a block per page
  FeatureOptions options;
  FeatureStats stats;
  std::uint32_t surfaces = 0;
  std::vector<std::uint64_t> blocks;  // version 2: page p's block is [blocks[p], blocks[p+1])
  std::vector<std::uint32_t> clipped, planes;  // version 2: per page
  std::uint64_t body = 0;             // version 1: where the runs of surface ids start
};

// The fixed fields of the section `bytes`, which starts at byte `at` of the file `path`, for a
// model of `leaf_count` leaves in `page_count` pages: checks the signature, version, options,
// counts and (version 2) that the blocks follow each other inside the section. Throws
// FormatError "<path>: byte <offset>: <what>".
FeatureSection decode_feature_header(std::string_view bytes, std::uint64_t at,
                                     std::uint64_t leaf_count, std::uint32_t page_count,
                                     const std::string& path);

// Version 1: the leaves' features (in node order). Checks every count against the bytes left,
// ids against the surface count, leaf indices, plane counts and modes, finite planes.
FeatureData decode_leaf_features(std::string_view bytes, std::uint64_t at,
                                 const FeatureSection& section, std::uint64_t leaf_count,
                                 const std::string& path);

// Version 2: the features of page `page`'s `node_count` nodes (page order). `is_leaf(k)` says
// whether node k is a leaf: leaves need a surface id below the surface count, only leaves may
// have planes. Checks as decode_leaf_features does.
void decode_page_features(std::string_view bytes, std::uint64_t at,
                          const FeatureSection& section, std::uint32_t page,
                          std::uint32_t node_count,
                          const std::function<bool(std::uint32_t)>& is_leaf,
                          const std::string& path, PageFeatures& out);

}  // namespace pointillist::ptl2
