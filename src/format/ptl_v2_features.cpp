#include "ptl_v2_features.hpp"

#include <cmath>
#include <cstring>

#include "pointillist/core/error.hpp"
#include "ptl_v2_layout.hpp"

namespace pointillist::ptl2 {
namespace {

constexpr char kSectionMagic[4] = {'P', 'T', 'L', 'F'};
constexpr std::uint32_t kSectionVersion = 1;
constexpr std::size_t kStatsCount = 13;
constexpr std::size_t kFixedBytes = 32 + 8 * kStatsCount + 8 * kMaxClipPlanes;

std::uint64_t* stat_fields(FeatureStats& s, std::size_t k) {
  std::uint64_t* fields[kStatsCount] = {
      &s.splats,      &s.edges,        &s.sharp_edges,   &s.crossing_edges, &s.antiparallel_edges,
      &s.candidates,  &s.clipped,      &s.pass_through,  &s.undefined_4_15, &s.nearest_rule,
      &s.capped,      &s.segments,     &s.large_segments};
  return fields[k];
}

class Writer {
 public:
  void u8(std::uint8_t v) { out.push_back(v); }
  void u32(std::uint32_t v) { grow(4), store_u32(&out[out.size() - 4], v); }
  void u64(std::uint64_t v) { grow(8), store_u64(&out[out.size() - 8], v); }
  void f32(float v) { grow(4), store_f32(&out[out.size() - 4], v); }
  std::vector<std::uint8_t> out;

 private:
  void grow(std::size_t n) { out.resize(out.size() + n); }
};

class Reader {
 public:
  Reader(std::string_view bytes, std::uint64_t at, const std::string& path)
      : b_(reinterpret_cast<const std::uint8_t*>(bytes.data())), size_(bytes.size()), at_(at),
        path_(path) {}
  [[noreturn]] void fail(const std::string& what) const { fail_at(pos_, what); }
  // The field that starts at section byte `pos` is wrong.
  [[noreturn]] void fail_at(std::uint64_t pos, const std::string& what) const {
    throw FormatError(path_ + ": byte " + std::to_string(at_ + pos) + ": sharp features: " +
                      what + "; the file is damaged (convert the scan again)");
  }
  std::uint64_t pos() const { return pos_; }
  void need(std::uint64_t n, const char* what) const {
    if (n > size_ - pos_) {
      fail(std::string("the section ends inside ") + what + " (" + std::to_string(n) +
           " bytes needed, " + std::to_string(size_ - pos_) + " left)");
    }
  }
  std::uint8_t u8() { return need(1, "a byte"), b_[pos_++]; }
  std::uint32_t u32() {
    need(4, "a 32-bit field");
    const std::uint32_t v = load_u32(b_ + pos_);
    pos_ += 4;
    return v;
  }
  std::uint64_t u64() {
    need(8, "a 64-bit field");
    const std::uint64_t v = load_u64(b_ + pos_);
    pos_ += 8;
    return v;
  }
  float f32() { return std::bit_cast<float>(u32()); }
  std::uint64_t left() const { return size_ - pos_; }
  const std::uint8_t* here() const { return b_ + pos_; }

 private:
  const std::uint8_t* b_;
  std::uint64_t size_, pos_ = 0, at_;
  const std::string& path_;
};

}  // namespace

std::vector<std::uint8_t> encode_features(std::span<const SphereNode> nodes,
                                          const TreeFeatures& f) {
  Writer w;
  for (char c : kSectionMagic) w.u8(static_cast<std::uint8_t>(c));
  w.u32(kSectionVersion);
  w.f32(f.options.sharp_threshold);
  w.f32(f.options.radius_scale);
  w.u8(static_cast<std::uint8_t>(f.options.edge_test));
  w.u8(static_cast<std::uint8_t>(f.options.clip_rule));
  w.u8(0);
  w.u8(0);
  w.u32(f.surface_count);
  std::uint64_t leaves = 0;
  for (const SphereNode& n : nodes) leaves += n.child_count == 0;
  w.u64(leaves);
  FeatureStats stats = f.stats;
  for (std::size_t k = 0; k < kStatsCount; ++k) w.u64(*stat_fields(stats, k));
  for (int k = 1; k <= kMaxClipPlanes; ++k) w.u64(stats.plane_histogram[k]);
  // Surface ids of the leaves in node order, as runs (a surface's leaves are mostly together).
  std::vector<std::pair<std::uint32_t, std::uint32_t>> runs;
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    if (nodes[k].child_count != 0) continue;
    if (!runs.empty() && runs.back().first == f.surface[k]) {
      ++runs.back().second;
    } else {
      runs.push_back({f.surface[k], 1});
    }
  }
  w.u64(runs.size());
  for (const auto& [id, length] : runs) w.u32(id), w.u32(length);
  // Clipped leaves: leaf index, clip code, planes.
  std::uint64_t clipped = 0;
  for (std::size_t k = 0; k < nodes.size(); ++k) clipped += nodes[k].child_count == 0 && !f.planes(k).empty();
  w.u64(clipped);
  std::uint32_t leaf = 0;
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    if (nodes[k].child_count != 0) continue;
    const auto planes = f.planes(k);
    if (!planes.empty()) {
      w.u32(leaf);
      w.u8(static_cast<std::uint8_t>(planes.size() | static_cast<unsigned>(f.clip_mode[k]) << 5));
      for (const ClipPlane& p : planes) w.f32(p.n.x), w.f32(p.n.y), w.f32(p.n.z), w.f32(p.h);
    }
    ++leaf;
  }
  return std::move(w.out);
}

FeatureData decode_features(std::string_view bytes, std::uint64_t at, std::uint64_t leaf_count,
                            const std::string& path) {
  Reader r(bytes, at, path);
  r.need(kFixedBytes, "its fixed fields");
  if (std::memcmp(r.here(), kSectionMagic, 4) != 0) r.fail("no 'PTLF' signature");
  for (int k = 0; k < 4; ++k) r.u8();
  if (const std::uint32_t v = r.u32(); v != kSectionVersion) {
    r.fail("section version " + std::to_string(v) + " (this Pointillist reads 1; upgrade it)");
  }
  FeatureData out;
  out.options.sharp_threshold = r.f32();
  out.options.radius_scale = r.f32();
  const std::uint8_t edge = r.u8(), rule = r.u8();
  r.u8();
  r.u8();
  if (edge > 1 || rule > 3) r.fail("unknown edge test or clip rule");
  out.options.edge_test = static_cast<EdgeTest>(edge);
  out.options.clip_rule = static_cast<ClipRule>(rule);
  if (!(out.options.sharp_threshold >= -1 && out.options.sharp_threshold <= 1) ||
      !(out.options.radius_scale >= 1 && out.options.radius_scale <= 2)) {
    r.fail("threshold or radius scale out of range");
  }
  const std::uint32_t surfaces = r.u32();
  if (const std::uint64_t leaves = r.u64(); leaves != leaf_count) {
    r.fail("it describes " + std::to_string(leaves) + " leaves, the model has " +
           std::to_string(leaf_count));
  }
  for (std::size_t k = 0; k < kStatsCount; ++k) *stat_fields(out.stats, k) = r.u64();
  for (int k = 1; k <= kMaxClipPlanes; ++k) out.stats.plane_histogram[k] = r.u64();
  if (out.stats.segments != surfaces) r.fail("surface count and statistics disagree");
  const std::uint64_t runs = r.u64();
  if (runs > r.left() / 8 || runs > leaf_count) r.fail(std::to_string(runs) + " runs of surface ids do not fit");
  out.surface_id.reserve(leaf_count);
  for (std::uint64_t k = 0; k < runs; ++k) {
    const std::uint64_t field = r.pos();
    const std::uint32_t id = r.u32(), length = r.u32();
    if (id >= surfaces) {
      r.fail_at(field, "surface id " + std::to_string(id) + " (the model has " +
                           std::to_string(surfaces) + " surfaces)");
    }
    if (length == 0 || length > leaf_count - out.surface_id.size()) {
      r.fail_at(field + 4, "a run of surface ids overruns the leaves");
    }
    out.surface_id.insert(out.surface_id.end(), length, id);
  }
  if (out.surface_id.size() != leaf_count) r.fail("the surface ids cover fewer leaves than the model has");
  const std::uint64_t clipped = r.u64();
  if (clipped > leaf_count || clipped > r.left() / 21) r.fail(std::to_string(clipped) + " clipped leaves do not fit");
  out.clip_mode.assign(leaf_count, ClipMode::None);
  out.clip_offset.assign(leaf_count + 1, 0);
  std::uint64_t next = 0;
  std::vector<std::uint32_t> counts(leaf_count, 0);
  for (std::uint64_t k = 0; k < clipped; ++k) {
    const std::uint64_t field = r.pos();
    const std::uint32_t leaf = r.u32();
    if (leaf < next || leaf >= leaf_count) {
      r.fail_at(field, "clipped leaf " + std::to_string(leaf) + " out of order or range");
    }
    next = std::uint64_t{leaf} + 1;
    const std::uint8_t code = r.u8();
    const std::uint32_t count = code & 31u, mode = code >> 5;
    if (count == 0 || count > kMaxClipPlanes || mode == 0 || mode > 3) {
      r.fail_at(field + 4, "clip code " + std::to_string(code) + " (1 to 16 planes, mode 1 to 3)");
    }
    r.need(16ull * count, "clip planes");
    out.clip_mode[leaf] = static_cast<ClipMode>(mode);
    counts[leaf] = count;
    for (std::uint32_t p = 0; p < count; ++p) {
      ClipPlane plane;
      plane.n = {r.f32(), r.f32(), r.f32()};
      plane.h = r.f32();
      if (!is_finite(plane.n) || !std::isfinite(plane.h)) r.fail("a clip plane is not finite");
      out.clip_planes.push_back(plane);
    }
  }
  for (std::uint64_t i = 0; i < leaf_count; ++i) out.clip_offset[i + 1] = out.clip_offset[i] + counts[i];
  return out;
}

}  // namespace pointillist::ptl2
