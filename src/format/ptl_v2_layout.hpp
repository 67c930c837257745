// Byte layout of .ptl version 2 (docs/ptl-format.md, "Version 2"): header fields, attribute
// schema, page-table entries, little-endian loads and stores. Private to the format module.
#pragma once

#include <bit>
#include <cstdint>
#include <cstring>

#include "pointillist/core/math.hpp"
#include "pointillist/lod/quantization.hpp"

namespace pointillist::ptl2 {

using namespace pointillist::quant;  // NOLINT(google-build-using-namespace): the record layout

constexpr std::uint32_t kHeaderSize = 256;
constexpr std::uint32_t kEndianMarker = 0x01020304;  // stored little-endian: 04 03 02 01
constexpr std::uint32_t kFlagHasColors = 1u << 0;
constexpr std::uint32_t kKnownFlags = kFlagHasColors;
// compat_flags bit 0: the header holds the model's coordinate frame (origin, up axis).
constexpr std::uint32_t kCompatFrame = 1u << 0;
constexpr std::uint32_t kPageEntrySize = 32;
constexpr std::uint32_t kRootEntrySize = 17;  // f32 centre x, y, z, radius; u8 child count
constexpr std::uint32_t kMinPageBytes = 1024;
constexpr std::uint32_t kMaxAttributes = 6;

namespace offset {
constexpr std::uint32_t kVersion = 8;
constexpr std::uint32_t kHeaderSize = 12;
constexpr std::uint32_t kEndian = 16;
constexpr std::uint32_t kFlags = 20;
constexpr std::uint32_t kCompatFlags = 24;
constexpr std::uint32_t kRecordSize = 28;
constexpr std::uint32_t kNodeCount = 32;
constexpr std::uint32_t kLeafCount = 40;
constexpr std::uint32_t kDepth = 48;
constexpr std::uint32_t kPageCount = 52;
constexpr std::uint32_t kPageTableOffset = 56;
constexpr std::uint32_t kMetadataOffset = 64;
constexpr std::uint32_t kMetadataSize = 72;
constexpr std::uint32_t kRootSphere = 80;
constexpr std::uint32_t kBoundsLo = 96;
constexpr std::uint32_t kBoundsHi = 108;
constexpr std::uint32_t kViewCenter = 120;
constexpr std::uint32_t kViewRadius = 132;
constexpr std::uint32_t kPageBytes = 136;
constexpr std::uint32_t kAttributeCount = 140;
constexpr std::uint32_t kAttributes = 144;  // kMaxAttributes entries of 8 bytes
constexpr std::uint32_t kOrigin = 192;      // f64[3], with kCompatFrame (else zeros)
constexpr std::uint32_t kUp = 216;          // f32[3], with kCompatFrame (else zeros)
constexpr std::uint32_t kReserved = 228;    // up to 256: zeros
}  // namespace offset

// Attribute table entry: u16 attribute, u16 encoding, u8 first bit, u8 bit count, u16 zero.
struct Attribute {
  std::uint16_t attribute = 0;
  std::uint16_t encoding = 0;
  std::uint8_t first_bit = 0;
  std::uint8_t bit_count = 0;
};
enum AttributeId : std::uint16_t {
  kAttrSphere = 1,    // encoding 1: QSplat 13-bit sphere code relative to the decoded parent
  kAttrChildren = 2,  // encoding 1: 0 leaf, 1..3 = 2..4 children
  kAttrNormal = 3,    // encoding 1: QSplat 14-bit cube-face normal code
  kAttrCone = 4,      // encoding 1: QSplat 2-bit cone code
  kAttrColor = 5,     // encoding 1: RGB 565, bit-replicated on decoding
  // encoding 1: the low bit of a leaf's radius trim, whose high bits are the cone bits: the trim
  // counts sixteenths of the decoded radius (without this attribute: the cone bits, eighths).
  // Interior nodes keep the bit 0.
  kAttrLeafTrimLow = 6,
};

// A record is a little-endian integer of 4 bytes (6 with colour): the packed node record of
// lod/quantization.hpp in bits 0..31, then RGB 565 in bits 32..47 with colours.
constexpr unsigned kColorShift = 32, kColorBits = 16;

// The attribute table of a file with (or without) colours, whose leaves keep their radius trim
// in eighths (the first version 2 files) or sixteenths (kAttrLeafTrimLow present).
struct Schema {
  Attribute entries[kMaxAttributes];
  std::uint32_t count = 0;
};
inline Schema schema(bool colors, LeafTrim trim) {
  Schema s{{{kAttrSphere, 1, kSphereShift, kSphereBits},
            {kAttrChildren, 1, kChildShift, kChildBits},
            {kAttrNormal, 1, kNormalShift, kNormalBits},
            {kAttrCone, 1, kConeShift, kConeBits}},
           4};
  if (colors) s.entries[s.count++] = {kAttrColor, 1, kColorShift, kColorBits};
  if (trim == LeafTrim::Sixteenths) s.entries[s.count++] = {kAttrLeafTrimLow, 1, kLowTrimShift, 1};
  return s;
}

inline void store_u16(std::uint8_t* p, std::uint16_t v) {
  p[0] = static_cast<std::uint8_t>(v);
  p[1] = static_cast<std::uint8_t>(v >> 8);
}
inline void store_u32(std::uint8_t* p, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
inline void store_u64(std::uint8_t* p, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
inline void store_f32(std::uint8_t* p, float v) { store_u32(p, std::bit_cast<std::uint32_t>(v)); }
inline void store_f64(std::uint8_t* p, double v) { store_u64(p, std::bit_cast<std::uint64_t>(v)); }
inline void store_vec(std::uint8_t* p, Vec3f v) {
  store_f32(p, v.x);
  store_f32(p + 4, v.y);
  store_f32(p + 8, v.z);
}
inline std::uint16_t load_u16(const std::uint8_t* p) {
  return static_cast<std::uint16_t>(p[0] | p[1] << 8);
}
inline std::uint32_t load_u32(const std::uint8_t* p) {
  std::uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= std::uint32_t{p[i]} << (8 * i);
  return v;
}
inline std::uint64_t load_u64(const std::uint8_t* p) {
  std::uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v |= std::uint64_t{p[i]} << (8 * i);
  return v;
}
inline float load_f32(const std::uint8_t* p) { return std::bit_cast<float>(load_u32(p)); }
inline double load_f64(const std::uint8_t* p) { return std::bit_cast<double>(load_u64(p)); }
inline Vec3f load_vec(const std::uint8_t* p) {
  return {load_f32(p), load_f32(p + 4), load_f32(p + 8)};
}

}  // namespace pointillist::ptl2
