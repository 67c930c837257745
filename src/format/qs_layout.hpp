// Byte layout of QSplat .qs 1.1 files (spec ../shared/specs/qsplat-qs-format.md §1-3): big-endian
// fields, fragment headers and node records. Private to the format module.
#pragma once

#include <bit>
#include <cstdint>
#include <cstring>
#include <vector>

#include "pointillist/core/math.hpp"
#include "pointillist/lod/sphere_tree.hpp"

namespace pointillist::qs_detail {

constexpr char kMagic[6] = {'Q', 'S', 'p', 'l', 'a', 't'};
constexpr char kVersion[2] = {'1', '1'};
constexpr std::uint32_t kTreeHeaderSize = 40;
constexpr std::uint32_t kCommentHeaderSize = 20;

// Field offsets inside a fragment header (spec §2.1).
namespace offset {
constexpr std::uint32_t kVersion = 6;
constexpr std::uint32_t kLength = 8;
constexpr std::uint32_t kLeafCount = 12;
constexpr std::uint32_t kOptions = 16;
constexpr std::uint32_t kCenter = 20;
constexpr std::uint32_t kRadius = 32;
constexpr std::uint32_t kRootChildren = 36;
}  // namespace offset

inline std::uint16_t load_be16(const std::uint8_t* p) {
  return static_cast<std::uint16_t>(p[0] << 8 | p[1]);
}
inline std::uint32_t load_be32(const std::uint8_t* p) {
  return std::uint32_t(p[0]) << 24 | std::uint32_t(p[1]) << 16 | std::uint32_t(p[2]) << 8 | p[3];
}
inline float load_be_float(const std::uint8_t* p) { return std::bit_cast<float>(load_be32(p)); }

// "QSplat11": the magic and version that open every fragment.
inline void append_magic(std::vector<std::uint8_t>& out) {
  for (const char c : kMagic) out.push_back(static_cast<std::uint8_t>(c));
  for (const char c : kVersion) out.push_back(static_cast<std::uint8_t>(c));
}
inline void append_be16(std::vector<std::uint8_t>& out, std::uint16_t v) {
  out.push_back(static_cast<std::uint8_t>(v >> 8));
  out.push_back(static_cast<std::uint8_t>(v));
}
inline void append_be32(std::vector<std::uint8_t>& out, std::uint32_t v) {
  for (int shift = 24; shift >= 0; shift -= 8) out.push_back(static_cast<std::uint8_t>(v >> shift));
}
inline void append_be_float(std::vector<std::uint8_t>& out, float v) {
  append_be32(out, std::bit_cast<std::uint32_t>(v));
}

// Child-count code C of a record (spec §3.2): 0 = leaf, 1..3 = 2..4 children.
constexpr std::uint32_t child_count_of_code(std::uint32_t c) { return c == 0 ? 0 : c + 1; }

// A decoded fragment tree, breadth-first with fragment-local indices: node 0 is the root (the
// header sphere), records follow in file order. level_start[j] is the index of the first node
// j levels below the root; level_start.back() == nodes.size().
struct DecodedTree {
  std::vector<SphereNode> nodes;
  std::vector<std::size_t> level_start;
  bool has_colors = false;
};

}  // namespace pointillist::qs_detail
