#include "ptl_v2_features.hpp"

#include <cmath>
#include <cstring>

#include "pointillist/core/error.hpp"
#include "pointillist/format/ptl_v2.hpp"
#include "ptl_v2_layout.hpp"

namespace pointillist::ptl2 {
namespace {

constexpr char kSectionMagic[4] = {'P', 'T', 'L', 'F'};
constexpr std::uint32_t kSectionVersion = 2;  // 1: the leaves in node order (still read)
constexpr std::size_t kStatsCount = 13;
constexpr std::size_t kBlockEntry = 16;  // u64 offset, u32 clipped nodes, u32 planes
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
  void seek(std::uint64_t pos) {
    if (pos > size_) fail("a position past the section's end");
    pos_ = pos;
  }
  std::uint64_t left() const { return size_ - pos_; }
  const std::uint8_t* here() const { return b_ + pos_; }

 private:
  const std::uint8_t* b_;
  std::uint64_t size_, pos_ = 0, at_;
  const std::string& path_;
};

}  // namespace

namespace {

void write_fixed(Writer& w, const TreeFeatures& f, std::uint64_t leaves) {
  for (char c : kSectionMagic) w.u8(static_cast<std::uint8_t>(c));
  w.u32(kSectionVersion);
  w.f32(f.options.sharp_threshold);
  w.f32(f.options.radius_scale);
  w.u8(static_cast<std::uint8_t>(f.options.edge_test));
  w.u8(static_cast<std::uint8_t>(f.options.clip_rule));
  w.u8(0);
  w.u8(0);
  w.u32(f.surface_count);
  w.u64(leaves);
  FeatureStats stats = f.stats;
  for (std::size_t k = 0; k < kStatsCount; ++k) w.u64(*stat_fields(stats, k));
  for (int k = 1; k <= kMaxClipPlanes; ++k) w.u64(stats.plane_histogram[k]);
}

// A clip code and its planes, after a record or leaf index.
void write_planes(Writer& w, const TreeFeatures& f, std::size_t node) {
  const auto planes = f.planes(node);
  w.u8(static_cast<std::uint8_t>(planes.size() | static_cast<unsigned>(f.clip_mode[node]) << 5));
  for (const ClipPlane& p : planes) w.f32(p.n.x), w.f32(p.n.y), w.f32(p.n.z), w.f32(p.h);
}

// A clip code at section byte `field` and its planes; appends the planes to `planes`.
ClipMode read_planes(Reader& r, std::uint64_t field, std::vector<ClipPlane>& planes) {
  const std::uint8_t code = r.u8();
  const std::uint32_t count = code & 31u, mode = code >> 5;
  if (count == 0 || count > kMaxClipPlanes || mode == 0 || mode > 3) {
    r.fail_at(field, "clip code " + std::to_string(code) + " (1 to 16 planes, mode 1 to 3)");
  }
  r.need(16ull * count, "clip planes");
  for (std::uint32_t p = 0; p < count; ++p) {
    ClipPlane plane;
    plane.n = {r.f32(), r.f32(), r.f32()};
    plane.h = r.f32();
    if (!is_finite(plane.n) || !std::isfinite(plane.h)) r.fail("a clip plane is not finite");
    planes.push_back(plane);
  }
  return static_cast<ClipMode>(mode);
}

}  // namespace

namespace {

PtlV2FeatureBlock feature_block(const TreeFeatures& f) {
  // Surface ids of every node, as runs (a surface's nodes are mostly together).
  std::vector<std::pair<std::uint32_t, std::uint32_t>> runs;
  PtlV2FeatureBlock block;
  const std::size_t n = f.surface.size();
  for (std::size_t k = 0; k < n; ++k) {
    if (!runs.empty() && runs.back().first == f.surface[k]) {
      ++runs.back().second;
    } else {
      runs.push_back({f.surface[k], 1});
    }
    block.clipped += !f.planes(k).empty();
    block.planes += static_cast<std::uint32_t>(f.planes(k).size());
  }
  Writer w;
  w.u32(static_cast<std::uint32_t>(runs.size()));
  for (const auto& [id, length] : runs) w.u32(id), w.u32(length);
  w.u32(block.clipped);
  for (std::size_t k = 0; k < n; ++k) {
    if (f.planes(k).empty()) continue;
    w.u32(static_cast<std::uint32_t>(k));
    write_planes(w, f, k);
  }
  block.bytes = std::move(w.out);
  return block;
}

std::uint64_t feature_head_size(std::uint32_t page_count) {
  return kFixedBytes + 8 + kBlockEntry * (std::uint64_t{page_count} + 1);
}

std::vector<std::uint8_t> feature_head(const TreeFeatures& summary, std::uint64_t leaf_count,
                                       std::span<const PtlV2FeatureBlockEntry> blocks) {
  Writer w;
  write_fixed(w, summary, leaf_count);
  w.u64(blocks.size());
  // The block table: (offset, clipped nodes, planes) per page, then (end, 0, 0).
  std::uint64_t at = feature_head_size(static_cast<std::uint32_t>(blocks.size()));
  for (const PtlV2FeatureBlockEntry& b : blocks) {
    w.u64(at), w.u32(b.clipped), w.u32(b.planes);
    at += b.size;
  }
  w.u64(at), w.u32(0), w.u32(0);
  return std::move(w.out);
}

}  // namespace

std::vector<std::uint8_t> encode_features(std::span<const SphereNode> nodes,
                                          const TreeFeatures& f,
                                          std::span<const std::span<const std::uint32_t>> pages) {
  std::uint64_t leaves = 0;
  for (const SphereNode& n : nodes) leaves += n.child_count == 0;
  std::vector<PtlV2FeatureBlock> blocks(pages.size());
  TreeFeatures page;
  for (std::size_t p = 0; p < pages.size(); ++p) {
    page.surface.clear();
    page.clip_mode.clear();
    page.clip_planes.clear();
    page.clip_offset.assign(1, 0);
    for (const std::uint32_t k : pages[p]) {
      page.surface.push_back(f.surface[k]);
      page.clip_mode.push_back(f.clip_mode[k]);
      const auto planes = f.planes(k);
      page.clip_planes.insert(page.clip_planes.end(), planes.begin(), planes.end());
      page.clip_offset.push_back(static_cast<std::uint32_t>(page.clip_planes.size()));
    }
    blocks[p] = feature_block(page);
  }
  std::vector<PtlV2FeatureBlockEntry> entries;
  for (const PtlV2FeatureBlock& b : blocks) entries.push_back({b.bytes.size(), b.clipped, b.planes});
  std::vector<std::uint8_t> out = feature_head(f, leaves, entries);
  for (const PtlV2FeatureBlock& b : blocks) out.insert(out.end(), b.bytes.begin(), b.bytes.end());
  return out;
}

FeatureSection decode_feature_header(std::string_view bytes, std::uint64_t at,
                                     std::uint64_t leaf_count, std::uint32_t page_count,
                                     const std::string& path) {
  Reader r(bytes, at, path);
  r.need(kFixedBytes, "its fixed fields");
  if (std::memcmp(r.here(), kSectionMagic, 4) != 0) r.fail("no 'PTLF' signature");
  for (int k = 0; k < 4; ++k) r.u8();
  FeatureSection out;
  out.version = r.u32();
  if (out.version != 1 && out.version != kSectionVersion) {
    r.fail("section version " + std::to_string(out.version) +
           " (this Pointillist reads 1 and 2; upgrade it)");
  }
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
  out.surfaces = r.u32();
  if (const std::uint64_t leaves = r.u64(); leaves != leaf_count) {
    r.fail("it describes " + std::to_string(leaves) + " leaves, the model has " +
           std::to_string(leaf_count));
  }
  for (std::size_t k = 0; k < kStatsCount; ++k) *stat_fields(out.stats, k) = r.u64();
  for (int k = 1; k <= kMaxClipPlanes; ++k) out.stats.plane_histogram[k] = r.u64();
  if (out.stats.segments != out.surfaces) r.fail("surface count and statistics disagree");
  if (out.version == 1) {
    out.body = r.pos();
    return out;
  }
  const std::uint64_t field = r.pos();
  if (const std::uint64_t pages = r.u64(); pages != page_count) {
    r.fail_at(field, "it describes " + std::to_string(pages) + " pages, the model has " +
                         std::to_string(page_count));
  }
  if (std::uint64_t{page_count} + 1 > r.left() / kBlockEntry) r.fail("the block table does not fit");
  out.blocks.resize(std::size_t{page_count} + 1);
  out.clipped.resize(page_count);
  out.planes.resize(page_count);
  const std::uint64_t table_end = r.pos() + kBlockEntry * out.blocks.size();
  for (std::size_t p = 0; p < out.blocks.size(); ++p) {
    const std::uint64_t entry = r.pos();
    out.blocks[p] = r.u64();
    const std::uint32_t clipped = r.u32(), planes = r.u32();
    if (p < page_count) {
      out.clipped[p] = clipped;
      out.planes[p] = planes;
    }
    const std::uint64_t low = p == 0 ? table_end : out.blocks[p - 1];
    if (out.blocks[p] < low || out.blocks[p] > bytes.size() ||
        (p == 0 && out.blocks[p] != table_end) ||
        (p + 1 == out.blocks.size() && out.blocks[p] != bytes.size())) {
      r.fail_at(entry, "the block of page " + std::to_string(p) + " starts at section byte " +
                           std::to_string(out.blocks[p]) +
                           ", not after the previous one and inside the section");
    }
  }
  return out;
}

FeatureData decode_leaf_features(std::string_view bytes, std::uint64_t at,
                                 const FeatureSection& section, std::uint64_t leaf_count,
                                 const std::string& path) {
  Reader r(bytes, at, path);
  r.seek(section.body);
  FeatureData out;
  out.options = section.options;
  out.stats = section.stats;
  const std::uint32_t surfaces = section.surfaces;
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
    const std::size_t before = out.clip_planes.size();
    out.clip_mode[leaf] = read_planes(r, field + 4, out.clip_planes);
    counts[leaf] = static_cast<std::uint32_t>(out.clip_planes.size() - before);
  }
  for (std::uint64_t i = 0; i < leaf_count; ++i) out.clip_offset[i + 1] = out.clip_offset[i] + counts[i];
  return out;
}

void decode_page_features(std::string_view bytes, std::uint64_t at,
                          const FeatureSection& section, std::uint32_t page,
                          std::uint32_t node_count,
                          const std::function<bool(std::uint32_t)>& is_leaf,
                          const std::string& path, PageFeatures& out) {
  out.clear();
  const std::uint64_t begin = section.blocks.at(page), end = section.blocks.at(page + 1);
  Reader r(bytes.substr(0, end), at, path);
  r.seek(begin);
  const std::string where = "page " + std::to_string(page) + ": ";
  const std::uint32_t runs = r.u32();
  if (runs > r.left() / 8 || runs > node_count) {
    r.fail(where + std::to_string(runs) + " runs of surface ids do not fit");
  }
  out.surface.reserve(node_count);
  for (std::uint32_t k = 0; k < runs; ++k) {
    const std::uint64_t field = r.pos();
    const std::uint32_t id = r.u32(), length = r.u32();
    if (length == 0 || length > node_count - out.surface.size()) {
      r.fail_at(field + 4, where + "a run of surface ids overruns the page's " +
                               std::to_string(node_count) + " nodes");
    }
    const auto first = static_cast<std::uint32_t>(out.surface.size());
    if (id >= section.surfaces) {
      for (std::uint32_t j = first; j < first + length && id == kMixedSurface; ++j) {
        if (is_leaf(j)) {
          r.fail_at(field, where + "leaf " + std::to_string(j) + " has no surface id");
        }
      }
      if (id != kMixedSurface) {
        r.fail_at(field, where + "surface id " + std::to_string(id) + " (the model has " +
                             std::to_string(section.surfaces) + " surfaces)");
      }
    }
    out.surface.insert(out.surface.end(), length, id);
  }
  if (out.surface.size() != node_count) {
    r.fail(where + "the surface ids cover " + std::to_string(out.surface.size()) + " of its " +
           std::to_string(node_count) + " nodes");
  }
  const std::uint64_t clipped_field = r.pos();
  const std::uint32_t clipped = r.u32();
  if (clipped > node_count || clipped > r.left() / 21) {
    r.fail(where + std::to_string(clipped) + " clipped nodes do not fit");
  }
  if (clipped != section.clipped[page]) {
    r.fail_at(clipped_field, where + std::to_string(clipped) + " clipped nodes, the block table "
                             "says " + std::to_string(section.clipped[page]));
  }
  out.clipped.reserve(clipped);
  out.clipped_mode.reserve(clipped);
  out.clipped_first.reserve(std::size_t{clipped} + 1);
  out.clipped_first.push_back(0);
  for (std::uint32_t k = 0; k < clipped; ++k) {
    const std::uint64_t field = r.pos();
    const std::uint32_t node = r.u32();
    if ((!out.clipped.empty() && node <= out.clipped.back()) || node >= node_count ||
        !is_leaf(node)) {
      r.fail_at(field, where + "clipped node " + std::to_string(node) +
                           " is out of order, out of range or not a leaf");
    }
    out.clipped.push_back(node);
    out.clipped_mode.push_back(read_planes(r, field + 4, out.planes));
    out.clipped_first.push_back(static_cast<std::uint32_t>(out.planes.size()));
  }
  if (out.planes.size() != section.planes[page]) {
    r.fail(where + std::to_string(out.planes.size()) + " clip planes, the block table says " +
           std::to_string(section.planes[page]));
  }
  if (r.left() != 0) r.fail(where + std::to_string(r.left()) + " bytes after the block's end");
}

}  // namespace pointillist::ptl2

namespace pointillist {

PtlV2FeatureBlock encode_ptl_v2_feature_block(const TreeFeatures& page) {
  return ptl2::feature_block(page);
}

std::uint64_t ptl_v2_feature_head_size(std::uint32_t page_count) {
  return ptl2::feature_head_size(page_count);
}

std::vector<std::uint8_t> encode_ptl_v2_feature_head(
    const TreeFeatures& summary, std::uint64_t leaf_count,
    std::span<const PtlV2FeatureBlockEntry> blocks) {
  return ptl2::feature_head(summary, leaf_count, blocks);
}

}  // namespace pointillist
