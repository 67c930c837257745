// Writing .ptl version 2 (docs/ptl-format.md, "Version 2"): QSplat-style quantization
// (Rusinkiewicz & Levoy, SIGGRAPH 2000) with conservative codes (ptl_v2_codec.hpp), records
// grouped into pages of bounded size, written to a temporary file and renamed.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "ptl_header.hpp"
#include "ptl_v2_codec.hpp"
#include "ptl_v2_features.hpp"
#include "ptl_v2_layout.hpp"
#include "pointillist/core/atomic_file.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/format/ptl_v2.hpp"

namespace pointillist {
namespace {

using namespace ptl2;

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw Error("cannot write " + path + " as .ptl version 2: " + what);
}

// Smallest float >= x.
float round_up(double x) {
  float f = static_cast<float>(x);
  if (static_cast<double>(f) < x) f = std::nextafter(f, std::numeric_limits<float>::infinity());
  return f;
}

// Checks values and the breadth-first structure; returns each node's parent (root: itself) and
// fills leaf count and depth.
std::vector<std::uint32_t> check_tree(const std::string& path, const SphereTree& tree,
                                      std::uint64_t& leaves, std::uint32_t& depth) {
  const std::size_t n = tree.nodes.size();
  if (n == 0) fail(path, "the hierarchy has no nodes");
  if (n > std::size_t{0xfffffffe}) fail(path, "more than 2^32 - 2 nodes");
  std::vector<std::uint32_t> parent(n, 0);
  std::uint64_t next_child = 1, level_end = 1, next_level_end = 1;
  leaves = 0;
  depth = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (i == level_end) {
      ++depth;
      level_end = next_level_end;
    }
    const SphereNode& nd = tree.nodes[i];
    const auto where = [&] { return "node " + std::to_string(i) + " of " + std::to_string(n); };
    if (!is_finite(nd.center) || !(std::isfinite(nd.radius) && nd.radius >= 0) ||
        !is_finite(nd.normal) || !(std::isfinite(nd.cone_sin) && nd.cone_sin >= 0)) {
      fail(path, where() + ": a centre, radius, normal or cone that is negative or not finite");
    }
    if (nd.child_count == 0) {
      ++leaves;
      continue;
    }
    if (nd.child_count < 2 || nd.child_count > 4) {
      fail(path,
           where() + ": child count " + std::to_string(nd.child_count) + " (must be 0, 2, 3 or 4)");
    }
    if (nd.first_child != next_child || next_child + nd.child_count > n) {
      fail(path, where() + ": first child " + std::to_string(nd.first_child) + ", expected " +
                     std::to_string(next_child) + " (children stored breadth-first, in range)");
    }
    for (std::uint32_t k = 0; k < nd.child_count; ++k) {
      parent[nd.first_child + k] = static_cast<std::uint32_t>(i);
    }
    next_child += nd.child_count;
    next_level_end = next_child;
  }
  if (next_child != n) {
    fail(path, "node " + std::to_string(next_child) + " is nobody's child");
  }
  return parent;
}

// Relative growth of interior targets (see write_ptl_v2): room for the children's codes, at
// the price of larger interior spheres. Chosen on the dragon's images against its triangles
// (bench/quality.sh, PSNR at 0,0 and 135,20, circles / ellipses): 0.08 gives 27.08/30.85 and
// 29.29/33.53 dB, 0.15 27.67/31.81 and 29.59/33.65, 0.2 27.74/31.83 and 29.82/34.05, 0.25
// 27.70/31.81 and 29.73/33.94, 0.35 27.57/31.66 and 29.66/33.90.
constexpr double kInteriorMargin = 0.2;

// A page stops growing by whole levels when the roots of its child pages would cost more than
// 1/kRootOverheadRatio of the records below them (17 bytes each), so that wide last levels do
// not turn into thousands of tiny subtrees with a root entry each.
constexpr std::uint64_t kRootOverheadRatio = 64;

struct PagePlan {
  std::uint32_t parent_page = kPtlNoPage;
  std::uint32_t first_root = 0;      // record index in the parent page
  std::vector<std::uint32_t> roots;  // node indices; empty for page 0 (the header sphere)
  std::vector<std::uint32_t> nodes;  // node indices in page order
  std::uint32_t level_count = 0;
  std::uint64_t byte_size = 0;
};

// Pages: page 0 holds the root and as many whole levels as fit in `budget` bytes; the interior
// nodes of a page's last level are the roots of the next pages, grouped in order so that each
// group's subtrees fit one page (a subtree too large for a page gets a page of its own, which
// takes its top levels and so on). Pages come in breadth-first order of this page tree.
std::vector<PagePlan> plan_pages(const SphereTree& tree, std::uint32_t record_size,
                                 std::uint64_t budget) {
  const auto& nodes = tree.nodes;
  const std::size_t n = nodes.size();
  std::vector<std::uint64_t> subtree(n, 1);
  for (std::size_t i = n; i-- > 0;) {
    for (std::uint32_t k = 0; k < nodes[i].child_count; ++k) {
      subtree[i] += subtree[nodes[i].first_child + k];
    }
  }
  std::vector<std::uint32_t> local(n, 0);  // record index of each node in its page
  std::vector<PagePlan> pages(1);
  std::vector<std::uint32_t> level, next, frontier;
  for (std::size_t pi = 0; pi < pages.size(); ++pi) {
    level.clear();
    if (pi == 0) {
      level.push_back(0);
    } else {
      for (const std::uint32_t r : pages[pi].roots) {
        for (std::uint32_t k = 0; k < nodes[r].child_count; ++k)
          level.push_back(nodes[r].first_child + k);
      }
    }
    const std::size_t root_count = pi == 0 ? 1 : pages[pi].roots.size();
    std::vector<std::uint32_t> page_nodes = level;
    std::uint64_t bytes = root_count * kRootEntrySize + level.size() * record_size;
    std::uint32_t levels = 1;
    frontier.clear();
    // A forest that fits takes every level (no child pages); otherwise levels are added while
    // they fit and the child pages' roots stay cheap.
    std::uint64_t forest_records = pi == 0 ? subtree[0] : 0;
    for (const std::uint32_t r : pages[pi].roots) forest_records += subtree[r] - 1;
    const bool whole = root_count * kRootEntrySize + forest_records * record_size <= budget;
    for (;;) {
      next.clear();
      for (const std::uint32_t v : level) {
        for (std::uint32_t k = 0; k < nodes[v].child_count; ++k)
          next.push_back(nodes[v].first_child + k);
      }
      if (next.empty()) break;
      std::uint64_t next_frontier = 0, below_next = 0;
      for (const std::uint32_t v : next) {
        if (nodes[v].child_count == 0) continue;
        ++next_frontier;
        below_next += subtree[v] - 1;
      }
      const bool roots_too_costly =
          !whole && next_frontier * kRootEntrySize * kRootOverheadRatio > below_next * record_size;
      if (bytes + next.size() * record_size > budget || roots_too_costly) {
        for (const std::uint32_t v : level) {
          if (nodes[v].child_count > 0) frontier.push_back(v);
        }
        break;
      }
      page_nodes.insert(page_nodes.end(), next.begin(), next.end());
      bytes += next.size() * record_size;
      ++levels;
      std::swap(level, next);
    }
    for (std::size_t j = 0; j < page_nodes.size(); ++j) local[page_nodes[j]] = std::uint32_t(j);
    // Group the frontier into child pages, in order.
    std::vector<std::uint32_t> group;
    std::uint64_t group_bytes = 0;
    const auto flush = [&] {
      if (group.empty()) return;
      PagePlan child;
      child.parent_page = static_cast<std::uint32_t>(pi);
      child.first_root = local[group.front()];
      child.roots = group;
      pages.push_back(std::move(child));
      group.clear();
      group_bytes = 0;
    };
    for (const std::uint32_t f : frontier) {
      const std::uint64_t need = kRootEntrySize + (subtree[f] - 1) * record_size;
      if (need > budget) {
        flush();
        group.push_back(f);
        flush();
        continue;
      }
      if (group_bytes + need > budget) flush();
      group.push_back(f);
      group_bytes += need;
    }
    flush();
    pages[pi].nodes = std::move(page_nodes);
    pages[pi].level_count = levels;
    pages[pi].byte_size = bytes;
  }
  return pages;
}

}  // namespace

PtlV2WriteReport write_ptl_v2(const std::string& path, const SphereTree& tree,
                              const std::string& metadata, const PtlV2WriteOptions& options) {
  ThreadPool pool(1);
  return write_ptl_v2(path, tree, metadata, options, pool);
}

PtlV2WriteReport write_ptl_v2(const std::string& path, const SphereTree& tree,
                              const std::string& metadata, const PtlV2WriteOptions& options,
                              ThreadPool& pool) {
  if (options.page_bytes < kMinPageBytes) {
    throw OptionError("page_bytes " + std::to_string(options.page_bytes) +
                      " is below the minimum " + std::to_string(kMinPageBytes));
  }
  PtlV2WriteReport report;
  std::uint64_t leaves = 0;
  std::uint32_t depth = 0;
  const std::vector<std::uint32_t> parent = check_tree(path, tree, leaves, depth);
  const auto& nodes = tree.nodes;
  const std::size_t n = nodes.size();
  const bool colors = options.write_colors && tree.has_colors;
  const std::uint32_t record_size = colors ? 6 : 4;

  // Targets: the tree's spheres, enlarged bottom-up where a child sticks out (in double, rounded
  // up), so each parent's decoded sphere, which encloses its target, can enclose its children's.
  std::vector<Sphere> target(n);
  for (std::size_t i = 0; i < n; ++i) target[i] = {nodes[i].center, nodes[i].radius};
  for (std::size_t i = n; i-- > 0;) {
    double need = 0;
    for (std::uint32_t k = 0; k < nodes[i].child_count; ++k) {
      const Sphere& c = target[nodes[i].first_child + k];
      const double dx = double(c.center.x) - target[i].center.x;
      const double dy = double(c.center.y) - target[i].center.y;
      const double dz = double(c.center.z) - target[i].center.z;
      need = std::max(need, std::sqrt(dx * dx + dy * dy + dz * dz) + double(c.radius));
    }
    if (need > double(target[i].radius)) {
      target[i].radius = round_up(need);
      ++report.spheres_enlarged;
    }
  }

  // Spheres, top-down against the decoded parents; the root against the header's sphere.
  // Children touch their parent's true sphere from inside (it is the smallest one around them),
  // so a decoded parent without room to spare leaves them only its own sphere. Interior nodes
  // therefore aim at their target grown by kInteriorMargin (when some code allows it), which
  // lets their children find tight codes; leaves, drawn at their decoded size, aim at their own.
  const auto grown = [](const Sphere& s) {
    return Sphere{s.center, round_up(double(s.radius) * (1 + kInteriorMargin))};
  };
  const Sphere header_sphere = nodes[0].child_count > 0 ? grown(target[0]) : target[0];
  std::vector<Sphere> decoded(n);
  std::vector<std::uint64_t> record(n, 0);
  // Level by level (breadth-first order keeps each level contiguous): a node depends only on
  // its decoded parent, so a level's nodes are encoded in parallel, in fixed chunks whose
  // statistics are summed in order (the same file and report for any thread count).
  struct ChunkStats {
    double leaf_ratio_sum = 0;
    std::uint64_t leaf_ratio_count = 0, parent_fallbacks = 0;
  };
  const auto encode_node = [&](std::size_t i, ChunkStats& stats) {
    const Sphere& p = i == 0 ? header_sphere : decoded[parent[i]];
    // Targets nest, so some code always qualifies (at worst the parent's own sphere, which
    // `exact` could only miss by a double rounding of the triangle inequality).
    bool exact = false;
    std::uint32_t code = qs_detail::kSphereCodeCount - 1;
    const LeafTrim mode = options.leaf_trim;
    LeafCode leaf;
    if (nodes[i].child_count > 0) {
      code = encode_enclosing_sphere(p, grown(target[i]), &exact);
      if (!exact) code = encode_enclosing_sphere(p, target[i], &exact);
    } else {
      // Leaves are drawn at their trimmed radius: the code and trim that draw them smallest.
      leaf = encode_enclosing_leaf(p, target[i], mode);
      code = leaf.code;
    }
    decoded[i] = qs_detail::decode_sphere(p, code);
    if (i > 0 && code == qs_detail::kSphereCodeCount - 1) ++stats.parent_fallbacks;
    const std::uint64_t children = nodes[i].child_count == 0 ? 0 : nodes[i].child_count - 1u;
    record[i] = std::uint64_t{code} << kSphereShift | children << kChildShift;
    if (nodes[i].child_count == 0) {
      record[i] |= leaf_trim_bits(leaf.trim, mode);
      if (nodes[i].radius > 0) {
        stats.leaf_ratio_sum += double(leaf.radius) / nodes[i].radius;
        ++stats.leaf_ratio_count;
      }
    }
  };
  constexpr std::size_t kChunk = 4096;
  double leaf_ratio_sum = 0;
  std::uint64_t leaf_ratio_count = 0;
  std::vector<ChunkStats> chunk_stats;
  for (std::size_t begin = 0, end = 1; begin < n;) {
    std::size_t next_end = end;  // the next level ends after the last child of this one
    for (std::size_t i = begin; i < end; ++i) {
      if (nodes[i].child_count > 0) next_end = nodes[i].first_child + nodes[i].child_count;
    }
    const std::size_t chunks = (end - begin + kChunk - 1) / kChunk;
    chunk_stats.assign(chunks, {});
    pool.run(chunks, [&](std::size_t c) {
      const std::size_t first = begin + c * kChunk, last = std::min(end, first + kChunk);
      for (std::size_t i = first; i < last; ++i) encode_node(i, chunk_stats[c]);
    });
    for (const ChunkStats& c : chunk_stats) {
      leaf_ratio_sum += c.leaf_ratio_sum;
      leaf_ratio_count += c.leaf_ratio_count;
      report.parent_fallbacks += c.parent_fallbacks;
    }
    begin = end;
    end = next_end;
  }
  report.mean_leaf_radius_ratio = leaf_ratio_count ? leaf_ratio_sum / double(leaf_ratio_count) : 1;

  // Normals, then cones bottom-up around the decoded normals: each holds the true cone and the
  // decoded cones (leaves: decoded normals) of the children.
  const auto normal_table = qs_detail::normal_table();
  std::vector<std::uint32_t> normal_code(n);
  for (std::size_t i = 0; i < n; ++i) {
    normal_code[i] = encode_normal_nearest(normalized(nodes[i].normal));
    record[i] |= std::uint64_t{normal_code[i]} << kNormalShift;
  }
  std::vector<double> cone_angle(n, 0.0);  // decoded half-angle; leaves 0
  for (std::size_t i = n; i-- > 0;) {
    const SphereNode& nd = nodes[i];
    if (nd.child_count == 0) continue;
    const Vec3f axis = normal_table[normal_code[i]];
    double theta = nd.cone_sin < 1 ? std::asin(double(nd.cone_sin)) : 1e9;
    theta += angle_between(axis, nd.normal);
    for (std::uint32_t k = 0; k < nd.child_count; ++k) {
      const std::uint32_t c = nd.first_child + k;
      theta = std::max(theta, angle_between(axis, normal_table[normal_code[c]]) + cone_angle[c]);
    }
    const std::uint32_t cone = encode_cone_at_least(theta);
    cone_angle[i] = cone < 3 ? cone_half_angle(cone) : 1e9;
    ++report.cone_codes[cone];
    record[i] |= std::uint64_t{cone} << kConeShift;
  }
  if (colors) {
    for (std::size_t i = 0; i < n; ++i) {
      record[i] |= std::uint64_t{encode_rgb565_nearest(nodes[i].color)} << kColorShift;
    }
  }

  const std::vector<PagePlan> pages = plan_pages(tree, record_size, options.page_bytes);
  if (pages.size() >= kPtlNoPage) fail(path, "too many pages");

  // Layout: header, page table, pages, metadata.
  const std::uint64_t table_offset = kHeaderSize;
  std::uint64_t page_offset = table_offset + pages.size() * kPageEntrySize;
  std::vector<std::uint8_t> head(page_offset, 0);
  std::vector<std::uint64_t> offsets(pages.size());
  for (std::size_t p = 0; p < pages.size(); ++p) {
    offsets[p] = page_offset;
    page_offset += pages[p].byte_size;
  }
  const std::uint64_t metadata_offset = page_offset;
  std::vector<std::uint8_t> feature_bytes;
  if (options.features) {
    std::vector<std::span<const std::uint32_t>> page_nodes;
    for (const PagePlan& pg : pages) page_nodes.emplace_back(pg.nodes);
    feature_bytes = encode_features(nodes, *options.features, page_nodes);
  }

  std::uint8_t* h = head.data();
  std::memcpy(h, ptl::kMagic, sizeof ptl::kMagic);
  store_u32(h + offset::kVersion, kPtlV2Version);
  store_u32(h + offset::kHeaderSize, kHeaderSize);
  store_u32(h + offset::kEndian, kEndianMarker);
  store_u32(h + offset::kFlags, colors ? kFlagHasColors : 0);
  // The frame only when it is not the default, so such files keep their old bytes.
  const bool frame = tree.origin != std::array<double, 3>{} || !(tree.up == Vec3f{0, 1, 0});
  store_u32(h + offset::kCompatFlags,
            (frame ? kCompatFrame : 0) | (feature_bytes.empty() ? 0 : kCompatFeatures));
  if (!feature_bytes.empty()) {
    store_u64(h + kFeaturesOffsetAt, metadata_offset + metadata.size());
    store_u64(h + kFeaturesSizeAt, feature_bytes.size());
  }
  if (frame) {
    for (int a = 0; a < 3; ++a) store_f64(h + offset::kOrigin + 8 * a, tree.origin[a]);
    store_vec(h + offset::kUp, tree.up);
  }
  store_u32(h + offset::kRecordSize, record_size);
  store_u64(h + offset::kNodeCount, n);
  store_u64(h + offset::kLeafCount, leaves);
  store_u32(h + offset::kDepth, depth);
  store_u32(h + offset::kPageCount, static_cast<std::uint32_t>(pages.size()));
  store_u64(h + offset::kPageTableOffset, table_offset);
  store_u64(h + offset::kMetadataOffset, metadata_offset);
  store_u64(h + offset::kMetadataSize, metadata.size());
  store_vec(h + offset::kRootSphere, header_sphere.center);
  store_f32(h + offset::kRootSphere + 12, header_sphere.radius);
  store_vec(h + offset::kBoundsLo, tree.bounds.lo);
  store_vec(h + offset::kBoundsHi, tree.bounds.hi);
  store_vec(h + offset::kViewCenter, tree.view_sphere.center);
  store_f32(h + offset::kViewRadius, tree.view_sphere.radius);
  store_u32(h + offset::kPageBytes, options.page_bytes);
  const Schema s = schema(colors, options.leaf_trim);
  store_u32(h + offset::kAttributeCount, s.count);
  for (std::uint32_t a = 0; a < s.count; ++a) {
    std::uint8_t* e = h + offset::kAttributes + 8 * a;
    store_u16(e, s.entries[a].attribute);
    store_u16(e + 2, s.entries[a].encoding);
    e[4] = s.entries[a].first_bit;
    e[5] = s.entries[a].bit_count;
  }
  for (std::size_t p = 0; p < pages.size(); ++p) {
    std::uint8_t* e = h + table_offset + p * kPageEntrySize;
    store_u64(e, offsets[p]);
    store_u32(e + 8, static_cast<std::uint32_t>(pages[p].byte_size));
    store_u32(e + 12, static_cast<std::uint32_t>(pages[p].nodes.size()));
    store_u32(e + 16, pages[p].parent_page);
    store_u32(e + 20, pages[p].first_root);
    store_u32(e + 24, p == 0 ? 1u : static_cast<std::uint32_t>(pages[p].roots.size()));
    store_u32(e + 28, pages[p].level_count);
  }

  AtomicFile file(path);
  file.write(head.data(), head.size());
  std::vector<std::uint8_t> bytes;
  for (std::size_t p = 0; p < pages.size(); ++p) {
    const PagePlan& pg = pages[p];
    bytes.assign(pg.byte_size, 0);
    std::uint8_t* b = bytes.data();
    const std::size_t roots = p == 0 ? 1 : pg.roots.size();
    for (std::size_t r = 0; r < roots; ++r) {
      const Sphere& sphere = p == 0 ? header_sphere : decoded[pg.roots[r]];
      store_vec(b + 16 * r, sphere.center);
      store_f32(b + 16 * r + 12, sphere.radius);
      b[16 * roots + r] = p == 0 ? 1 : nodes[pg.roots[r]].child_count;
    }
    std::uint8_t* rec = b + roots * kRootEntrySize;
    for (const std::uint32_t v : pg.nodes) {
      store_u32(rec, static_cast<std::uint32_t>(record[v]));
      if (colors) store_u16(rec + 4, static_cast<std::uint16_t>(record[v] >> 32));
      rec += record_size;
    }
    file.write(bytes.data(), bytes.size());
  }
  file.write(metadata.data(), metadata.size());
  file.write(feature_bytes.data(), feature_bytes.size());
  file.commit();

  report.file_size = metadata_offset + metadata.size() + feature_bytes.size();
  report.record_bytes = std::uint64_t{n} * record_size;
  report.node_count = n;
  report.leaf_count = leaves;
  report.page_count = static_cast<std::uint32_t>(pages.size());
  report.record_size = record_size;
  report.bytes_per_leaf = double(report.file_size) / double(leaves);
  return report;
}

}  // namespace pointillist
