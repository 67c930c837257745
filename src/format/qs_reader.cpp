// Reading QSplat .qs 1.1 files (Rusinkiewicz & Levoy, "QSplat: A Multiresolution Point Rendering
// System for Large Meshes", SIGGRAPH 2000; layout in ../shared/specs/qsplat-qs-format.md §2-7).
// The whole file is validated while it is decoded breadth-first, so corrupt input ends in a
// FormatError with a byte offset, never in an out-of-bounds read or an endless loop.
#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "printable.hpp"
#include "qs_assemble.hpp"
#include "qs_layout.hpp"
#include "qs_tables.hpp"
#include "pointillist/core/file_bytes.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/format/qs.hpp"

namespace pointillist {
namespace {

using namespace qs_detail;

[[noreturn]] void fail_at(const std::string& path, std::uint64_t byte, const std::string& what) {
  throw FormatError(path + ": byte " + std::to_string(byte) + ": " + what);
}


std::string str(std::uint64_t v) { return std::to_string(v); }
// A signed 32-bit field as the spec reads it, with its raw bytes: "-1 (0xffffffff)".
std::string int32_field(std::int32_t v) {
  char hex[16];
  std::snprintf(hex, sizeof hex, "%08x", static_cast<std::uint32_t>(v));
  return std::to_string(v) + " (0x" + hex + ")";
}

// Reads the fragment header at `at` (spec §2.1-2.3) and checks it against the file.
QsFragment read_fragment_header(const std::string& path, const std::uint8_t* file,
                                std::uint64_t size, std::uint64_t at) {
  const std::uint64_t left = size - at;
  const std::uint8_t* h = file + at;
  if (left < kCommentHeaderSize) {
    fail_at(path, size,
            "file ends early: a fragment header needs at least " + str(kCommentHeaderSize) +
                " bytes from byte " + str(at) + ", only " + str(left) +
                " remain; the file was probably truncated");
  }
  if (std::memcmp(h, kMagic, sizeof kMagic) != 0) {
    fail_at(path, at,
            (at == 0 ? std::string("not a QSplat file: ") : std::string()) +
                "expected the fragment magic \"QSplat\", found " +
                format_detail::printable_bytes(h, sizeof kMagic));
  }
  if (std::memcmp(h + offset::kVersion, kVersion, sizeof kVersion) != 0) {
    fail_at(path, at + offset::kVersion,
            "QSplat version " + format_detail::printable_bytes(h + offset::kVersion, 2) +
                ", this reader knows only version \"11\" (QSplat 1.1)");
  }
  QsFragment f;
  f.offset = at;
  f.options = load_be32(h + offset::kOptions);
  f.is_comment = (f.options & kQsOptionComment) != 0;
  if ((f.options & ~(kQsOptionColor | kQsOptionComment)) != 0) {
    fail_at(path, at + offset::kOptions,
            "options word " + str(f.options) +
                " has unknown bits (expected 0 or 1 for a tree, 2 for a comment)");
  }
  const std::uint32_t header_size = f.is_comment ? kCommentHeaderSize : kTreeHeaderSize;
  if (left < header_size) {
    fail_at(path, size,
            "file ends early: the tree fragment header at byte " + str(at) + " needs " +
                str(header_size) + " bytes, only " + str(left) +
                " remain; the file was probably truncated");
  }
  const auto length = static_cast<std::int32_t>(load_be32(h + offset::kLength));
  if (length < static_cast<std::int32_t>(header_size)) {
    fail_at(path, at + offset::kLength,
            "fragment length " + int32_field(length) + " is shorter than the " +
                str(header_size) + "-byte " + (f.is_comment ? "comment" : "tree") +
                " fragment header");
  }
  f.length = static_cast<std::uint32_t>(length);
  if (f.length > left) {
    fail_at(path, at + offset::kLength,
            "fragment length " + str(f.length) + " runs to byte " + str(at + f.length) +
                ", past the end of the file (" + str(size) +
                " bytes); the file was probably truncated");
  }
  if (f.is_comment) return f;

  const auto leaves = static_cast<std::int32_t>(load_be32(h + offset::kLeafCount));
  if (leaves < 1) {
    fail_at(path, at + offset::kLeafCount,
            "leaf count " + int32_field(leaves) + ", expected at least 1");
  }
  f.leaf_count = static_cast<std::uint32_t>(leaves);
  f.root.center = {load_be_float(h + offset::kCenter), load_be_float(h + offset::kCenter + 4),
                   load_be_float(h + offset::kCenter + 8)};
  f.root.radius = load_be_float(h + offset::kRadius);
  if (!is_finite(f.root.center)) {
    fail_at(path, at + offset::kCenter, "root sphere centre is not finite");
  }
  if (!(std::isfinite(f.root.radius) && f.root.radius > 0)) {
    fail_at(path, at + offset::kRadius,
            "root sphere radius " + std::to_string(f.root.radius) +
                ", expected positive and finite");
  }
  f.root_child_count = load_be32(h + offset::kRootChildren);
  if (f.root_child_count < 2 || f.root_child_count > 4) {
    fail_at(path, at + offset::kRootChildren,
            "root child count " + int32_field(static_cast<std::int32_t>(f.root_child_count)) +
                ", expected 2, 3 or 4");
  }
  return f;
}

// Where the next child groups are expected, in the order they must appear (breadth-first).
struct PendingGroup {
  std::uint64_t at;         // file offset the parent's pointer gives
  std::uint64_t record_at;  // the parent's record (or fragment header) offset, for messages
  bool has_pointer;
};

// Decodes one tree fragment breadth-first (spec §3-7), checking every group's position and
// size against the parent pointers and the fragment end.
DecodedTree decode_fragment(const std::string& path, const std::uint8_t* file, QsFragment& f,
                            QsStats& stats) {
  const bool color = (f.options & kQsOptionColor) != 0;
  const std::uint32_t record_size = color ? 6 : 4;
  const std::uint64_t end = f.offset + f.length;
  const auto normals = normal_table();

  DecodedTree tree;
  tree.has_colors = color;
  std::vector<SphereNode>& nodes = tree.nodes;
  nodes.reserve(1 + (f.length - kTreeHeaderSize) / record_size);
  SphereNode root;
  root.center = f.root.center;
  root.radius = f.root.radius;
  root.child_count = static_cast<std::uint8_t>(f.root_child_count);
  nodes.push_back(root);

  // The root's group always starts with a pointer (the viewer reads one unconditionally).
  std::vector<PendingGroup> pending{{f.offset + kTreeHeaderSize, f.offset, true}};
  std::size_t next_pending = 0;
  std::uint64_t cursor = f.offset + kTreeHeaderSize;
  std::uint64_t leaves = 0;
  std::size_t level_end = 1;
  tree.level_start = {0, 1};

  for (std::size_t p = 0; p < nodes.size(); ++p) {
    if (p == level_end) {
      level_end = nodes.size();
      tree.level_start.push_back(level_end);
    }
    const std::uint32_t k = nodes[p].child_count;
    if (k == 0) continue;
    const Vec3f pc = nodes[p].center;
    const float pr = nodes[p].radius;
    const PendingGroup group = pending[next_pending++];
    const auto owner = [&] {
      return p == 0 ? std::string("the root") : "the record at byte " + str(group.record_at);
    };
    if (cursor != group.at) {
      fail_at(path, cursor,
              "the child group of " + owner() +
                  " should start here (groups are stored breadth-first, one after the other), "
                  "but the pointer of the group holding that record says byte " +
                  str(group.at));
    }
    const std::uint64_t need = (group.has_pointer ? 4 : 0) + std::uint64_t{k} * record_size;
    if (need > end - cursor) {
      fail_at(path, cursor,
              "the child group of " + owner() + " needs " + str(need) + " bytes (" + str(k) +
                  " records), but the fragment ends at byte " + str(end));
    }
    std::uint64_t there = 0;  // where the next child's own group must start
    if (group.has_pointer) {
      const auto pointer = static_cast<std::int32_t>(load_be32(file + cursor));
      if (pointer <= 0) {
        fail_at(path, cursor,
                "group pointer " + int32_field(pointer) +
                    ", expected a positive distance to the first grandchild group");
      }
      there = cursor + static_cast<std::uint64_t>(pointer);
      cursor += 4;
    }
    nodes[p].first_child = static_cast<std::uint32_t>(nodes.size());
    bool any_grandchild = false;
    for (std::uint32_t i = 0; i < k; ++i, cursor += record_size) {
      const std::uint8_t* r = file + cursor;
      const std::uint16_t w0 = load_be16(r), w1 = load_be16(r + 2);
      const std::uint32_t s = w0 >> 3, g = (w0 >> 2) & 1u, c = w0 & 3u, q = w1 >> 2,
                          cone = w1 & 3u;
      if (s >= kSphereCodeCount && s != kOutOfTableSphereCode) {
        fail_at(path, cursor,
                "sphere code " + str(s) + " is outside the table (expected 0.." +
                    str(kSphereCodeCount - 1) + ", or " + str(kOutOfTableSphereCode) +
                    " as QSplat 1.0 writes for a cube not in the table); the file is corrupt");
      }
      if (c == 0 && g != 0) {
        fail_at(path, cursor, "a leaf record (child-count code 0) has its grandchild bit set");
      }
      if (nodes.size() >= std::size_t{1} << 32) {
        fail_at(path, cursor, "more than 2^32 nodes");
      }
      // QSplat 1.0's out-of-table code decodes as its viewer does (parent centre, radius 0).
      if (s == kOutOfTableSphereCode) ++stats.out_of_table_records;
      const Sphere decoded = decode_qs_sphere({pc, pr}, s);
      SphereNode n;
      n.center = decoded.center;
      n.radius = decoded.radius;
      n.normal = q < kNormalCodeCount ? normals[q] : Vec3f{0, 0, 1};
      n.child_count = static_cast<std::uint8_t>(child_count_of_code(c));
      n.cone_sin = c == 0 ? 0.0f : (cone == 3 ? 2.0f : cone_sin_bound(cone));
      if (color) n.color = decode_rgb565(load_be16(r + 4));
      // |c - c_parent| + r > r_parent: spheres that touch the parent from inside and stick out
      // only by float rounding (~1e-7 of the radius) are not counted.
      const double dx = double(n.center.x) - pc.x, dy = double(n.center.y) - pc.y,
                   dz = double(n.center.z) - pc.z;
      const double slack = pr * (1 + 1e-5) - n.radius;
      if (slack < 0 || dx * dx + dy * dy + dz * dz > slack * slack) ++stats.records_outside_parent;
      ++stats.child_count_histogram[n.child_count];
      ++stats.cone_code_histogram[cone];
      if (c == 0) {
        ++leaves;
      } else {
        any_grandchild = true;
        const std::uint64_t group_size = std::uint64_t{n.child_count} * record_size + 4 * g;
        pending.push_back({there, cursor, g != 0});
        there += group_size;
      }
      nodes.push_back(n);
    }
    if (p != 0 && group.has_pointer != any_grandchild) {
      fail_at(path, group.record_at,
              group.has_pointer
                  ? "grandchild bit set, but none of the record's children has children"
                  : "grandchild bit clear, but a child of the record has children");
    }
  }
  // The last level's end was pushed when the loop reached that level: level_start.back() is
  // nodes.size().

  f.padding = static_cast<std::uint32_t>(end - cursor);
  if (end - cursor > 3) {
    fail_at(path, cursor,
            "the tree ends here, but the fragment length says it ends at byte " + str(end) +
                " (" + str(end - cursor) + " extra bytes; at most 3 bytes of padding)");
  }
  if (leaves != f.leaf_count) {
    fail_at(path, f.offset + offset::kLeafCount,
            "the header says " + str(f.leaf_count) + " leaves, the tree has " + str(leaves));
  }
  const std::size_t levels = tree.level_start.size() - 1;
  if (stats.records_per_level.size() < levels - 1) stats.records_per_level.resize(levels - 1);
  for (std::size_t j = 1; j < levels; ++j) {
    stats.records_per_level[j - 1] += tree.level_start[j + 1] - tree.level_start[j];
  }
  stats.leaf_count += leaves;
  stats.record_count += nodes.size() - 1;
  return tree;
}

}  // namespace

QsModel read_qs(const std::string& path) {
  const FileBytes bytes = FileBytes::map(path);
  const auto* file = reinterpret_cast<const std::uint8_t*>(bytes.view().data());
  const std::uint64_t size = bytes.view().size();
  if (size == 0) fail_at(path, 0, "the file is empty (expected a QSplat .qs file)");

  QsModel model;
  model.file_size = size;
  std::vector<DecodedTree> trees;
  for (std::uint64_t at = 0; at < size;) {
    QsFragment f = read_fragment_header(path, file, size, at);
    if (f.is_comment) {
      std::size_t text_size = f.length - kCommentHeaderSize;
      const char* text = reinterpret_cast<const char*>(file + at + kCommentHeaderSize);
      for (int i = 0; i < 3 && text_size > 0 && text[text_size - 1] == '\0'; ++i) --text_size;
      model.comments.append(text, text_size);
    } else {
      trees.push_back(decode_fragment(path, file, f, model.stats));
    }
    model.fragments.push_back(f);
    at += f.length;
  }
  if (trees.empty()) {
    fail_at(path, size, "the file has only comment fragments, no tree fragment to draw");
  }
  model.tree = assemble_tree(std::move(trees), model.stats);
  return model;
}

bool is_qs_file(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return false;
  char magic[sizeof kMagic];
  std::size_t got = 0;
  while (got < sizeof magic) {
    const ssize_t n = ::read(fd, magic + got, sizeof magic - got);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    got += static_cast<std::size_t>(n);
  }
  ::close(fd);
  return got == sizeof magic && std::memcmp(magic, kMagic, sizeof magic) == 0;
}

std::string QsModel::metadata() const {
  std::string s = "format: QSplat .qs 1.1, " + str(fragments.size()) + " fragment" +
                  (fragments.size() == 1 ? "" : "s") + "\n";
  for (const QsFragment& f : fragments) {
    s += "fragment: byte " + str(f.offset) + ", " + str(f.length) + " bytes, ";
    if (f.is_comment) {
      s += "comment\n";
    } else {
      s += str(f.leaf_count) + " leaves" +
           ((f.options & kQsOptionColor) != 0 ? ", colour" : "") + "\n";
    }
  }
  std::size_t start = 0;
  while (start < comments.size()) {
    std::size_t stop = comments.find('\n', start);
    if (stop == std::string::npos) stop = comments.size();
    s += "comment: " + comments.substr(start, stop - start) + "\n";
    start = stop + 1;
  }
  s += "records: " + str(stats.record_count) + " (" + str(stats.leaf_count) + " leaves), " +
       str(stats.records_outside_parent) + " not inside their parent as stored" +
       (stats.out_of_table_records == 0
            ? std::string()
            : ", " + str(stats.out_of_table_records) + " with the out-of-table sphere code") +
       "\n";
  s += "enclosure fix: " + str(stats.spheres_enlarged) + " spheres enlarged, " +
       str(stats.cones_widened) + " normal cones widened\n";
  return s;
}

}  // namespace pointillist
