// Reading .ptl version 2 (docs/ptl-format.md, "Version 2"): the header and page table are
// validated when the file is opened; each page is validated as it is decoded, so no byte outside
// the file, the page or the tables is ever read.
#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "ptl_header.hpp"
#include "ptl_v2_codec.hpp"
#include "ptl_v2_features.hpp"
#include "ptl_v2_mesh.hpp"
#include "ptl_v2_layout.hpp"
#include "ptl_v2_mapping.hpp"
#include "pointillist/core/file_bytes.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/format/ptl.hpp"
#include "pointillist/format/ptl_v2.hpp"
#include "pointillist/lod/pages.hpp"

namespace pointillist {

namespace {

using namespace ptl2;

std::string str(std::uint64_t v) { return std::to_string(v); }

using ptl::fail_at;

bool finite_sphere(const Sphere& s) {
  return is_finite(s.center) && std::isfinite(s.radius) && s.radius >= 0;
}

}  // namespace

std::unique_ptr<PtlV2File> PtlV2File::open(const std::string& path) {
  std::unique_ptr<PtlV2File> file(new PtlV2File);
  file->path_ = path;
  file->map_ = std::make_unique<Mapping>();
  // Pages are read as they are used: a render of a large model reads a small part of it.
  file->map_->bytes = FileBytes::map(path, FileBytes::Use::Parts);
  const std::string_view view = file->map_->bytes.view();
  const auto* b = reinterpret_cast<const std::uint8_t*>(view.data());
  const std::uint64_t size = view.size();
  file->size_ = size;

  if (size < sizeof ptl::kMagic || std::memcmp(b, ptl::kMagic, sizeof ptl::kMagic) != 0) {
    fail_at(path, 0, "not a Pointillist model file (expected \"PTLSPLAT\")");
  }
  if (size < offset::kVersion + 4) {
    fail_at(path, size,
            "file ends early: the header needs " + str(kHeaderSize) + " bytes, the file has only " +
                str(size));
  }
  const std::uint32_t version = load_u32(b + offset::kVersion);
  if (version == 1) {
    fail_at(path, offset::kVersion,
            ".ptl version 1 file; PtlV2File reads version 2 only (open it with PtlFile or "
            "read_ptl, which reads both)");
  }
  if (version == 0) fail_at(path, offset::kVersion, "invalid .ptl version 0");
  if (version != kPtlV2Version) {
    fail_at(path, offset::kVersion,
            ".ptl version " + str(version) +
                " is newer than this build of Pointillist reads "
                "(versions 1 and 2); upgrade Pointillist to open it");
  }
  if (size < kHeaderSize) {
    fail_at(path, size,
            "file ends early: the header needs " + str(kHeaderSize) + " bytes, the file has only " +
                str(size));
  }
  const std::uint32_t header_size = load_u32(b + offset::kHeaderSize);
  if (header_size < kHeaderSize || header_size > size) {
    fail_at(path, offset::kHeaderSize,
            "header size " + str(header_size) + " (at least " + str(kHeaderSize) + ", within the " +
                str(size) + "-byte file)");
  }
  const std::uint32_t endian = load_u32(b + offset::kEndian);
  if (endian != kEndianMarker) {
    fail_at(path, offset::kEndian,
            "endianness marker does not read 0x01020304 little-endian; the file is corrupt or "
            "was written byte-swapped");
  }
  const std::uint32_t flags = load_u32(b + offset::kFlags);
  if ((flags & ~kKnownFlags) != 0) {
    fail_at(path, offset::kFlags,
            "flags " + str(flags) +
                " name features this build does not know; upgrade "
                "Pointillist to open the file");
  }
  file->has_colors_ = (flags & kFlagHasColors) != 0;
  file->record_size_ = load_u32(b + offset::kRecordSize);
  const std::uint32_t want_record = file->has_colors_ ? 6 : 4;
  if (file->record_size_ != want_record) {
    fail_at(path, offset::kRecordSize,
            "record size " + str(file->record_size_) + ", expected " + str(want_record) +
                (file->has_colors_ ? " (with colours)" : " (without colours)"));
  }
  // Known layouts: leaf trims in eighths (the first files) or sixteenths (one more attribute).
  const std::uint32_t attribute_count = load_u32(b + offset::kAttributeCount);
  const std::uint32_t eighths_count = schema(file->has_colors_, LeafTrim::Eighths).count;
  if (attribute_count != eighths_count && attribute_count != eighths_count + 1) {
    fail_at(path, offset::kAttributeCount,
            "attribute count " + str(attribute_count) + ", expected " + str(eighths_count) +
                " or " + str(eighths_count + 1) + "; upgrade Pointillist to open the file");
  }
  file->leaf_trim_ = attribute_count == eighths_count ? LeafTrim::Eighths : LeafTrim::Sixteenths;
  const Schema expected = schema(file->has_colors_, file->leaf_trim_);
  for (std::uint32_t a = 0; a < expected.count; ++a) {
    const std::uint8_t* e = b + offset::kAttributes + 8 * a;
    const Attribute& x = expected.entries[a];
    if (load_u16(e) != x.attribute || load_u16(e + 2) != x.encoding || e[4] != x.first_bit ||
        e[5] != x.bit_count) {
      fail_at(path, offset::kAttributes + 8 * a,
              "attribute " + str(a) + " is not the version 2 layout (attribute " +
                  str(x.attribute) + ", encoding " + str(x.encoding) + ", bits " +
                  str(x.first_bit) + ".." + str(x.first_bit + x.bit_count - 1) +
                  "); upgrade Pointillist to open the file");
    }
  }
  file->node_count_ = load_u64(b + offset::kNodeCount);
  file->leaf_count_ = load_u64(b + offset::kLeafCount);
  file->depth_ = load_u32(b + offset::kDepth);
  if (file->node_count_ == 0 || file->node_count_ > 0xfffffffeu) {
    fail_at(path, offset::kNodeCount, "node count " + str(file->node_count_) + " (1 to 2^32 - 2)");
  }
  file->root_sphere_ = {load_vec(b + offset::kRootSphere), load_f32(b + offset::kRootSphere + 12)};
  file->bounds_ = {load_vec(b + offset::kBoundsLo), load_vec(b + offset::kBoundsHi)};
  file->view_sphere_ = {load_vec(b + offset::kViewCenter), load_f32(b + offset::kViewRadius)};
  if (load_u32(b + offset::kCompatFlags) & kCompatFrame) {
    for (int a = 0; a < 3; ++a) file->origin_[a] = load_f64(b + offset::kOrigin + 8 * a);
    const Vec3f up = load_vec(b + offset::kUp);
    if (!std::isfinite(file->origin_[0]) || !std::isfinite(file->origin_[1]) ||
        !std::isfinite(file->origin_[2])) {
      fail_at(path, offset::kOrigin, "origin is not finite");
    }
    if (!is_finite(up) || !(dot(up, up) > 0.5f && dot(up, up) < 2.0f)) {
      fail_at(path, offset::kUp, "up axis is not a unit vector");
    }
    file->up_ = normalized(up);
  }
  if (!finite_sphere(file->root_sphere_)) {
    fail_at(path, offset::kRootSphere, "root sphere is not finite or has a negative radius");
  }
  if (!is_finite(file->bounds_.lo) || !is_finite(file->bounds_.hi) ||
      !is_finite(file->view_sphere_.center) || !std::isfinite(file->view_sphere_.radius)) {
    fail_at(path, offset::kBoundsLo, "bounds or view sphere are not finite");
  }

  // Page table.
  const std::uint32_t page_count = load_u32(b + offset::kPageCount);
  const std::uint64_t table = load_u64(b + offset::kPageTableOffset);
  if (page_count == 0) fail_at(path, offset::kPageCount, "page count is 0");
  if (table < header_size || table > size ||
      std::uint64_t{page_count} * kPageEntrySize > size - table) {
    fail_at(path, table < header_size ? offset::kPageTableOffset : size,
            "file ends early or page table misplaced: " + str(page_count) + " entries at byte " +
                str(table) + " need " + str(std::uint64_t{page_count} * kPageEntrySize) +
                " bytes, the file has " + str(size));
  }
  file->pages_.resize(page_count);
  std::uint64_t records = 0;
  std::uint64_t pages_end = table + std::uint64_t{page_count} * kPageEntrySize;
  for (std::uint32_t p = 0; p < page_count; ++p) {
    const std::uint64_t at = table + std::uint64_t{p} * kPageEntrySize;
    const std::uint8_t* e = b + at;
    PtlV2PageInfo& info = file->pages_[p];
    info = {load_u64(e),      load_u32(e + 8),  load_u32(e + 12), load_u32(e + 16),
            load_u32(e + 20), load_u32(e + 24), load_u32(e + 28)};
    const std::string which = "page " + str(p) + " of " + str(page_count) + ": ";
    if (info.byte_size > size) {
      fail_at(path, at + 8,
              which + "the page is " + str(info.byte_size) + " bytes long, more than the whole "
              "file (" + str(size) + " bytes): the page table is corrupt");
    }
    if (info.offset > size || info.byte_size > size - info.offset) {
      fail_at(path, size,
              which + "file ends early: the page needs bytes " + str(info.offset) + " to " +
                  str(info.offset + info.byte_size) + ", the file has only " + str(size) +
                  " bytes; it was probably truncated");
    }
    if (info.offset < pages_end) {
      fail_at(path, at,
              which + "offset " + str(info.offset) + " overlaps the " +
                  (p == 0 ? std::string("page table") : "previous page") + " (which ends at byte " +
                  str(pages_end) + ")");
    }
    pages_end = info.offset + info.byte_size;
    const bool root_page = p == 0;
    if (root_page ? (info.parent_page != kPtlNoPage || info.root_count != 1 || info.first_root != 0)
                  : (info.parent_page >= p)) {
      fail_at(path, at + 16,
              which + "parent page " + str(info.parent_page) +
                  (root_page ? " (page 0 has none and one root)" : " must come before the page"));
    }
    if (!root_page) {
      const PtlV2PageInfo& parent = file->pages_[info.parent_page];
      if (info.root_count == 0 || info.first_root >= parent.node_count ||
          info.root_count > parent.node_count - info.first_root) {
        fail_at(path, at + 20,
                which + "roots " + str(info.first_root) + " + " + str(info.root_count) +
                    " are outside parent page " + str(info.parent_page) + " (" +
                    str(parent.node_count) + " records)");
      }
    }
    const std::uint64_t want = std::uint64_t{info.root_count} * kRootEntrySize +
                               std::uint64_t{info.node_count} * file->record_size_;
    if (info.node_count == 0 || info.level_count == 0 || info.byte_size != want) {
      fail_at(path, at + 8,
              which + "byte size " + str(info.byte_size) + ", " + str(info.node_count) +
                  " records in " + str(info.level_count) + " levels under " + str(info.root_count) +
                  " roots need " + str(want));
    }
    records += info.node_count;
  }
  if (records != file->node_count_) {
    fail_at(path, offset::kNodeCount,
            "header says " + str(file->node_count_) + " nodes, the pages hold " + str(records));
  }
  const std::uint64_t metadata_offset = load_u64(b + offset::kMetadataOffset);
  const std::uint64_t metadata_size = load_u64(b + offset::kMetadataSize);
  if (metadata_offset < header_size) {
    fail_at(path, offset::kMetadataOffset,
            "metadata offset " + str(metadata_offset) + " lies inside the header");
  }
  if (metadata_size > size) {
    fail_at(path, offset::kMetadataSize,
            "the metadata is " + str(metadata_size) + " bytes long, more than the whole file (" +
                str(size) + " bytes): the header is corrupt");
  }
  if (metadata_offset > size || metadata_size > size - metadata_offset) {
    fail_at(path, size,
            "file ends early: the metadata needs bytes " + str(metadata_offset) + " to " +
                str(metadata_offset + metadata_size) + ", the file has only " + str(size) +
                " bytes; it was probably truncated");
  }
  file->metadata_.assign(view.data() + metadata_offset, metadata_size);
  if (load_u32(b + offset::kCompatFlags) & kCompatFeatures) {
    const std::uint64_t at = load_u64(b + kFeaturesOffsetAt), bytes = load_u64(b + kFeaturesSizeAt);
    if (at < header_size || bytes == 0 || at > size || bytes > size - at) {
      fail_at(path, kFeaturesOffsetAt,
              "the sharp-features section (bytes " + str(at) + " to " + str(at + bytes) +
                  ") is not inside the file (" + str(size) +
                  " bytes); it was probably truncated");
    }
    file->features_offset_ = at;
    file->features_size_ = bytes;
  }
  if (load_u32(b + offset::kCompatFlags) & kCompatMesh) {
    const std::uint64_t at = load_u64(b + kMeshOffsetAt);
    if (at < header_size || at > size) {
      fail_at(path, kMeshOffsetAt,
              "the mesh faces' section starts at byte " + str(at) + ", outside the file (" +
                  str(size) + " bytes); it was probably truncated");
    }
    file->mesh_size_ = mesh_section_size(view.substr(at), at, path);
    file->mesh_offset_ = at;
  }
  return file;
}

PtlV2File::~PtlV2File() = default;

template <bool kParents, class OnRecord>
std::uint32_t PtlV2File::scan_page(std::uint32_t page, std::vector<Sphere>& root_spheres,
                                   std::vector<std::uint8_t>& root_child_counts,
                                   OnRecord&& on_record, const PagePrefix& prefix,
                                   std::uint32_t* scanned,
                                   std::span<const std::uint32_t> known) const {
  assert(page < pages_.size());
  const PtlV2PageInfo& info = pages_[page];
  const auto* base = reinterpret_cast<const std::uint8_t*>(map_->bytes.view().data());
  const std::uint8_t* b = base + info.offset;
  const auto which = [&] { return "page " + str(page) + ": "; };
  const std::uint32_t roots = info.root_count;
  root_spheres.resize(roots);
  root_child_counts.resize(roots);
  for (std::uint32_t r = 0; r < roots; ++r) {
    const Sphere sphere{load_vec(b + 16 * r), load_f32(b + 16 * r + 12)};
    if (!finite_sphere(sphere)) {
      fail_at(path_, info.offset + 16 * r,
              which() + "root " + str(r) + " sphere is not finite or has a negative radius");
    }
    const std::uint8_t k = b[16 * roots + r];
    if (page == 0 ? k != 1 : (k < 2 || k > 4)) {
      fail_at(path_, info.offset + 16 * roots + r,
              which() + "root " + str(r) + " has child count " + str(k) +
                  (page == 0 ? " (page 0's root: 1)" : " (2 to 4)"));
    }
    root_spheres[r] = sphere;
    root_child_counts[r] = k;
  }
  if (page == 0 && std::memcmp(&root_spheres[0], &root_sphere_, sizeof(Sphere)) != 0) {
    fail_at(path_, info.offset, "page 0's root sphere differs from the header's");
  }
  const std::uint64_t records_at = info.offset + std::uint64_t{roots} * kRootEntrySize;
  const std::uint32_t count = info.node_count, rs = record_size_;
  const bool trim_low_bit = leaf_trim_ == LeafTrim::Sixteenths;
  // Level by level: the parents of level L + 1 are the roots (L = 0) or the interior records of
  // level L, in order; a level holds exactly their children. Child counts of the records seen
  // so far (the scan for the next parent never passes the current record).
  std::vector<std::uint8_t> child_counts(kParents ? count : 0);
  std::uint64_t need = 0;
  for (std::uint32_t r = 0; r < roots; ++r) need += root_child_counts[r];
  std::uint32_t next_root = 0;
  std::uint64_t next_parent = 0;  // scan position for interior records
  std::uint64_t i = 0, level_begin = 0;
  std::uint32_t levels = 0;
  std::uint32_t node_level = 0;  // the level holding prefix.node, once reached
  bool partial = false;
  while (need > 0 && i < count) {
    if (prefix.enough(levels, i, node_level)) {
      partial = true;
      break;
    }
    if (need > count - i) {
      fail_at(path_, records_at + i * rs,
              which() + "level " + str(levels + 1) + " needs " + str(need) +
                  " records, the page has " + str(count - i) + " left of " + str(count));
    }
    level_begin = i;
    const std::uint64_t level_end = i + need;
    ++levels;
    if (node_level == 0 && prefix.node < level_end) node_level = levels;
    need = 0;
    // Record i checked (sphere code, reserved bit, normal code) and passed on.
    const auto take = [&](PageParent parent, bool first_child) {
      const std::uint64_t at = records_at + i * rs;
      const std::uint8_t* r = base + at;
      const bool is_known = i < known.size();
      const std::uint32_t rec = is_known ? known[i] : load_u32(r);
      const std::uint16_t color = rs == 6 && !is_known ? load_u16(r + 4) : 0;
      const std::uint32_t code = bits(rec, kSphereShift, kSphereBits);
      const std::uint32_t children = record_child_count(rec);
      const std::uint32_t normal = bits(rec, kNormalShift, kNormalBits);
      if (code >= kSphereCodeCount) {
        fail_at(path_, at,
                which() + "record " + str(i) + ": sphere code " + str(code) +
                    " is outside the table (0.." + str(kSphereCodeCount - 1) + ")");
      }
      if (bits(rec, kLowTrimShift, 1) != 0 && (children != 0 || !trim_low_bit)) {
        fail_at(path_, at + 1,
                which() + "record " + str(i) + ": reserved bit 15 is set" +
                    (trim_low_bit ? " on an interior node" : ""));
      }
      if (normal >= kNormalCodeCount) {
        fail_at(path_, at + 2,
                which() + "record " + str(i) + ": normal code " + str(normal) +
                    " is outside the table (0.." + str(kNormalCodeCount - 1) + ")");
      }
      if constexpr (kParents) child_counts[i] = static_cast<std::uint8_t>(children);
      need += children;
      if (!is_known) on_record(static_cast<std::uint32_t>(i), rec, color, parent, first_child);
    };
    if constexpr (!kParents) {
      // The level's size is the previous level's child counts' sum, and that is all there is
      // to check of the structure: the records in one run (a loop a parent, of 2 to 4
      // records, mispredicts its end).
      for (; i < level_end; ++i) take(PageParent{}, false);
      continue;
    }
    while (i < level_end) {
      // The level's records are exactly the children of these parents, so the scan stays
      // within the previous level.
      PageParent parent;
      std::uint32_t k;
      if (next_root < roots) {
        parent = {true, next_root};
        k = root_child_counts[next_root++];
      } else {
        while (child_counts[next_parent] == 0) ++next_parent;
        parent = {false, static_cast<std::uint32_t>(next_parent)};
        k = child_counts[next_parent++];
      }
      for (std::uint32_t c = 0; c < k; ++c, ++i) take(parent, c == 0);
    }
  }
  if (scanned != nullptr) *scanned = static_cast<std::uint32_t>(i);
  if (partial) return static_cast<std::uint32_t>(level_begin);
  if (i != count) {
    fail_at(path_, records_at + i * rs,
            which() + "record " + str(i) + " of " + str(count) +
                " has no parent (the tree of the page ends before it)");
  }
  if (levels != info.level_count) {
    fail_at(path_, records_at + std::uint64_t{count} * rs - rs,
            which() + "the records form " + str(levels) + " levels, the page table says " +
                str(info.level_count));
  }
  // The last level's interior nodes have their children in child pages.
  return static_cast<std::uint32_t>(level_begin);
}

void PtlV2File::decode_page(std::uint32_t page, PtlV2Page& out) const {
  out.nodes.resize(pages_[page].node_count);
  const DecodeTables tables;
  out.last_level_begin = scan_page(
      page, out.root_spheres, out.root_child_counts,
      [&](std::uint32_t i, std::uint32_t rec, std::uint16_t color, PageParent parent,
          bool first_child) {
        if (parent.is_root) {
          decode_node_into(tables, rec, color, has_colors_, leaf_trim_,
                           out.root_spheres[parent.index], out.nodes[i]);
        } else {
          SphereNode& pn = out.nodes[parent.index];
          if (first_child) pn.first_child = i;
          decode_node_into(tables, rec, color, has_colors_, leaf_trim_, pn, out.nodes[i]);
        }
      });
}

void PtlV2File::forget_page(std::uint32_t page) const {
  assert(page < pages_.size());
  // Dropping the mapping page by page costs a system call and a fault of the surrounding
  // folio again for the next page read nearby (a 20 M-point model's full frame: 1.12-1.24x
  // the time): the whole mapping is let go at once, each time the pages copied since reach
  // kForgetBytes or an eighth of the file. The mapped part of the file then stays under about
  // that much.
  const std::uint64_t since =
      map_->copied_since_forget.fetch_add(pages_[page].byte_size) + pages_[page].byte_size;
  // One thread of those that cross the mark unmaps (the one whose count is still current).
  std::uint64_t seen = since;
  if (since < std::min(kForgetBytes, size_ / 8) ||
      !map_->copied_since_forget.compare_exchange_strong(seen, 0)) {
    return;
  }
  map_->bytes.forget();
}

std::uint32_t PtlV2File::page_record(std::uint32_t page, std::uint32_t k) const {
  assert(page < pages_.size() && k < pages_[page].node_count);
  const PtlV2PageInfo& info = pages_[page];
  const auto* base = reinterpret_cast<const std::uint8_t*>(map_->bytes.view().data());
  return load_u32(base + info.offset + std::uint64_t{info.root_count} * kRootEntrySize +
                  std::uint64_t{k} * record_size_);
}

void PtlV2File::pack_page(std::uint32_t page, PackedPage& out, const PagePrefix& prefix) const {
  const std::uint32_t count = pages_[page].node_count;
  const std::size_t known = std::min<std::size_t>(out.records.size(), count);
  out.records.resize(count);
  out.colors.resize(has_colors_ ? count : 0);
  out.links.clear();
  out.leaf_trim = leaf_trim_;
  std::vector<Sphere> root_spheres;
  std::vector<std::uint8_t> root_child_counts;
  std::uint32_t scanned = count;
  out.last_level_begin = scan_page</*kParents=*/false>(
      page, root_spheres, root_child_counts,
      [&](std::uint32_t i, std::uint32_t rec, std::uint16_t color, PageParent, bool) {
        out.records[i] = rec;
        if (has_colors_) out.colors[i] = color;
      },
      prefix, &scanned, std::span<const std::uint32_t>(out.records.data(), known));
  if (scanned < count) {
    // The last loaded level's children are further down this page: every loaded record links
    // to its children's place in the page (past the loaded ones for that level).
    out.last_level_begin = scanned;
    out.records.resize(scanned);
    out.records.shrink_to_fit();
    if (has_colors_) {
      out.colors.resize(scanned);
      out.colors.shrink_to_fit();
    }
  }
  std::uint32_t first_level = 0;
  for (const std::uint8_t k : root_child_counts) first_level += k;
  out.index_links(first_level);
  out.root_parent = root_spheres[0];
  if (page == 0) return;
  const PtlV2PageInfo& info = pages_[page];
  // The traversal reaches this page through its roots' records in the parent page, whose child
  // counts must be the ones this page's first level was checked against.
  const PtlV2PageInfo& parent = pages_[info.parent_page];
  const auto* base = reinterpret_cast<const std::uint8_t*>(map_->bytes.view().data());
  const std::uint64_t parent_records =
      parent.offset + std::uint64_t{parent.root_count} * kRootEntrySize;
  for (std::uint32_t r = 0; r < info.root_count; ++r) {
    const std::uint64_t at = parent_records + std::uint64_t{info.first_root + r} * record_size_;
    const std::uint32_t children = record_child_count(load_u32(base + at));
    if (children == 0 || children != root_child_counts[r]) {
      fail_at(path_, info.offset + 16 * info.root_count + r,
              "page " + str(page) + ": root " + str(r) + " has " + str(root_child_counts[r]) +
                  " children, record " + str(info.first_root + r) + " of parent page " +
                  str(info.parent_page) + " (byte " + str(at) + ") has " +
                  str(children));
    }
  }
}

PtlModel read_ptl(const std::string& path) {
  const std::uint32_t version = ptl_file_version(path);
  PtlModel model;
  if (version == kPtlV2Version) {
    const auto file = PtlV2File::open(path);
    model.tree = file->decode_all();
    model.metadata = file->metadata();
    model.file_size = file->file_size();
  } else {
    // Version 1, a bad magic or an unknown version: PtlFile says what is wrong.
    const auto file = PtlFile::open(path);
    const SphereTreeView& t = file->tree();
    model.tree.nodes.assign(t.nodes.begin(), t.nodes.end());
    model.tree.has_colors = t.has_colors;
    model.tree.leaf_count = t.leaf_count;
    model.tree.depth = t.depth;
    model.tree.bounds = t.bounds;
    model.tree.view_sphere = t.view_sphere;
    model.metadata = file->metadata();
    model.file_size = file->file_size();
  }
  model.version = version == kPtlV2Version ? kPtlV2Version : 1;
  return model;
}

}  // namespace pointillist
