// Writing a .ptl version 2 file in parts (see PtlV2PartWriter in ptl_v2.hpp): the top of the
// hierarchy over the subtrees' roots lives in page 0; each subtree's pages follow, planned from
// its shape alone, so the layout is known before any subtree is encoded.
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include "ptl_v2_codec.hpp"
#include "ptl_v2_encode.hpp"
#include "pointillist/core/atomic_file.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/format/ptl_v2.hpp"

namespace pointillist {

using namespace ptl2;

namespace {

std::uint32_t record_size_for(bool colors, const PtlV2WriteOptions& options) {
  return colors && options.write_colors ? 6 : 4;
}

}  // namespace

PtlV2SubtreeSummary summarize_ptl_v2_subtree(const SphereTree& tree,
                                             const PtlV2WriteOptions& options) {
  PtlV2SubtreeSummary s;
  std::uint64_t leaves = 0;
  std::uint32_t depth = 0;
  check_tree("a subtree", tree.nodes, leaves, depth);
  const auto& nodes = tree.nodes;
  const std::size_t n = nodes.size();
  s.root = nodes[0];
  s.node_count = n;
  s.leaf_count = leaves;
  s.depth = depth;
  if (nodes[0].child_count > 0) {
    const std::uint32_t record_size = record_size_for(tree.has_colors, options);
    const std::vector<PagePlan> plan = plan_pages(nodes, record_size, options.page_bytes, true);
    std::uint64_t offset = 0;
    for (const PagePlan& pg : plan) {
      s.pages.push_back(page_entry(pg, offset));
      offset += pg.byte_size;
    }
  }
  return s;
}

struct PtlV2PartWriter::State {
  std::string path;
  PtlV2WriteOptions options;
  bool colors = false;
  std::uint32_t record_size = 4;
  std::vector<PtlV2SubtreeSummary> subtrees;
  SphereTree top;
  std::size_t first_root = 0;  // index of subtree 0's root in the top (its last level)
  EncodedTree top_codes;                    // the top's cones are added by finish
  std::vector<std::uint32_t> root_cone;     // each subtree's root's cone code, once written
  std::vector<PtlV2PageInfo> table;         // the whole file's
  std::vector<std::uint32_t> first_page;    // table index of each subtree's first page
  std::vector<std::uint8_t> written;  // bytes, not bits: subtrees are written concurrently
  std::vector<EncodeStats> subtree_stats;  // merged in order by finish()
  std::uint64_t metadata_offset = 0;
  std::uint64_t node_count = 0, leaf_count = 0;
  std::uint32_t depth = 0;
  EncodeStats stats;
  std::optional<AtomicFile> file;  // the file's owner's
  int join_fd = -1;                // a joining writer's: the owner's temporary file
  std::string join_path;
  HeaderFields header;  // as finish_uncommitted wrote it
  bool finished = false;

  // The file of a writer that owns it; a joining writer only writes subtrees.
  AtomicFile& own_file() {
    if (!file) {
      throw Error("cannot finish " + path + " here: this process writes subtrees into the file "
                  "of the process that owns it (MPI rank 0), which finishes it");
    }
    return *file;
  }
  void write_bytes(std::uint64_t offset, const void* data, std::size_t size) {
    if (file) {
      file->write_at(offset, data, size);
      return;
    }
    if (!write_all_at(join_fd, offset, data, size)) {
      throw IoError(errno_message(join_path + ": cannot write a subtree at byte " +
                                  std::to_string(offset)) +
                    "; check the free disk of the output's folder");
    }
  }
};

PtlV2PartWriter::PtlV2PartWriter(const std::string& path,
                                 std::vector<PtlV2SubtreeSummary> subtrees, bool has_colors,
                                 const PtlV2WriteOptions& options, const std::string& join)
    : state_(std::make_unique<State>()) {
  State& st = *state_;
  if (options.page_bytes < kMinPageBytes) {
    throw OptionError("page_bytes " + std::to_string(options.page_bytes) +
                      " is below the minimum " + std::to_string(kMinPageBytes));
  }
  if (options.features) {
    throw OptionError("cannot write " + path + " in parts with sharp features (not built yet)");
  }
  st.path = path;
  st.options = options;
  st.colors = has_colors && options.write_colors;
  st.record_size = record_size_for(has_colors, options);
  st.subtrees = std::move(subtrees);
  const std::size_t count = st.subtrees.size();
  std::vector<SphereNode> roots;
  roots.reserve(count);
  for (const PtlV2SubtreeSummary& s : st.subtrees) roots.push_back(s.root);
  st.top = build_top_tree(roots, has_colors);
  SphereTree& top = st.top;
  const std::size_t top_count = top.nodes.size();
  st.first_root = top_count - count;

  // The top's records, top-down against decoded parents (its last level: the subtrees' roots,
  // encoded as interior nodes when they have children), then normals; cones wait for finish
  // (an interior root's cone holds its children's decoded cones: its subtree's encoding finds it).
  std::vector<std::uint32_t> parent(top_count, 0);
  for (std::size_t i = 0; i < st.first_root; ++i) {
    for (std::uint32_t k = 0; k < top.nodes[i].child_count; ++k)
      parent[top.nodes[i].first_child + k] = static_cast<std::uint32_t>(i);
  }
  std::vector<Sphere> target(top_count);
  for (std::size_t i = 0; i < top_count; ++i) target[i] = {top.nodes[i].center, top.nodes[i].radius};
  EncodedTree& enc = st.top_codes;
  enc.root_parent = count == 1 && top.nodes[0].child_count == 0 ? target[0] : grown(target[0]);
  enc.decoded.resize(top_count);
  enc.record.assign(top_count, 0);
  for (std::size_t i = 0; i < top_count; ++i) {
    const Sphere& p = i == 0 ? enc.root_parent : enc.decoded[parent[i]];
    std::uint64_t fallbacks = st.stats.parent_fallbacks;
    const SphereCode code =
        encode_sphere(p, target[i], top.nodes[i].child_count, options.leaf_trim, st.stats);
    if (i == 0) st.stats.parent_fallbacks = fallbacks;
    enc.decoded[i] = code.decoded;
    enc.record[i] = code.bits;
    enc.record[i] |= std::uint64_t{encode_normal_nearest(normalized(top.nodes[i].normal))}
                     << kNormalShift;
  }
  if (st.colors) {
    for (std::size_t i = 0; i < top_count; ++i)
      enc.record[i] |= std::uint64_t{encode_rgb565_nearest(top.nodes[i].color)} << kColorShift;
  }

  // The layout: page 0 holds the whole top; then each subtree's pages.
  std::uint64_t pages = 1;
  for (const PtlV2SubtreeSummary& s : st.subtrees) pages += s.pages.size();
  if (pages >= kPtlNoPage) throw Error("cannot write " + path + ": too many pages");
  std::uint64_t offset = kHeaderSize + pages * kPageEntrySize;
  PtlV2PageInfo top_page;
  top_page.offset = offset;
  top_page.byte_size = static_cast<std::uint32_t>(kRootEntrySize + top_count * st.record_size);
  top_page.node_count = static_cast<std::uint32_t>(top_count);
  top_page.parent_page = kPtlNoPage;
  top_page.root_count = 1;
  top_page.level_count = top.depth + 1;
  st.table.push_back(top_page);
  offset += top_page.byte_size;
  st.node_count = top_count;
  st.leaf_count = 0;
  st.depth = top.depth;
  for (std::size_t k = 0; k < count; ++k) {
    const PtlV2SubtreeSummary& s = st.subtrees[k];
    st.node_count += s.node_count - 1;
    st.leaf_count += s.leaf_count;
    st.depth = std::max(st.depth, top.depth + s.depth);
    const auto base = static_cast<std::uint32_t>(st.table.size());
    st.first_page.push_back(base);
    for (std::size_t p = 0; p < s.pages.size(); ++p) {
      PtlV2PageInfo e = s.pages[p];
      e.offset += offset;
      if (p == 0) {
        e.parent_page = 0;
        e.first_root = static_cast<std::uint32_t>(st.first_root + k);
      } else {
        e.parent_page += base;
      }
      st.table.push_back(e);
    }
    if (!s.pages.empty()) {
      const PtlV2PageInfo& last = s.pages.back();
      offset += last.offset + last.byte_size;
    }
  }
  if (st.node_count > 0xfffffffeu) throw Error("cannot write " + path + ": more than 2^32 - 2 nodes");
  st.metadata_offset = offset;
  st.written.assign(count, 0);
  st.root_cone.assign(count, 0);
  st.subtree_stats.resize(count);
  if (join.empty()) {
    st.file.emplace(path);
    return;
  }
  st.join_path = join;
  st.join_fd = ::open(join.c_str(), O_WRONLY | O_CLOEXEC);
  if (st.join_fd < 0) {
    throw IoError(errno_message(join + ": cannot open the file being written") +
                  "; every rank needs the output's folder, shared (NFS, Lustre, ...)");
  }
}

PtlV2PartWriter::~PtlV2PartWriter() {
  if (state_ && state_->join_fd >= 0) ::close(state_->join_fd);
}

std::size_t PtlV2PartWriter::subtree_count() const { return state_->subtrees.size(); }

void PtlV2PartWriter::write_subtree(std::size_t k, const SphereTree& tree, ThreadPool& pool) {
  State& st = *state_;
  const PtlV2SubtreeSummary& s = st.subtrees.at(k);
  if (tree.nodes.size() != s.node_count || tree.nodes.empty() ||
      std::memcmp(&tree.nodes[0], &s.root, sizeof(SphereNode)) != 0) {
    throw Error("cannot write " + st.path + ": subtree " + std::to_string(k) +
                " is not the one summarized (its root or node count differs)");
  }
  st.written[k] = 1;
  if (s.pages.empty()) return;  // a single leaf: its record is in the top
  std::uint64_t leaves = 0;
  std::uint32_t depth = 0;
  const std::vector<std::uint32_t> parent = check_tree(st.path, tree.nodes, leaves, depth);
  const Sphere& decoded_root = st.top_codes.decoded[st.first_root + k];
  EncodeStats& stats = st.subtree_stats[k];
  const EncodedTree enc = encode_tree(tree.nodes, parent, nullptr, &decoded_root,
                                      st.options.leaf_trim, st.colors, pool, stats);
  // The root's record lives in the top page: its cone is kept for finish and counted there.
  st.root_cone[k] = quant::bits(std::uint32_t(enc.record[0]), kConeShift, kConeBits);
  --stats.cone_codes[st.root_cone[k]];
  const std::vector<PagePlan> plan =
      plan_pages(tree.nodes, st.record_size, st.options.page_bytes, true);
  std::vector<std::uint8_t> bytes;
  std::vector<Sphere> root_spheres;
  std::vector<std::uint8_t> root_children;
  for (std::size_t p = 0; p < plan.size(); ++p) {
    root_spheres.clear();
    root_children.clear();
    for (const std::uint32_t r : plan[p].roots) {
      root_spheres.push_back(enc.decoded[r]);
      root_children.push_back(tree.nodes[r].child_count);
    }
    page_bytes(plan[p], root_spheres, root_children, enc.record, st.record_size, bytes);
    st.write_bytes(st.table[st.first_page[k] + p].offset, bytes.data(), bytes.size());
  }
}

PtlV2WriteReport PtlV2PartWriter::finish(const Aabb& bounds, const Sphere& view_sphere,
                                         const std::array<double, 3>& origin, Vec3f up,
                                         const std::string& metadata) {
  const PtlV2WriteReport report = finish_uncommitted(bounds, view_sphere, origin, up, metadata);
  state_->own_file().commit();
  return report;
}

const std::string& PtlV2PartWriter::temp_path() const {
  return state_->file ? state_->file->temp_path() : state_->join_path;
}

void PtlV2PartWriter::sync() {
  State& st = *state_;
  if (st.file) {
    st.file->sync();
  } else if (::fdatasync(st.join_fd) != 0) {
    throw IoError(errno_message(st.join_path + ": cannot put the subtrees written on disk") +
                  "; check the output's folder");
  }
}

void PtlV2PartWriter::write_at(std::uint64_t offset, const void* data, std::size_t size) {
  state_->own_file().write_at(offset, data, size);
}

// What the owner needs of a subtree another process wrote: its root's cone code and its
// encoding's statistics, as bytes.
std::vector<char> PtlV2PartWriter::written_part(std::size_t k) const {
  const State& st = *state_;
  if (k >= st.written.size() || !st.written[k]) {
    throw Error("cannot pass on subtree " + std::to_string(k) + " of " + st.path +
                ": it was not written by this process (" + std::to_string(st.written.size()) +
                " subtrees)");
  }
  std::vector<char> part(sizeof(std::uint32_t) + sizeof(EncodeStats));
  std::memcpy(part.data(), &st.root_cone[k], sizeof(std::uint32_t));
  std::memcpy(part.data() + sizeof(std::uint32_t), &st.subtree_stats[k], sizeof(EncodeStats));
  return part;
}

void PtlV2PartWriter::adopt_part(std::size_t k, std::span<const char> part) {
  State& st = *state_;
  const std::size_t expected = sizeof(std::uint32_t) + sizeof(EncodeStats);
  if (k >= st.written.size() || part.size() != expected) {
    throw Error("cannot write " + st.path + ": another process passed on subtree " +
                std::to_string(k) + " of " + std::to_string(st.written.size()) + " in " +
                std::to_string(part.size()) + " bytes, where " + std::to_string(expected) +
                " were expected; every rank must run the same pointillist build");
  }
  std::memcpy(&st.root_cone[k], part.data(), sizeof(std::uint32_t));
  std::memcpy(&st.subtree_stats[k], part.data() + sizeof(std::uint32_t), sizeof(EncodeStats));
  st.written[k] = 1;
}

void PtlV2PartWriter::commit_with_features(
    const std::string& metadata,
    const std::function<std::uint64_t(std::uint64_t)>& write_section) {
  State& st = *state_;
  if (!st.finished) {
    throw Error("cannot write " + st.path + ": its features come after finish_uncommitted");
  }
  HeaderFields f = st.header;
  f.metadata_size = metadata.size();
  f.features_offset = f.metadata_offset + metadata.size();
  f.features_size = write_section(f.features_offset);
  if (f.features_size == 0) f.features_offset = 0;
  AtomicFile& file = st.own_file();
  file.write_at(f.metadata_offset, metadata.data(), metadata.size());
  const std::vector<std::uint8_t> head = header_and_table(f, st.table);
  file.write_at(0, head.data(), head.size());
  file.commit();
}

PtlV2WriteReport PtlV2PartWriter::finish_uncommitted(const Aabb& bounds,
                                                     const Sphere& view_sphere,
                                                     const std::array<double, 3>& origin,
                                                     Vec3f up, const std::string& metadata) {
  State& st = *state_;
  AtomicFile& file = st.own_file();
  for (std::size_t k = 0; k < st.written.size(); ++k) {
    if (!st.written[k]) {
      throw Error("cannot write " + st.path + ": subtree " + std::to_string(k) +
                  " of " + std::to_string(st.written.size()) + " was not written");
    }
  }
  for (const EncodeStats& t : st.subtree_stats) {
    st.stats.spheres_enlarged += t.spheres_enlarged;
    st.stats.parent_fallbacks += t.parent_fallbacks;
    st.stats.leaf_ratio_sum += t.leaf_ratio_sum;
    st.stats.leaf_ratio_count += t.leaf_ratio_count;
    for (int c = 0; c < 4; ++c) st.stats.cone_codes[c] += t.cone_codes[c];
  }
  // The top's cones, bottom-up around its decoded normals.
  const SphereTree& top = st.top;
  EncodedTree& enc = st.top_codes;
  for (std::size_t i = top.nodes.size(); i-- > 0;) {
    if (top.nodes[i].child_count == 0) continue;
    const std::uint32_t cone = i >= st.first_root ? st.root_cone[i - st.first_root]
                                                  : encode_cone(top.nodes, enc.record, i);
    ++st.stats.cone_codes[cone];
    enc.record[i] |= std::uint64_t{cone} << kConeShift;
  }
  HeaderFields f;
  f.colors = st.colors;
  f.record_size = st.record_size;
  f.leaf_trim = st.options.leaf_trim;
  f.node_count = st.node_count;
  f.leaf_count = st.leaf_count;
  f.depth = st.depth;
  f.page_bytes = st.options.page_bytes;
  f.metadata_offset = st.metadata_offset;
  f.metadata_size = metadata.size();
  f.root_sphere = st.top_codes.root_parent;
  f.bounds = bounds;
  f.view_sphere = view_sphere;
  f.origin = origin;
  f.up = up;
  const std::vector<std::uint8_t> head = header_and_table(f, st.table);
  file.write_at(0, head.data(), head.size());
  PagePlan top_page;
  top_page.byte_size = st.table[0].byte_size;
  top_page.nodes.resize(st.top.nodes.size());
  for (std::size_t i = 0; i < top_page.nodes.size(); ++i) top_page.nodes[i] = std::uint32_t(i);
  std::vector<std::uint8_t> bytes;
  const Sphere header_root = st.top_codes.root_parent;
  const std::uint8_t one = 1;
  page_bytes(top_page, {&header_root, 1}, {&one, 1}, st.top_codes.record, st.record_size, bytes);
  file.write_at(st.table[0].offset, bytes.data(), bytes.size());
  file.write_at(st.metadata_offset, metadata.data(), metadata.size());
  st.header = f;
  st.finished = true;

  PtlV2WriteReport report;
  report.file_size = st.metadata_offset + metadata.size();
  report.record_bytes = st.node_count * st.record_size;
  report.node_count = st.node_count;
  report.leaf_count = st.leaf_count;
  report.page_count = static_cast<std::uint32_t>(st.table.size());
  report.record_size = st.record_size;
  report.bytes_per_leaf = double(report.file_size) / double(std::max<std::uint64_t>(1, st.leaf_count));
  report.spheres_enlarged = st.stats.spheres_enlarged;
  report.parent_fallbacks = st.stats.parent_fallbacks;
  report.mean_leaf_radius_ratio = st.stats.leaf_ratio_count
                                      ? st.stats.leaf_ratio_sum / double(st.stats.leaf_ratio_count)
                                      : 1;
  for (int c = 0; c < 4; ++c) report.cone_codes[c] = st.stats.cone_codes[c];
  return report;
}

}  // namespace pointillist
