// The mesh section of .ptl version 2 (docs/ptl-format.md, "Mesh faces"): a mesh's triangles over
// the hierarchy's leaves, kept for the hybrid point/polygon mode, a block per page (the page
// holding a triangle's first corner). Private to the format module.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "pointillist/lod/sphere_tree.hpp"

namespace pointillist {
class ThreadPool;
}

namespace pointillist::ptl2 {

// compat_flags bit 2: the header holds the offset of a mesh section (readers that do not know it
// read the file without faces); the section gives its own size.
constexpr std::uint32_t kCompatMesh = 1u << 2;
constexpr std::uint32_t kMeshOffsetAt = 248;  // u64
constexpr std::uint64_t kMeshFixedBytes = 40;

// The section for `triangles` over the leaves of the tree `nodes` (leaf k = the k-th node
// without children, in node order), written as pages whose node indices are `pages[p]`.
// Asserts every index is below the leaf count. The pages' blocks are encoded on `pool`; the
// bytes do not depend on its thread count.
std::vector<std::uint8_t> encode_mesh(std::span<const SphereNode> nodes,
                                      std::span<const std::array<std::uint32_t, 3>> triangles,
                                      std::span<const std::span<const std::uint32_t>> pages,
                                      ThreadPool& pool);

// The section's size from its fixed fields at `bytes` (the rest of the file from byte `at`).
// Throws FormatError "<path>: byte <offset>: <what>" when they do not fit.
std::uint64_t mesh_section_size(std::string_view bytes, std::uint64_t at, const std::string& path);

// Every triangle of the section `bytes` (starting at byte `at` of `path`), blocks in page order,
// for a model of `leaf_count` leaves in `page_count` pages. Checks the signature, the counts
// against the header and the bytes, each block's end, and every corner against the leaf count;
// throws FormatError naming the byte.
std::vector<std::array<std::uint32_t, 3>> decode_mesh(std::string_view bytes, std::uint64_t at,
                                                      std::uint64_t leaf_count,
                                                      std::uint32_t page_count,
                                                      const std::string& path);

}  // namespace pointillist::ptl2
