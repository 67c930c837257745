// QSplat's quantization (Rusinkiewicz & Levoy, SIGGRAPH 2000; tables as
// ../shared/specs/qsplat-qs-format.md §4-7 give them) and the packed node record built on it:
// a node's sphere as one of 7,621 spheres relative to its decoded parent (13 bits), its normal
// as one of 16,224 cube-face directions (14 bits), its normal cone in 2 bits and its colour in
// RGB 565. Decoding is a few table lookups and multiply-adds, cheap enough to run during a
// traversal, so a hierarchy kept in this form never needs to be decoded whole. Used by the .qs
// and .ptl version 2 files (format) and by the paged renderer (render).
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>

#include "pointillist/core/math.hpp"
#include "pointillist/lod/sphere_tree.hpp"

namespace pointillist::quant {

// ---- 13-bit sphere codes (spec §4) ----

constexpr int kSphereGrid = 13;
constexpr std::uint32_t kSphereCodeCount = 7621;

// Candidate sphere in parent units: centre offset (x, y, z) and radius r.
struct SphereCandidate {
  float x = 0, y = 0, z = 0, r = 0;
};

// The 7621 candidates, indexed by code: m (cube size in cells, 1..13) outermost, then the low
// cell x, y, z; cubes whose circumsphere misses the unit ball are skipped (spec §4.1).
std::span<const SphereCandidate, kSphereCodeCount> sphere_table();

// Code of the cube of m cells with low cell (x, y, z), or -1 when that cube is not in the table
// (out of range or skipped).
int sphere_code(int m, int x, int y, int z);
// sphere_code's table for searches that look up many codes: entry ((m * 13 + x) * 13 + y) * 13
// + z for m in 1..13 and x, y, z in 0..13 - m (-1 where the cube is skipped).
std::span<const std::int16_t> sphere_code_table();

// Decoded sphere of candidate `s` relative to the decoded parent sphere (spec §4.2): float32,
// each component multiplied then added, so every reader and writer of a format built on these
// codes (.qs, .ptl version 2, the paged renderer) computes the same bits.
inline Sphere decode_sphere(const Sphere& parent, const SphereCandidate& s) {
  return {{parent.center.x + parent.radius * s.x, parent.center.y + parent.radius * s.y,
           parent.center.z + parent.radius * s.z},
          parent.radius * s.r};
}
inline Sphere decode_sphere(const Sphere& parent, std::uint32_t code) {
  return decode_sphere(parent, sphere_table()[code]);
}

// ---- 14-bit normal codes (spec §5) ----

constexpr int kNormalGrid = 52;
constexpr std::uint32_t kNormalCodeCount = 6 * kNormalGrid * kNormalGrid;  // 16224

// Unit normals of all codes 0..16223 (grid corners that are not on the sphere, never written,
// clamped onto it). Codes >= 16224 mean (0, 0, 1) in QSplat 1.0.
std::span<const Vec3f, kNormalCodeCount> normal_table();

// Code of a unit normal (the cube-face grid on atan of the components, spec §5.2; no dither).
std::uint32_t encode_normal(Vec3f n);
// The same code without atan: each component's cell is the number of cell boundaries at or
// below it, the boundaries (the least value of each cell 1..51) found once by bisection over
// encode_normal's own cell function. That function is non-decreasing in its input (checked over
// every float with this C library's atanf), so the codes are the same.
std::uint32_t encode_normal_by_bounds(Vec3f n);

// ---- 2-bit normal cone codes (spec §6) ----

// Upper bound on sin θ that code k (0..2) promises: ((k + 1)/4)². Code 3 means "no bound".
constexpr float cone_sin_bound(std::uint32_t k) {
  return float((k + 1) * (k + 1)) / 16.0f;
}

// ---- RGB 565 (spec §7) ----

constexpr std::uint16_t encode_rgb565(Rgb8 c) {
  return static_cast<std::uint16_t>((c.r >> 3) << 11 | (c.g >> 2) << 5 | (c.b >> 3));
}
constexpr Rgb8 decode_rgb565(std::uint16_t w) {
  const unsigned r5 = w >> 11, g6 = (w >> 5) & 63, b5 = w & 31;
  return {static_cast<std::uint8_t>(r5 << 3 | r5 >> 2),
          static_cast<std::uint8_t>(g6 << 2 | g6 >> 4),
          static_cast<std::uint8_t>(b5 << 3 | b5 >> 2)};
}

// ---- The packed node record (.ptl version 2, docs/ptl-format.md) ----
//
// 32 bits, fields from bit 0 up: sphere code (13 bits, relative to the decoded parent), child
// count (2 bits: 0 leaf, 1..3 = 2..4 children), bit 15 (interior nodes: 0; leaves: the low bit
// of the radius trim when the file says so), normal code (14 bits), and 2 bits that are the
// cone code of an interior node and the radius trim of a leaf. Colour, when present, is a
// separate 16-bit RGB 565 word.

constexpr unsigned kSphereShift = 0, kSphereBits = 13;
constexpr unsigned kChildShift = 13, kChildBits = 2;
constexpr unsigned kLowTrimShift = 15;  // 1 bit
constexpr unsigned kNormalShift = 16, kNormalBits = 14;
constexpr unsigned kConeShift = 30, kConeBits = 2;

constexpr std::uint32_t bits(std::uint32_t record, unsigned shift, unsigned count) {
  return (record >> shift) & ((std::uint32_t{1} << count) - 1);
}
// A record's child count: 0 (leaf) or 2..4.
constexpr std::uint32_t record_child_count(std::uint32_t record) {
  const std::uint32_t c = bits(record, kChildShift, kChildBits);
  return c == 0 ? 0 : c + 1;
}

// cone_sin of a decoded interior node whose cone code is 3 ("no bound").
constexpr float kNoConeBound = 2.0f;
// cone_sin an interior node gets for cone code k.
constexpr float decoded_cone_sin(std::uint32_t k) {
  return k < 3 ? cone_sin_bound(k) : kNoConeBound;
}

// How a leaf's radius trim is stored: in its 2 cone bits, steps of 1/8 (t = 0..3), or in the
// cone bits and bit 15, steps of 1/16 (t = 0..7). The file's schema says which.
enum class LeafTrim : std::uint8_t { Eighths, Sixteenths };

// A leaf's trim code t from its record.
constexpr std::uint32_t leaf_trim_code(std::uint32_t record, LeafTrim trim) {
  const std::uint32_t high = bits(record, kConeShift, kConeBits);
  return trim == LeafTrim::Eighths ? high : high << 1 | bits(record, kLowTrimShift, 1);
}
// The record bits that store trim code t (< max_leaf_trim + 1): leaf_trim_code's inverse.
constexpr std::uint32_t leaf_trim_bits(std::uint32_t t, LeafTrim trim) {
  return trim == LeafTrim::Eighths ? t << kConeShift
                                   : (t >> 1) << kConeShift | (t & 1) << kLowTrimShift;
}
// Largest trim code.
constexpr std::uint32_t max_leaf_trim(LeafTrim trim) { return trim == LeafTrim::Eighths ? 3 : 7; }

// A leaf's drawn radius: its decoded sphere's radius less t/8 (or t/16) of it. The writer picks
// the largest t whose trimmed sphere, around the decoded centre, still holds the leaf's true
// sphere; the trimmed sphere is concentric with the decoded one, so it stays inside the decoded
// parent. Computed the same way (float) by the writer and every reader.
constexpr float trimmed_leaf_radius(float decoded_radius, std::uint32_t t, LeafTrim trim) {
  const float step = trim == LeafTrim::Eighths ? 0.125f : 0.0625f;
  return decoded_radius * (1.0f - step * static_cast<float>(t));
}

// Decoding tables, fetched once (the table functions initialise on first use).
struct DecodeTables {
  const SphereCandidate* spheres = sphere_table().data();
  const Vec3f* normals = normal_table().data();
};

namespace detail {

using Lanes4 = float __attribute__((vector_size(16)));  // GCC/Clang vector extension

// decode_node_into with the parent sphere as 16 bytes: centre x, y, z, radius.
inline void decode_node_into(const DecodeTables& tables, std::uint32_t record,
                             std::uint16_t rgb565, bool has_color, LeafTrim trim,
                             const unsigned char* parent_bytes, SphereNode& out) {
  Lanes4 parent, candidate;
  std::memcpy(&parent, parent_bytes, sizeof parent);
  std::memcpy(&candidate, &tables.spheres[bits(record, kSphereShift, kSphereBits)],
              sizeof candidate);
  // decode_sphere lane by lane: centre + radius · offset, and 0 + radius · r (exactly radius · r,
  // which is positive).
  Lanes4 sphere = Lanes4{parent[0], parent[1], parent[2], 0.0f} + parent[3] * candidate;
  const std::uint32_t children = record_child_count(record);
  float cone = 0.0f;
  if (children == 0) {
    sphere[3] = trimmed_leaf_radius(sphere[3], leaf_trim_code(record, trim), trim);
  } else {
    cone = decoded_cone_sin(bits(record, kConeShift, kConeBits));
  }
  const Vec3f& normal = tables.normals[bits(record, kNormalShift, kNormalBits)];
  const Lanes4 normal_cone{normal.x, normal.y, normal.z, cone};
  const Rgb8 color = has_color ? decode_rgb565(rgb565) : Rgb8{};
  const std::uint64_t tail = std::uint64_t{children} << 32 | std::uint64_t{color.r} << 40 |
                             std::uint64_t{color.g} << 48 |
                             std::uint64_t{color.b} << 56;  // first_child 0
  auto* bytes = reinterpret_cast<unsigned char*>(&out);
  std::memcpy(bytes + offsetof(SphereNode, center), &sphere, sizeof sphere);
  std::memcpy(bytes + offsetof(SphereNode, normal), &normal_cone, sizeof normal_cone);
  std::memcpy(bytes + offsetof(SphereNode, first_child), &tail, sizeof tail);
}
static_assert(offsetof(SphereNode, radius) == 12 && offsetof(SphereNode, normal) == 16 &&
                  offsetof(SphereNode, cone_sin) == 28 && offsetof(SphereNode, first_child) == 32 &&
                  offsetof(SphereNode, child_count) == 36 && offsetof(SphereNode, color) == 37 &&
                  offsetof(Sphere, radius) == 12,
              "decode_node_into writes SphereNode's layout and reads Sphere's");
static_assert(std::endian::native == std::endian::little, "decode_node_into writes little-endian");

}  // namespace detail

// The node of a valid record (sphere code < kSphereCodeCount, normal code < kNormalCodeCount)
// against its decoded parent sphere, written to `out`: decoded centre and radius (leaves
// trimmed), normal, cone_sin (0 for leaves), child count and colour (0 without one);
// first_child 0. The node is written as three stores (16, 16 and 8 bytes), so that copying it
// soon after loads it whole: built field by field, later copies stall on store-to-load
// forwarding (a third of the paged traversal's time, measured).
inline void decode_node_into(const DecodeTables& tables, std::uint32_t record,
                             std::uint16_t rgb565, bool has_color, LeafTrim trim,
                             const Sphere& parent, SphereNode& out) {
  detail::decode_node_into(tables, record, rgb565, has_color, trim,
                           reinterpret_cast<const unsigned char*>(&parent), out);
}
// The same with the parent's decoded node (its centre and radius).
inline void decode_node_into(const DecodeTables& tables, std::uint32_t record,
                             std::uint16_t rgb565, bool has_color, LeafTrim trim,
                             const SphereNode& parent, SphereNode& out) {
  detail::decode_node_into(tables, record, rgb565, has_color, trim,
                           reinterpret_cast<const unsigned char*>(&parent) +
                               offsetof(SphereNode, center),
                           out);
}

}  // namespace pointillist::quant
