#include "ptl_header.hpp"

#include <cstring>

#include "pointillist/core/error.hpp"

namespace pointillist::ptl {
namespace {

void put_u32(std::uint8_t* p, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
void put_u64(std::uint8_t* p, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
void put_f32(std::uint8_t* p, float v) {
  std::uint32_t bits;
  std::memcpy(&bits, &v, 4);
  put_u32(p, bits);
}
void put_vec(std::uint8_t* p, Vec3f v) {
  put_f32(p, v.x);
  put_f32(p + 4, v.y);
  put_f32(p + 8, v.z);
}

std::uint32_t get_u32(const std::uint8_t* p) {
  std::uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= std::uint32_t{p[i]} << (8 * i);
  return v;
}
std::uint64_t get_u64(const std::uint8_t* p) {
  std::uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v |= std::uint64_t{p[i]} << (8 * i);
  return v;
}
float get_f32(const std::uint8_t* p) {
  const std::uint32_t bits = get_u32(p);
  float v;
  std::memcpy(&v, &bits, 4);
  return v;
}
Vec3f get_vec(const std::uint8_t* p) { return {get_f32(p), get_f32(p + 4), get_f32(p + 8)}; }

}  // namespace

std::array<std::uint8_t, kHeaderSize> encode_header(const Header& h) {
  std::array<std::uint8_t, kHeaderSize> b{};
  std::memcpy(b.data() + offset::kMagic, kMagic, sizeof kMagic);
  put_u32(b.data() + offset::kVersion, h.version);
  put_u32(b.data() + offset::kHeaderSize, h.header_size);
  put_u32(b.data() + offset::kFlags, h.flags);
  put_u32(b.data() + offset::kNodeSize, h.node_size);
  put_u64(b.data() + offset::kNodeCount, h.node_count);
  put_u64(b.data() + offset::kLeafCount, h.leaf_count);
  put_u32(b.data() + offset::kDepth, h.depth);
  put_u32(b.data() + offset::kCompatFlags, h.compat_flags);
  put_vec(b.data() + offset::kBoundsLo, h.bounds.lo);
  put_vec(b.data() + offset::kBoundsHi, h.bounds.hi);
  put_vec(b.data() + offset::kViewCenter, h.view_sphere.center);
  put_f32(b.data() + offset::kViewRadius, h.view_sphere.radius);
  put_u64(b.data() + offset::kNodesOffset, h.nodes_offset);
  put_u64(b.data() + offset::kMetadataOffset, h.metadata_offset);
  put_u64(b.data() + offset::kMetadataSize, h.metadata_size);
  return b;
}

Header decode_header(const std::uint8_t* b) {
  Header h;
  h.version = get_u32(b + offset::kVersion);
  h.header_size = get_u32(b + offset::kHeaderSize);
  h.flags = get_u32(b + offset::kFlags);
  h.node_size = get_u32(b + offset::kNodeSize);
  h.node_count = get_u64(b + offset::kNodeCount);
  h.leaf_count = get_u64(b + offset::kLeafCount);
  h.depth = get_u32(b + offset::kDepth);
  h.compat_flags = get_u32(b + offset::kCompatFlags);
  h.bounds.lo = get_vec(b + offset::kBoundsLo);
  h.bounds.hi = get_vec(b + offset::kBoundsHi);
  h.view_sphere.center = get_vec(b + offset::kViewCenter);
  h.view_sphere.radius = get_f32(b + offset::kViewRadius);
  h.nodes_offset = get_u64(b + offset::kNodesOffset);
  h.metadata_offset = get_u64(b + offset::kMetadataOffset);
  h.metadata_size = get_u64(b + offset::kMetadataSize);
  return h;
}

void fail_at(const std::string& path, std::uint64_t byte, const std::string& what) {
  throw FormatError(path + ": byte " + std::to_string(byte) + ": " + what);
}

}  // namespace pointillist::ptl
