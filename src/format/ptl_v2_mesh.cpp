// The mesh section of .ptl version 2 (see ptl_v2_mesh.hpp and docs/ptl-format.md).
//
// Layout: "PTLM", u32 version 1, u64 leaf count, u64 triangle count T, u64 page count P, u64
// section size, then (u64 section offset, u64 triangles) for each page and (section size, 0)
// after the last; then the blocks. A block's triangles are sorted by first corner and stored as
// three zigzag LEB128 varints each: first corner minus the previous triangle's first corner (0
// before the block's first), then the second and third corners minus the first. Leaves of one
// subtree are near each other in node order, so most triangles take 4 to 6 bytes.
#include "ptl_v2_mesh.hpp"

#include <algorithm>
#include <bit>
#include <cassert>
#include <cstring>

#include "ptl_v2_layout.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/core/radix_sort.hpp"
#include "pointillist/core/thread_pool.hpp"

namespace pointillist::ptl2 {
namespace {

constexpr char kMagic[4] = {'P', 'T', 'L', 'M'};
constexpr std::uint32_t kVersion = 1;
constexpr std::uint64_t kBlockEntry = 16;

void put_varint(std::vector<std::uint8_t>& out, std::int64_t delta) {
  std::uint64_t v = (static_cast<std::uint64_t>(delta) << 1) ^ static_cast<std::uint64_t>(delta >> 63);
  while (v >= 0x80) {
    out.push_back(static_cast<std::uint8_t>(v | 0x80));
    v >>= 7;
  }
  out.push_back(static_cast<std::uint8_t>(v));
}

[[noreturn]] void fail(const std::string& path, std::uint64_t byte, const std::string& what) {
  throw FormatError(path + ": byte " + std::to_string(byte) + ": mesh faces: " + what +
                    "; the file is damaged (convert the mesh again, or render without --hybrid)");
}

}  // namespace

std::vector<std::uint8_t> encode_mesh(std::span<const SphereNode> nodes,
                                      std::span<const std::array<std::uint32_t, 3>> triangles,
                                      std::span<const std::span<const std::uint32_t>> pages,
                                      ThreadPool& pool) {
  // The page of every leaf.
  std::vector<std::uint32_t> leaf_of_node(nodes.size(), 0);
  std::uint32_t leaves = 0;
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    if (nodes[i].child_count == 0) leaf_of_node[i] = leaves++;
  }
  std::vector<std::uint32_t> page_of_leaf(leaves, 0);
  for (std::uint32_t p = 0; p < pages.size(); ++p) {
    for (const std::uint32_t node : pages[p]) {
      if (nodes[node].child_count == 0) page_of_leaf[leaf_of_node[node]] = p;
    }
  }
  // Triangles by page (counting), then by first corner and input order within a page.
  std::vector<std::uint64_t> page_begin(pages.size() + 1, 0);
  for (const auto& t : triangles) {
    assert(t[0] < leaves && t[1] < leaves && t[2] < leaves);
    ++page_begin[page_of_leaf[t[0]] + 1];
  }
  for (std::size_t p = 0; p < pages.size(); ++p) page_begin[p + 1] += page_begin[p];
  std::vector<std::pair<std::uint32_t, std::uint32_t>> keyed(triangles.size());  // (first, t)
  {
    std::vector<std::uint64_t> next(page_begin.begin(), page_begin.end() - 1);
    for (std::uint32_t t = 0; t < triangles.size(); ++t) {
      keyed[next[page_of_leaf[triangles[t][0]]]++] = {triangles[t][0], t};
    }
  }
  // Each page's block sorted and encoded on its own (the same bytes for any thread count).
  std::vector<std::vector<std::uint8_t>> blocks(pages.size());
  pool.run(pages.size(), [&](std::size_t p) {
    const auto first = keyed.begin() + std::ptrdiff_t(page_begin[p]);
    const auto last = keyed.begin() + std::ptrdiff_t(page_begin[p + 1]);
    if (first == last) return;
    // By first corner; the scatter above left each page in input order, which the stable sort
    // keeps among equal corners.
    const auto [low, high] = std::minmax_element(
        first, last, [](const auto& a, const auto& b) { return a.first < b.first; });
    const std::uint32_t base = low->first;
    std::vector<std::pair<std::uint32_t, std::uint32_t>> scratch;
    stable_radix_sort(std::span(first, last), scratch, std::bit_width(high->first - base),
                      [base](const auto& k) { return std::uint64_t{k.first - base}; });
    std::vector<std::uint8_t>& block = blocks[p];
    block.reserve(6 * std::size_t(last - first));
    std::int64_t previous = 0;
    for (auto it = first; it != last; ++it) {
      const auto& t = triangles[it->second];
      const std::int64_t corner = t[0];
      put_varint(block, corner - previous);
      put_varint(block, std::int64_t{t[1]} - corner);
      put_varint(block, std::int64_t{t[2]} - corner);
      previous = corner;
    }
  });

  std::uint64_t total = kMeshFixedBytes + kBlockEntry * (pages.size() + 1);
  for (const auto& block : blocks) total += block.size();
  std::vector<std::uint8_t> out(kMeshFixedBytes + kBlockEntry * (pages.size() + 1), 0);
  out.reserve(total);
  std::memcpy(out.data(), kMagic, 4);
  store_u32(out.data() + 4, kVersion);
  store_u64(out.data() + 8, leaves);
  store_u64(out.data() + 16, triangles.size());
  store_u64(out.data() + 24, pages.size());
  for (std::uint32_t p = 0; p < pages.size(); ++p) {
    store_u64(out.data() + kMeshFixedBytes + kBlockEntry * p, out.size());
    store_u64(out.data() + kMeshFixedBytes + kBlockEntry * p + 8,
              page_begin[p + 1] - page_begin[p]);
    out.insert(out.end(), blocks[p].begin(), blocks[p].end());
    std::vector<std::uint8_t>().swap(blocks[p]);
  }
  store_u64(out.data() + kMeshFixedBytes + kBlockEntry * pages.size(), out.size());
  store_u64(out.data() + 32, out.size());
  return out;
}

std::uint64_t mesh_section_size(std::string_view bytes, std::uint64_t at, const std::string& path) {
  if (bytes.size() < kMeshFixedBytes) {
    fail(path, at, "the section's fixed fields (" + std::to_string(kMeshFixedBytes) +
                       " bytes) run past the end of the file; it was probably truncated");
  }
  const auto* b = reinterpret_cast<const std::uint8_t*>(bytes.data());
  if (std::memcmp(b, kMagic, 4) != 0) fail(path, at, "no PTLM signature where the header says");
  const std::uint64_t size = load_u64(b + 32);
  if (size < kMeshFixedBytes || size > bytes.size()) {
    fail(path, at + 32, "section size " + std::to_string(size) + " does not fit the " +
                            std::to_string(bytes.size()) + " bytes left in the file");
  }
  return size;
}

std::vector<std::array<std::uint32_t, 3>> decode_mesh(std::string_view bytes, std::uint64_t at,
                                                      std::uint64_t leaf_count,
                                                      std::uint32_t page_count,
                                                      const std::string& path) {
  const std::uint64_t size = mesh_section_size(bytes, at, path);
  const auto* b = reinterpret_cast<const std::uint8_t*>(bytes.data());
  if (const std::uint32_t v = load_u32(b + 4); v != kVersion) {
    fail(path, at + 4, "section version " + std::to_string(v) +
                           " is not known to this Pointillist (upgrade it)");
  }
  if (load_u64(b + 8) != leaf_count) {
    fail(path, at + 8, "leaf count " + std::to_string(load_u64(b + 8)) + " differs from the "
                           "header's " + std::to_string(leaf_count));
  }
  if (load_u64(b + 24) != page_count) {
    fail(path, at + 24, "page count " + std::to_string(load_u64(b + 24)) + " differs from the "
                            "header's " + std::to_string(page_count));
  }
  const std::uint64_t table_end = kMeshFixedBytes + kBlockEntry * (std::uint64_t{page_count} + 1);
  if (table_end > size) fail(path, at + 24, "the block table runs past the section's end");
  const std::uint64_t total = load_u64(b + 16);
  // Every triangle takes at least 3 bytes.
  if (total > (size - table_end) / 3) {
    fail(path, at + 16, std::to_string(total) + " triangles cannot fit in " +
                            std::to_string(size - table_end) + " bytes");
  }
  std::vector<std::array<std::uint32_t, 3>> out;
  out.reserve(total);
  std::uint64_t pos = table_end;
  for (std::uint32_t p = 0; p < page_count; ++p) {
    const std::uint8_t* entry = b + kMeshFixedBytes + kBlockEntry * p;
    const std::uint64_t begin = load_u64(entry), count = load_u64(entry + 8);
    const std::uint64_t end = load_u64(entry + kBlockEntry);
    if (begin != pos || end < begin || end > size) {
      fail(path, at + kMeshFixedBytes + kBlockEntry * p,
           "page " + std::to_string(p) + "'s block [" + std::to_string(begin) + ", " +
               std::to_string(end) + ") does not follow the previous one inside the section");
    }
    if (count > total - out.size() || count > (end - begin) / 3) {
      fail(path, at + kMeshFixedBytes + kBlockEntry * p + 8,
           "page " + std::to_string(p) + " claims " + std::to_string(count) +
               " triangles, more than its bytes or the total hold");
    }
    const auto varint = [&](const char* what) {
      std::uint64_t v = 0;
      for (int shift = 0;; shift += 7) {
        if (pos >= end || shift > 35) {
          fail(path, at + pos, std::string("a malformed or unfinished number (") + what + ")");
        }
        const std::uint8_t byte = b[pos++];
        v |= std::uint64_t{byte & 0x7fu} << shift;
        if (!(byte & 0x80)) break;
      }
      return static_cast<std::int64_t>(v >> 1) ^ -static_cast<std::int64_t>(v & 1);
    };
    std::int64_t previous = 0;
    for (std::uint64_t t = 0; t < count; ++t) {
      const std::uint64_t start = pos;
      const std::int64_t first = previous + varint("first corner");
      const std::int64_t second = first + varint("second corner");
      const std::int64_t third = first + varint("third corner");
      for (const std::int64_t c : {first, second, third}) {
        if (c < 0 || static_cast<std::uint64_t>(c) >= leaf_count) {
          fail(path, at + start, "a triangle of page " + std::to_string(p) +
                                     " refers to leaf " + std::to_string(c) + " of " +
                                     std::to_string(leaf_count));
        }
      }
      out.push_back({static_cast<std::uint32_t>(first), static_cast<std::uint32_t>(second),
                     static_cast<std::uint32_t>(third)});
      previous = first;
    }
    if (pos != end) {
      fail(path, at + pos, "page " + std::to_string(p) + "'s block has " +
                               std::to_string(end - pos) + " bytes after its last triangle");
    }
  }
  if (out.size() != total) {
    fail(path, at + 16, "the blocks hold " + std::to_string(out.size()) + " triangles, not " +
                            std::to_string(total));
  }
  return out;
}

}  // namespace pointillist::ptl2
