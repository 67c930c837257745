// Writing QSplat .qs 1.1 files the way QSplat 1.0's `qsplat_make` does (Rusinkiewicz & Levoy,
// SIGGRAPH 2000; ../shared/specs/qsplat-qs-format.md §2-8): an optional comment fragment, then
// one tree fragment whose groups are written breadth-first, each child quantized against its
// already decoded parent.
#include <cmath>
#include <cstdint>
#include <deque>
#include <limits>
#include <string>
#include <vector>

#include "qs_layout.hpp"
#include "qs_make.hpp"
#include "qs_tables.hpp"
#include "pointillist/core/atomic_file.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/format/qs.hpp"

namespace pointillist {
namespace {

using namespace qs_detail;

// Comment fragment (§2.2): the PLY comments, one per line, zero-padded to a multiple of 4.
std::vector<std::uint8_t> comment_fragment(const std::vector<std::string>& comments) {
  std::string text;
  for (const std::string& c : comments) {
    text += c;
    text += '\n';
  }
  const std::size_t padding = (4 - text.size() % 4) % 4;
  std::vector<std::uint8_t> out;
  append_magic(out);
  append_be32(out, static_cast<std::uint32_t>(kCommentHeaderSize + text.size() + padding));
  append_be32(out, 0);
  append_be32(out, kQsOptionComment);
  out.insert(out.end(), text.begin(), text.end());
  out.insert(out.end(), padding, 0);
  return out;
}

class TreeWriter {
 public:
  TreeWriter(MakeTree& tree, bool colors, const QsWriteOptions& options)
      : tree_(tree), colors_(colors), record_size_(colors ? 6 : 4), random_(options.dither_seed),
        dither_(options.dither_normals) {}

  // Bytes of the child group of `n` (§3.1); the root's always has a pointer (§12.9).
  std::uint64_t group_size(const MakeNode& n, bool is_root) const {
    return std::uint64_t{n.child_count} * record_size_ + (n.has_grandchild || is_root ? 4 : 0);
  }

  std::uint64_t fragment_length() const {
    std::uint64_t size = kTreeHeaderSize;
    for (std::size_t i = tree_.leaf_count; i < tree_.nodes.size(); ++i) {
      size += group_size(tree_.nodes[i], i == tree_.root);
    }
    return size + (4 - size % 4) % 4;
  }

  // The tree fragment; counts records and levels into `report`.
  std::vector<std::uint8_t> write(QsWriteReport& report) {
    const std::uint64_t length = fragment_length();
    if (length > std::uint64_t{std::numeric_limits<std::int32_t>::max()}) {
      throw Error("too many points for one QSplat fragment (" + std::to_string(length) +
                  " bytes, the format's limit is 2^31 - 1)");
    }
    const MakeNode& root = tree_.nodes[tree_.root];
    std::vector<std::uint8_t> out;
    out.reserve(length);
    append_magic(out);
    append_be32(out, static_cast<std::uint32_t>(length));
    append_be32(out, static_cast<std::uint32_t>(tree_.leaf_count));
    append_be32(out, colors_ ? kQsOptionColor : 0);
    append_be_float(out, root.center.x);
    append_be_float(out, root.center.y);
    append_be_float(out, root.center.z);
    append_be_float(out, root.radius);
    append_be32(out, root.child_count);

    // Breadth-first (§3.3): `pending` is the size of the groups of all queued nodes, which is
    // the distance from a group's pointer to where its first child's group will land.
    std::deque<std::pair<std::uint32_t, std::uint32_t>> queue{{tree_.root, 0}};  // node, level
    std::uint64_t pending = group_size(root, true);
    while (!queue.empty()) {
      const auto [index, level] = queue.front();
      queue.pop_front();
      const bool is_root = index == tree_.root;
      const MakeNode parent = tree_.nodes[index];  // a copy: its children are rewritten below
      if (parent.has_grandchild || is_root) append_be32(out, static_cast<std::uint32_t>(pending));
      pending -= group_size(parent, is_root);
      report.depth = std::max(report.depth, level + 1);
      for (std::uint32_t i = 0; i < parent.child_count; ++i) {
        MakeNode& child = tree_.nodes[parent.children[i]];
        write_record(parent, child, out);
        ++report.record_count;
        if (child.child_count > 0) {
          queue.emplace_back(parent.children[i], level + 1);
          pending += group_size(child, false);
        }
      }
    }
    // Padding repeats the start of the last record (§2.1), as the original does.
    const std::size_t padding = (4 - out.size() % 4) % 4;
    for (std::size_t i = 0; i < padding; ++i) out.push_back(out[out.size() - record_size_]);
    return out;
  }

 private:
  // Encodes `child` against its decoded parent and replaces its sphere by the decoded one (§4.4).
  // The out-of-table code decodes to radius 0, as in QSplat 1.0; only leaves were seen with it,
  // so what the original writes below an interior node with that code is unverified.
  void write_record(const MakeNode& parent, MakeNode& child, std::vector<std::uint8_t>& out) {
    const int code = encode_sphere(parent.center, parent.radius, child.center, child.radius);
    const Sphere decoded = decode_qs_sphere({parent.center, parent.radius}, std::uint32_t(code));
    child.center = decoded.center;
    child.radius = decoded.radius;

    const std::uint32_t c = child.child_count == 0 ? 0 : child.child_count - 1u;
    const std::uint32_t g = child.has_grandchild ? 1 : 0;
    append_be16(out, static_cast<std::uint16_t>(std::uint32_t(code) << 3 | g << 2 | c));
    const std::uint32_t normal = encode_normal(dithered(child.normal));
    append_be16(out, static_cast<std::uint16_t>(normal << 2 | encode_cone(child.cone)));
    if (colors_) append_be16(out, encode_rgb565(child.color));
  }

  // The normal jittered by up to half a grid cell per component, renormalized (§5.2).
  Vec3f dithered(Vec3f n) {
    constexpr float kCell = 2.0f / kNormalGrid;
    float d[3];
    for (float& v : d) {
      const float u = float(random_.next()) / float(GlibcRandom::kMax);
      v = dither_ ? (u - 0.5f) * kCell : 0.0f;
    }
    const Vec3f j{n.x + d[0], n.y + d[1], n.z + d[2]};
    const float inv = 1.0f / std::sqrt(j.x * j.x + j.y * j.y + j.z * j.z);
    return {j.x * inv, j.y * inv, j.z * inv};
  }

  MakeTree& tree_;
  bool colors_;
  std::uint32_t record_size_;
  GlibcRandom random_;
  bool dither_;
};

}  // namespace

QsWriteReport write_qs(const std::string& path, const PointSet& mesh,
                       const QsWriteOptions& options) {
  const bool colors = options.write_colors && mesh.has_colors();
  MakeTree tree = make_leaves(mesh, colors, path);
  if (tree.leaf_count < 2) {
    throw Error("cannot write " + path + " as QSplat: " + std::to_string(tree.leaf_count) +
                " usable points (of " + std::to_string(mesh.size()) +
                "); a QSplat tree needs at least 2");
  }
  if (tree.leaf_count > std::uint64_t{std::numeric_limits<std::int32_t>::max()}) {
    throw Error("cannot write " + path + " as QSplat: more than 2^31 - 1 points");
  }
  build_hierarchy(tree);

  QsWriteReport report;
  report.input_points = mesh.size();
  report.leaf_count = tree.leaf_count;
  std::vector<std::uint8_t> comment;
  if (options.write_comments && !mesh.comments.empty()) comment = comment_fragment(mesh.comments);
  std::vector<std::uint8_t> fragment;
  try {
    fragment = TreeWriter(tree, colors, options).write(report);
  } catch (const Error& e) {
    throw Error("cannot write " + path + " as QSplat: " + e.what());
  }
  report.file_size = comment.size() + fragment.size();

  AtomicFile file(path);
  if (!comment.empty()) file.write(comment.data(), comment.size());  // data() may be null
  file.write(fragment.data(), fragment.size());
  file.commit();
  return report;
}

}  // namespace pointillist
