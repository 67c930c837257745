// The pieces of writing .ptl version 2 (private to format): checking a hierarchy, encoding its
// nodes (spheres top-down against decoded parents, normals, cones bottom-up, colours), cutting it
// into pages and laying out the header. write_ptl_v2 writes a whole tree with them; the part
// writer (ptl_v2_parts.cpp) writes a top and subtrees encoded one at a time.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "pointillist/core/thread_pool.hpp"
#include "pointillist/format/ptl_v2.hpp"
#include "ptl_v2_layout.hpp"

namespace pointillist::ptl2 {

// Relative growth of interior targets: room for the children's codes, at the price of larger
// interior spheres (chosen on the dragon's images, see ptl_v2_encode.cpp).
constexpr double kInteriorMargin = 0.2;

// Smallest float >= x.
float round_up(double x);
// `s` grown by kInteriorMargin, rounded up: what an interior node's code aims at.
Sphere grown(const Sphere& s);

// Checks values and the breadth-first structure of `nodes`; returns each node's parent (root:
// itself) and fills leaf count and depth. Throws Error "cannot write PATH ...", naming the node.
std::vector<std::uint32_t> check_tree(const std::string& path, std::span<const SphereNode> nodes,
                                      std::uint64_t& leaves, std::uint32_t& depth);

struct EncodeStats {
  std::uint64_t spheres_enlarged = 0;
  std::uint64_t parent_fallbacks = 0;
  double leaf_ratio_sum = 0;
  std::uint64_t leaf_ratio_count = 0;
  std::uint64_t cone_codes[4] = {};
};

// One node's sphere code against its parent's decoded sphere: interior nodes aim at their grown
// target (else the target), leaves take the code and radius trim that draw them smallest.
struct SphereCode {
  std::uint32_t code = 0;
  Sphere decoded;
  std::uint64_t bits = 0;  // sphere, child count and leaf trim bits of the record
};
SphereCode encode_sphere(const Sphere& parent, const Sphere& target, std::uint8_t child_count,
                         quant::LeafTrim mode, EncodeStats& stats);

// The cone code of interior node i around its decoded normal: it holds the node's true cone and
// its children's decoded normals and cones, all read back from the records (normal bits; cone
// bits of interior children, a leaf's cone being its normal alone). The node's normal bits and
// its children's records must be complete.
std::uint32_t encode_cone(std::span<const SphereNode> nodes, std::span<const std::uint64_t> record,
                          std::size_t i);

// Every node of a breadth-first tree, encoded.
struct EncodedTree {
  std::vector<std::uint64_t> record;       // record bits; colour in bits 32-47
  std::vector<Sphere> decoded;             // decoded spheres
  Sphere root_parent;                      // what node 0 was encoded against
};

// Targets (the spheres, enlarged bottom-up where a child sticks out), then spheres top-down with
// node 0 against `root_parent` (null: the header's rule, its target grown when it has children),
// normals, cones bottom-up, colours when `colors`. With `root_decoded`, node 0's record is
// written elsewhere (a subtree of a file written in parts): its decoded sphere is taken as given
// and its children are encoded against it. The same bits for any thread count.
EncodedTree encode_tree(std::span<const SphereNode> nodes, std::span<const std::uint32_t> parent,
                        const Sphere* root_parent, const Sphere* root_decoded,
                        quant::LeafTrim mode, bool colors, ThreadPool& pool, EncodeStats& stats);

// A page: its roots (node indices; none for page 0 of a whole file, whose root is the header's
// sphere) and its records in page order.
struct PagePlan {
  std::uint32_t parent_page = kPtlNoPage;
  std::uint32_t first_root = 0;      // record index in the parent page
  std::vector<std::uint32_t> roots;
  std::vector<std::uint32_t> nodes;
  std::uint32_t level_count = 0;
  std::uint64_t byte_size = 0;
};

// Cuts a breadth-first tree into pages of at most `budget` bytes (docs/ptl-format.md, "Page"),
// in breadth-first order of the page tree. Page 0 holds the root and the coarse levels; with
// `root_in_parent` (a subtree of a file written in parts) the root's record is in another page,
// and page 0's single root is node 0 (its parent_page is left for the caller). Depends only on
// the tree's shape.
std::vector<PagePlan> plan_pages(std::span<const SphereNode> nodes, std::uint32_t record_size,
                                 std::uint64_t budget, bool root_in_parent = false);

// The bytes of a page: root table (spheres and child counts) then records. `root_spheres`
// holds one decoded sphere per root (page 0 of a whole file: the header's sphere, child count 1).
void page_bytes(const PagePlan& page, std::span<const Sphere> root_spheres,
                std::span<const std::uint8_t> root_child_counts,
                std::span<const std::uint64_t> records, std::uint32_t record_size,
                std::vector<std::uint8_t>& out);

// Everything the header says (docs/ptl-format.md, "Header").
struct HeaderFields {
  bool colors = false;
  std::uint32_t record_size = 4;
  quant::LeafTrim leaf_trim = quant::LeafTrim::Sixteenths;
  std::uint64_t node_count = 0, leaf_count = 0;
  std::uint32_t depth = 0;
  std::uint32_t page_bytes = 0;
  std::uint64_t metadata_offset = 0, metadata_size = 0;
  std::uint64_t features_offset = 0, features_size = 0;  // size 0: no features section
  std::uint64_t mesh_offset = 0;  // 0: no mesh section
  Sphere root_sphere;
  Aabb bounds;
  Sphere view_sphere;
  std::array<double, 3> origin{};
  Vec3f up{0, 1, 0};
};

// A page-table entry for `page` starting at byte `offset`.
PtlV2PageInfo page_entry(const PagePlan& page, std::uint64_t offset);

// The header and the page table.
std::vector<std::uint8_t> header_and_table(const HeaderFields& fields,
                                           std::span<const PtlV2PageInfo> pages);

}  // namespace pointillist::ptl2
