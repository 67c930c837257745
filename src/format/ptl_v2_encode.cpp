// The pieces of writing .ptl version 2 (see ptl_v2_encode.hpp; byte layout: docs/ptl-format.md,
// "Version 2"): QSplat-style quantization (Rusinkiewicz & Levoy, SIGGRAPH 2000) with
// conservative codes (ptl_v2_codec.hpp), and records grouped into pages of bounded size.
#include "ptl_v2_encode.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "ptl_header.hpp"
#include "ptl_v2_codec.hpp"
#include "ptl_v2_features.hpp"
#include "ptl_v2_mesh.hpp"
#include "pointillist/core/error.hpp"

namespace pointillist::ptl2 {
namespace {

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw Error("cannot write " + path + " as .ptl version 2: " + what);
}

// A page stops growing by whole levels when the roots of its child pages would cost more than
// 1/kRootOverheadRatio of the records below them (17 bytes each), so that wide last levels do
// not turn into thousands of tiny subtrees with a root entry each.
constexpr std::uint64_t kRootOverheadRatio = 64;

}  // namespace

// kInteriorMargin was chosen on the dragon's images against its triangles (bench/quality.sh,
// PSNR at 0,0 and 135,20, circles / ellipses): 0.08 gives 27.08/30.85 and 29.29/33.53 dB, 0.15
// 27.67/31.81 and 29.59/33.65, 0.2 27.74/31.83 and 29.82/34.05, 0.25 27.70/31.81 and
// 29.73/33.94, 0.35 27.57/31.66 and 29.66/33.90.

float round_up(double x) {
  float f = static_cast<float>(x);
  if (static_cast<double>(f) < x) f = std::nextafter(f, std::numeric_limits<float>::infinity());
  return f;
}

Sphere grown(const Sphere& s) {
  return Sphere{s.center, round_up(double(s.radius) * (1 + kInteriorMargin))};
}

std::vector<std::uint32_t> check_tree(const std::string& path, std::span<const SphereNode> nodes,
                                      std::uint64_t& leaves, std::uint32_t& depth) {
  const std::size_t n = nodes.size();
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
    const SphereNode& nd = nodes[i];
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

SphereCode encode_sphere(const Sphere& parent, const Sphere& target, std::uint8_t child_count,
                         quant::LeafTrim mode, EncodeStats& stats) {
  // Targets nest, so some code always qualifies (at worst the parent's own sphere, which
  // `exact` could only miss by a double rounding of the triangle inequality).
  SphereCode out;
  bool exact = false;
  LeafCode leaf;
  if (child_count > 0) {
    out.code = encode_enclosing_sphere(parent, grown(target), &exact);
    if (!exact) out.code = encode_enclosing_sphere(parent, target, &exact);
  } else {
    // Leaves are drawn at their trimmed radius: the code and trim that draw them smallest.
    leaf = encode_enclosing_leaf(parent, target, mode);
    out.code = leaf.code;
  }
  out.decoded = qs_detail::decode_sphere(parent, out.code);
  if (out.code == qs_detail::kSphereCodeCount - 1) ++stats.parent_fallbacks;
  const std::uint64_t children = child_count == 0 ? 0 : child_count - 1u;
  out.bits = std::uint64_t{out.code} << kSphereShift | children << kChildShift;
  if (child_count == 0) {
    out.bits |= leaf_trim_bits(leaf.trim, mode);
    if (target.radius > 0) {
      stats.leaf_ratio_sum += double(leaf.radius) / target.radius;
      ++stats.leaf_ratio_count;
    }
  }
  return out;
}

std::uint32_t encode_cone(std::span<const SphereNode> nodes, std::span<const std::uint64_t> record,
                          std::size_t i) {
  const auto normal_table = qs_detail::normal_table();
  const auto normal_of = [&](std::size_t j) {
    return normal_table[quant::bits(std::uint32_t(record[j]), kNormalShift, kNormalBits)];
  };
  const SphereNode& node = nodes[i];
  const Vec3f axis = normal_of(i);
  double theta = node.cone_sin < 1 ? std::asin(double(node.cone_sin)) : 1e9;
  theta += angle_between(axis, node.normal);
  if (encode_cone_at_least(theta) == 3) return 3;  // θ only grows below
  // Children whose cones have the same code (leaves: their normal alone, no angle) need only
  // the widest angle from the axis among them, the least cosine (acos decreases): one acos a
  // code instead of one a child. A child with code 3 (no bound; an infinite angle) makes it 3.
  double least[4] = {2, 2, 2, 2};  // by the children's cone codes 0-2; 3 for leaves
  for (std::uint32_t k = 0; k < node.child_count; ++k) {
    const std::size_t ch = node.first_child + k;
    // A leaf's cone bits hold its radius trim, not a cone.
    std::uint32_t slot = 3;
    if (nodes[ch].child_count > 0) {
      slot = quant::bits(std::uint32_t(record[ch]), kConeShift, kConeBits);
      if (slot == 3) return 3;
    }
    least[slot] = std::min(least[slot], cosine_between(axis, normal_of(ch)));
  }
  for (std::uint32_t slot = 0; slot < 4; ++slot) {
    if (least[slot] > 1) continue;
    const double child_angle = slot < 3 ? cone_half_angle(slot) : 0.0;
    theta = std::max(theta, std::acos(least[slot]) + child_angle);
  }
  return encode_cone_at_least(theta);
}

namespace {

// Where each level of a breadth-first tree starts, and n at the end.
std::vector<std::size_t> level_starts(std::span<const SphereNode> nodes) {
  std::vector<std::size_t> starts;
  for (std::size_t begin = 0, end = 1; begin < nodes.size();) {
    starts.push_back(begin);
    std::size_t next_end = end;  // the next level ends after the last child of this one
    for (std::size_t i = end; i-- > begin;) {
      if (nodes[i].child_count > 0) {
        next_end = nodes[i].first_child + nodes[i].child_count;
        break;
      }
    }
    begin = end;
    end = next_end;
  }
  starts.push_back(nodes.size());
  return starts;
}

// fn(chunk, begin, end) over fixed chunks of [begin, end) on the pool: chunk boundaries depend
// only on the range, so per-chunk sums added in chunk order are the same for any thread count.
constexpr std::size_t kEncodeChunk = 4096;
template <class Fn>
void for_chunks(ThreadPool& pool, std::size_t begin, std::size_t end, Fn&& fn) {
  const std::size_t chunks = (end - begin + kEncodeChunk - 1) / kEncodeChunk;
  if (chunks == 1) return fn(0, begin, end);
  pool.run(chunks, [&](std::size_t c) {
    const std::size_t first = begin + c * kEncodeChunk;
    fn(c, first, std::min(end, first + kEncodeChunk));
  });
}

}  // namespace

EncodedTree encode_tree(std::span<const SphereNode> nodes, std::span<const std::uint32_t> parent,
                        const Sphere* root_parent, const Sphere* root_decoded,
                        quant::LeafTrim mode, bool colors, ThreadPool& pool, EncodeStats& stats) {
  const std::size_t n = nodes.size();
  EncodedTree out;
  // Level by level (breadth-first order keeps each level contiguous): a node depends only on
  // its children (bottom-up passes) or its parent (top-down), so each level runs in parallel.
  const std::vector<std::size_t> levels = level_starts(nodes);
  const std::size_t level_count = levels.size() - 1;
  std::vector<EncodeStats> chunk_stats;
  // fn(stats, first, last) for each chunk of each level; a chunk counts into its own stats on
  // the stack of the thread that runs it, which shares no cache line with another thread's
  // (counting straight into chunk_stats, whose neighbours the other thread was counting into,
  // cost up to 7 % of a mesh's conversion, as the vector happened to be aligned).
  const auto each_level = [&](bool bottom_up, auto&& fn) {
    for (std::size_t l = 0; l < level_count; ++l) {
      const std::size_t k = bottom_up ? level_count - 1 - l : l;
      chunk_stats.assign((levels[k + 1] - levels[k] + kEncodeChunk - 1) / kEncodeChunk, {});
      for_chunks(pool, levels[k], levels[k + 1],
                 [&](std::size_t c, std::size_t first, std::size_t last) {
                   EncodeStats own;
                   fn(own, first, last);
                   chunk_stats[c] = own;
                 });
      for (const EncodeStats& c : chunk_stats) {
        stats.leaf_ratio_sum += c.leaf_ratio_sum;
        stats.leaf_ratio_count += c.leaf_ratio_count;
        stats.parent_fallbacks += c.parent_fallbacks;
        stats.spheres_enlarged += c.spheres_enlarged;
        for (int q = 0; q < 4; ++q) stats.cone_codes[q] += c.cone_codes[q];
      }
    }
  };

  // Targets: the tree's spheres, enlarged bottom-up where a child sticks out (in double, rounded
  // up), so each parent's decoded sphere, which encloses its target, can enclose its children's.
  // Only radii change: a target's centre is its node's.
  std::vector<float> target_radius(n);
  const auto target = [&](std::size_t i) { return Sphere{nodes[i].center, target_radius[i]}; };
  each_level(true, [&](EncodeStats& st, std::size_t first, std::size_t last) {
    for (std::size_t i = first; i < last; ++i) {
      const Vec3f centre = nodes[i].center;
      target_radius[i] = nodes[i].radius;
      double need = 0;
      for (std::uint32_t k = 0; k < nodes[i].child_count; ++k) {
        const std::size_t ch = nodes[i].first_child + k;
        const double dx = double(nodes[ch].center.x) - centre.x;
        const double dy = double(nodes[ch].center.y) - centre.y;
        const double dz = double(nodes[ch].center.z) - centre.z;
        need = std::max(need, std::sqrt(dx * dx + dy * dy + dz * dz) + double(target_radius[ch]));
      }
      if (need > double(target_radius[i])) {
        target_radius[i] = round_up(need);
        ++st.spheres_enlarged;
      }
    }
  });

  // Spheres, top-down against the decoded parents. Children touch their parent's true sphere
  // from inside (it is the smallest one around them), so a decoded parent without room to spare
  // leaves them only its own sphere. Interior nodes therefore aim at their target grown by
  // kInteriorMargin (when some code allows it), which lets their children find tight codes;
  // leaves, drawn at their decoded size, aim at their own.
  out.root_parent = root_parent        ? *root_parent
                    : nodes[0].child_count > 0 ? grown(target(0))
                                             : target(0);
  out.decoded.resize(n);
  out.record.resize(n);
  each_level(false, [&](EncodeStats& st, std::size_t first, std::size_t last) {
    for (std::size_t i = first; i < last; ++i) {
      if (i == 0 && root_decoded) {
        out.decoded[0] = *root_decoded;
        out.record[0] = 0;
        continue;
      }
      const Sphere& p = i == 0 ? out.root_parent : out.decoded[parent[i]];
      const std::uint64_t fallbacks = st.parent_fallbacks;
      const SphereCode code = encode_sphere(p, target(i), nodes[i].child_count, mode, st);
      if (i == 0) st.parent_fallbacks = fallbacks;  // the root's parent is no node's
      out.decoded[i] = code.decoded;
      out.record[i] = code.bits;
    }
  });

  target_radius = {};

  // Normals and colours, then cones bottom-up around the decoded normals: each holds the true
  // cone and the decoded cones (leaves: decoded normals) of the children, read back from their
  // records.
  for_chunks(pool, 0, n, [&](std::size_t, std::size_t first, std::size_t last) {
    for (std::size_t i = first; i < last; ++i) {
      out.record[i] |= std::uint64_t{encode_normal_nearest(normalized(nodes[i].normal))}
                       << kNormalShift;
      if (colors) {
        out.record[i] |= std::uint64_t{encode_rgb565_nearest(nodes[i].color)} << kColorShift;
      }
    }
  });
  each_level(true, [&](EncodeStats& st, std::size_t first, std::size_t last) {
    for (std::size_t i = first; i < last; ++i) {
      if (nodes[i].child_count == 0) continue;
      const std::uint32_t cone = encode_cone(nodes, out.record, i);
      ++st.cone_codes[cone];
      out.record[i] |= std::uint64_t{cone} << kConeShift;
    }
  });
  return out;
}

std::vector<PagePlan> plan_pages(std::span<const SphereNode> nodes, std::uint32_t record_size,
                                 std::uint64_t budget, bool root_in_parent) {
  const std::size_t n = nodes.size();
  std::vector<std::uint64_t> subtree(n, 1);
  for (std::size_t i = n; i-- > 0;) {
    for (std::uint32_t k = 0; k < nodes[i].child_count; ++k) {
      subtree[i] += subtree[nodes[i].first_child + k];
    }
  }
  std::vector<std::uint32_t> local(n, 0);  // record index of each node in its page
  std::vector<PagePlan> pages(1);
  if (root_in_parent) pages[0].roots = {0};
  std::vector<std::uint32_t> level, next, frontier;
  for (std::size_t pi = 0; pi < pages.size(); ++pi) {
    const bool header_root = pi == 0 && !root_in_parent;
    level.clear();
    if (header_root) {
      level.push_back(0);
    } else {
      for (const std::uint32_t r : pages[pi].roots) {
        for (std::uint32_t k = 0; k < nodes[r].child_count; ++k)
          level.push_back(nodes[r].first_child + k);
      }
    }
    const std::size_t root_count = header_root ? 1 : pages[pi].roots.size();
    std::vector<std::uint32_t> page_nodes = level;
    std::uint64_t bytes = root_count * kRootEntrySize + level.size() * record_size;
    std::uint32_t levels = 1;
    frontier.clear();
    // A forest that fits takes every level (no child pages); otherwise levels are added while
    // they fit and the child pages' roots stay cheap.
    std::uint64_t forest_records = header_root ? subtree[0] : 0;
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

void page_bytes(const PagePlan& page, std::span<const Sphere> root_spheres,
                std::span<const std::uint8_t> root_child_counts,
                std::span<const std::uint64_t> records, std::uint32_t record_size,
                std::vector<std::uint8_t>& out) {
  out.assign(page.byte_size, 0);
  std::uint8_t* b = out.data();
  const std::size_t roots = root_spheres.size();
  for (std::size_t r = 0; r < roots; ++r) {
    store_vec(b + 16 * r, root_spheres[r].center);
    store_f32(b + 16 * r + 12, root_spheres[r].radius);
    b[16 * roots + r] = root_child_counts[r];
  }
  std::uint8_t* rec = b + roots * kRootEntrySize;
  for (const std::uint32_t v : page.nodes) {
    store_u32(rec, static_cast<std::uint32_t>(records[v]));
    if (record_size == 6) store_u16(rec + 4, static_cast<std::uint16_t>(records[v] >> 32));
    rec += record_size;
  }
}

PtlV2PageInfo page_entry(const PagePlan& page, std::uint64_t offset) {
  PtlV2PageInfo e;
  e.offset = offset;
  e.byte_size = static_cast<std::uint32_t>(page.byte_size);
  e.node_count = static_cast<std::uint32_t>(page.nodes.size());
  e.parent_page = page.parent_page;
  e.first_root = page.first_root;
  e.root_count = page.roots.empty() ? 1u : static_cast<std::uint32_t>(page.roots.size());
  e.level_count = page.level_count;
  return e;
}

std::vector<std::uint8_t> header_and_table(const HeaderFields& f,
                                           std::span<const PtlV2PageInfo> pages) {
  const std::uint64_t table_offset = kHeaderSize;
  std::vector<std::uint8_t> head(table_offset + pages.size() * kPageEntrySize, 0);
  std::uint8_t* h = head.data();
  std::memcpy(h, ptl::kMagic, sizeof ptl::kMagic);
  store_u32(h + offset::kVersion, kPtlV2Version);
  store_u32(h + offset::kHeaderSize, kHeaderSize);
  store_u32(h + offset::kEndian, kEndianMarker);
  store_u32(h + offset::kFlags, f.colors ? kFlagHasColors : 0);
  // The frame only when it is not the default, so such files keep their old bytes.
  const bool frame = f.origin != std::array<double, 3>{} || !(f.up == Vec3f{0, 1, 0});
  store_u32(h + offset::kCompatFlags,
            (frame ? kCompatFrame : 0) | (f.features_size == 0 ? 0 : kCompatFeatures) |
                (f.mesh_offset == 0 ? 0 : kCompatMesh));
  if (f.mesh_offset != 0) store_u64(h + kMeshOffsetAt, f.mesh_offset);
  if (f.features_size != 0) {
    store_u64(h + kFeaturesOffsetAt, f.features_offset);
    store_u64(h + kFeaturesSizeAt, f.features_size);
  }
  if (frame) {
    for (int a = 0; a < 3; ++a) store_f64(h + offset::kOrigin + 8 * a, f.origin[a]);
    store_vec(h + offset::kUp, f.up);
  }
  store_u32(h + offset::kRecordSize, f.record_size);
  store_u64(h + offset::kNodeCount, f.node_count);
  store_u64(h + offset::kLeafCount, f.leaf_count);
  store_u32(h + offset::kDepth, f.depth);
  store_u32(h + offset::kPageCount, static_cast<std::uint32_t>(pages.size()));
  store_u64(h + offset::kPageTableOffset, table_offset);
  store_u64(h + offset::kMetadataOffset, f.metadata_offset);
  store_u64(h + offset::kMetadataSize, f.metadata_size);
  store_vec(h + offset::kRootSphere, f.root_sphere.center);
  store_f32(h + offset::kRootSphere + 12, f.root_sphere.radius);
  store_vec(h + offset::kBoundsLo, f.bounds.lo);
  store_vec(h + offset::kBoundsHi, f.bounds.hi);
  store_vec(h + offset::kViewCenter, f.view_sphere.center);
  store_f32(h + offset::kViewRadius, f.view_sphere.radius);
  store_u32(h + offset::kPageBytes, f.page_bytes);
  const Schema s = schema(f.colors, f.leaf_trim);
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
    store_u64(e, pages[p].offset);
    store_u32(e + 8, pages[p].byte_size);
    store_u32(e + 12, pages[p].node_count);
    store_u32(e + 16, pages[p].parent_page);
    store_u32(e + 20, pages[p].first_root);
    store_u32(e + 24, pages[p].root_count);
    store_u32(e + 28, pages[p].level_count);
  }
  return head;
}

}  // namespace pointillist::ptl2
