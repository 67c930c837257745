// The fixed 256-byte header of a .ptl file (docs/ptl-format.md), encoded and decoded field by
// field in little-endian order, so the layout does not depend on struct padding or the host.
// Private to the format module.
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "pointillist/core/math.hpp"

namespace pointillist::ptl {

constexpr std::size_t kHeaderSize = 256;
constexpr std::uint32_t kNodeSize = 40;
constexpr std::uint64_t kNodeAlignment = 64;
constexpr char kMagic[8] = {'P', 'T', 'L', 'S', 'P', 'L', 'A', 'T'};

// `flags`: features a reader must understand; a reader rejects a file with a bit it does not know.
constexpr std::uint32_t kFlagHasColors = 1u << 0;
constexpr std::uint32_t kKnownFlags = kFlagHasColors;
// `compat_flags`: optional features; a reader ignores bits it does not know. None in version 1.

// Byte offsets of the header fields.
namespace offset {
constexpr std::size_t kMagic = 0;
constexpr std::size_t kVersion = 8;
constexpr std::size_t kHeaderSize = 12;
constexpr std::size_t kFlags = 16;
constexpr std::size_t kNodeSize = 20;
constexpr std::size_t kNodeCount = 24;
constexpr std::size_t kLeafCount = 32;
constexpr std::size_t kDepth = 40;
constexpr std::size_t kCompatFlags = 44;
constexpr std::size_t kBoundsLo = 48;
constexpr std::size_t kBoundsHi = 60;
constexpr std::size_t kViewCenter = 72;
constexpr std::size_t kViewRadius = 84;
constexpr std::size_t kNodesOffset = 88;
constexpr std::size_t kMetadataOffset = 96;
constexpr std::size_t kMetadataSize = 104;
constexpr std::size_t kReserved = 112;  // up to kHeaderSize: zero in version 1
}  // namespace offset

struct Header {
  std::uint32_t version = 0;
  std::uint32_t header_size = 0;
  std::uint32_t flags = 0;
  std::uint32_t node_size = 0;
  std::uint64_t node_count = 0;
  std::uint64_t leaf_count = 0;
  std::uint32_t depth = 0;
  std::uint32_t compat_flags = 0;
  Aabb bounds;
  Sphere view_sphere;
  std::uint64_t nodes_offset = 0;
  std::uint64_t metadata_offset = 0;
  std::uint64_t metadata_size = 0;
};

// Header bytes with the magic, the fields of `h`, and zeros in the reserved area.
std::array<std::uint8_t, kHeaderSize> encode_header(const Header& h);
// Fields of a header; `bytes` holds at least kHeaderSize bytes. Does not check the magic.
Header decode_header(const std::uint8_t* bytes);

// Throws FormatError "PATH: byte BYTE: WHAT" (the readers of both .ptl versions).
[[noreturn]] void fail_at(const std::string& path, std::uint64_t byte, const std::string& what);

}  // namespace pointillist::ptl
