// Native model file `.ptl`, version 2: the compact, paged form of a QSplat bounding-sphere
// hierarchy (Rusinkiewicz & Levoy, SIGGRAPH 2000). Nodes are 4-byte records (6 with colour):
// sphere relative to the parent (13-bit code), child count, normal (14 bits), normal cone
// (2 bits), RGB 565. Unlike QSplat 1.0, every decoded sphere encloses the true sphere and its
// decoded children, and every decoded cone contains the true cone, so culling on decoded values
// stays conservative. Records are grouped in pages (the coarse levels first, then subtrees of
// bounded size) that decode independently. Byte layout: docs/ptl-format.md, "Version 2".
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "pointillist/core/math.hpp"
#include "pointillist/core/thread_pool.hpp"
#include "pointillist/lod/pages.hpp"
#include "pointillist/lod/quantization.hpp"
#include "pointillist/lod/sphere_tree.hpp"
#include "pointillist/lod/tree_features.hpp"

namespace pointillist {

namespace ptl2 {
struct FeatureSection;  // format/ptl_v2_features.hpp (private)
}

constexpr std::uint32_t kPtlV2Version = 2;

// Largest angle between a node's normal and its decoded normal (radians): 2°, from the 52×52
// cube-face grid with nearest-cell encoding (measured worst case 1.966° over 4·10^7 normals).
constexpr double kPtlV2NormalErrorRad = 2.0 * 3.14159265358979323846 / 180.0;

constexpr std::uint32_t kPtlNoPage = 0xffffffffu;

// One page-table entry.
struct PtlV2PageInfo {
  std::uint64_t offset = 0;       // byte offset of the page in the file
  std::uint32_t byte_size = 0;    // root table + records
  std::uint32_t node_count = 0;   // records in the page
  std::uint32_t parent_page = 0;  // page holding the roots; kPtlNoPage for page 0
  // The roots are `root_count` consecutive interior nodes of the parent page's last level,
  // starting at record `first_root` of the parent page. Page 0 has one root: the header's
  // sphere, whose single child is the tree's root (record 0 of page 0).
  std::uint32_t first_root = 0;
  std::uint32_t root_count = 0;
  std::uint32_t level_count = 0;  // levels of records below the roots
};

struct PtlV2WriteOptions {
  // Store RGB 565 colours (6-byte records) when the tree has colors; off: 4-byte records.
  bool write_colors = true;
  // Upper bound on a page's size in bytes (root table and records), >= 1024. Smaller pages
  // mean finer-grained loading and a slightly larger page table; the top page holds as many
  // whole coarse levels as fit.
  std::uint32_t page_bytes = 32 * 1024;
  // How leaves keep their radius trim: in sixteenths of the decoded radius (default; leaves
  // 1.24x their true radius on the dragon), or in eighths (1.28x), the encoding of the first
  // version 2 files, which Pointillist before 2026-11-24 reads.
  quant::LeafTrim leaf_trim = quant::LeafTrim::Sixteenths;
  // Sharp features of the tree's nodes to store (the leaves' surface ids and clip planes, in a
  // section after the metadata), or null.
  const TreeFeatures* features = nullptr;
  // A mesh's faces over the tree's leaves (leaf k = the k-th node without children in node
  // order, as sphere_tree_leaves lists them), kept for the hybrid point/polygon mode in a section
  // after the features, a block per page (about 5 bytes a triangle); empty: none.
  std::span<const std::array<std::uint32_t, 3>> triangles;
};

// What write_ptl_v2 did.
struct PtlV2WriteReport {
  std::uint64_t file_size = 0;     // bytes
  std::uint64_t record_bytes = 0;  // bytes of node records alone
  std::uint64_t mesh_bytes = 0;    // bytes of the mesh faces' section (0 without)
  std::uint64_t node_count = 0;
  std::uint64_t leaf_count = 0;
  std::uint32_t page_count = 0;
  std::uint32_t record_size = 0;  // 4, or 6 with colours
  double bytes_per_leaf = 0;      // file_size / leaf_count
  // Input spheres enlarged (in double, rounded up) so that each holds its children's; 0 for
  // trees from build_sphere_tree, whose spheres nest already.
  std::uint64_t spheres_enlarged = 0;
  // Nodes whose code had to fall back to the parent's sphere (still enclosing the target).
  std::uint64_t parent_fallbacks = 0;
  double mean_leaf_radius_ratio = 0;  // decoded / true leaf radius, mean over leaves
  std::uint64_t cone_codes[4] = {};   // interior nodes by cone code
};

// Writes `tree` (breadth-first, as build_sphere_tree makes it) to `path` as .ptl version 2,
// atomically (temporary file in the same folder, then rename), with `metadata` (free text)
// after the pages. Spheres are quantized top-down against the decoded parents: an interior
// node's code is the smallest decoded sphere that holds the written sphere (first grown by 20%,
// so its children fit tightly) and lies inside the decoded parent; a leaf's code and radius trim
// are those that draw it smallest while still holding its written sphere. The header keeps the
// sphere the root is decoded against (float32), bounds and view sphere. About 300 ms for the
// 437k-leaf dragon on one thread. Leaves come out about 1.23 times their written radius on
// average (the grid is 1/13 of the parent). A tree whose spheres do not nest is handled
// (spheres_enlarged). Throws Error for an empty tree, more than 2^32 - 2 nodes, a malformed
// structure (children not breadth-first, child counts other than 0, 2, 3, 4) or non-finite
// values, naming the node; OptionError for page_bytes < 1024; IoError naming the file.
PtlV2WriteReport write_ptl_v2(const std::string& path, const SphereTree& tree,
                              const std::string& metadata, const PtlV2WriteOptions& options = {});
// The same, encoding each level of the tree in parallel on `pool` (the file is the same for any
// thread count).
PtlV2WriteReport write_ptl_v2(const std::string& path, const SphereTree& tree,
                              const std::string& metadata, const PtlV2WriteOptions& options,
                              ThreadPool& pool);


// Writing a file in parts (the chunked conversion): subtrees below a common top are encoded and
// written one at a time, so no step holds the whole hierarchy.
//   1. Each subtree (a tree from build_sphere_tree) is summarized: its root node, its node and
//      leaf counts, its depth and the pages it will take below the root.
//   2. A PtlV2PartWriter over the summaries (in a spatially coherent order) builds the top over
//      the roots (build_top_tree), encodes its spheres and normals and lays out the file:
//      header, page table, the top page, then each subtree's pages in turn, then the metadata.
//   3. write_subtree(k, tree) encodes subtree k below its root's decoded sphere and writes its
//      pages in place; subtrees may come in any order, different subtrees on several threads at
//      once.
//   4. finish() encodes the top's cones (an interior root's comes from its subtree's encoding),
//      writes the header, the table, the top page and the metadata, and renames the file into
//      place.
// The file is an ordinary version 2 file; the same subtrees give the same bytes.
struct PtlV2SubtreeSummary {
  SphereNode root;                    // as built: true sphere, normal, cone, colour, children
  std::uint64_t node_count = 0;       // nodes of the subtree, its root included
  std::uint64_t leaf_count = 0;
  std::uint32_t depth = 0;            // levels below its root
  // Its pages below the root, in order, as if alone in a file: offsets from the first one's
  // start, parent pages counted from the first (whose parent is the top page: kPtlNoPage here).
  std::vector<PtlV2PageInfo> pages;
};

// Summarizes `tree` for a PtlV2PartWriter with the same options (colours only when the tree
// and the options have them). Throws what write_ptl_v2 throws for a malformed tree.
PtlV2SubtreeSummary summarize_ptl_v2_subtree(const SphereTree& tree,
                                             const PtlV2WriteOptions& options);

class PtlV2PartWriter {
 public:
  // Lays out `path` (written to a temporary file beside it) for the summarized subtrees. Throws
  // Error for no subtrees, more than 2^20 or more than 2^32 - 2 nodes; OptionError for
  // page_bytes < 1024 or features (not written in parts); IoError naming the file.
  // With `join`, the temporary file of the writer that owns the output (its temp_path(), in
  // another process, e.g. MPI rank 0, over the same subtrees and options): this writer only
  // writes subtrees into it (write_subtree, sync, written_part); the owner adopts what it needs
  // of them (adopt_part) and finishes the file.
  PtlV2PartWriter(const std::string& path, std::vector<PtlV2SubtreeSummary> subtrees,
                  bool has_colors, const PtlV2WriteOptions& options = {},
                  const std::string& join = {});
  ~PtlV2PartWriter();
  PtlV2PartWriter(const PtlV2PartWriter&) = delete;
  PtlV2PartWriter& operator=(const PtlV2PartWriter&) = delete;

  std::size_t subtree_count() const;
  // Encodes and writes subtree `k`, which must be the tree summarized as subtree k (checked: its
  // root and node count). Throws Error when it is not, IoError when writing fails.
  void write_subtree(std::size_t k, const SphereTree& tree, ThreadPool& pool);
  // What the owner needs of subtree k once this writer wrote it (its root's cone code and its
  // encoding's statistics), as bytes for adopt_part. Throws Error when k was not written here.
  std::vector<char> written_part(std::size_t k) const;
  // Subtree k as written by a joining writer, from its written_part. Throws Error for a k out
  // of range or bytes of the wrong size.
  void adopt_part(std::size_t k, std::span<const char> part);
  // Writes the rest and renames the file into place. `bounds` and `view_sphere` are those of all
  // the leaves; origin and up the model's frame. Throws Error when a subtree was not written,
  // IoError when writing fails.
  PtlV2WriteReport finish(const Aabb& bounds, const Sphere& view_sphere,
                          const std::array<double, 3>& origin, Vec3f up,
                          const std::string& metadata);
  // Sharp features are found on the written file, then added (the chunked conversion):
  // finish_uncommitted writes what finish() writes but leaves the file at temp_path(), complete
  // and readable (PtlV2File::open) without features; commit_with_features then writes `metadata`
  // in place of the first, calls write_section(offset), which writes the features section from
  // byte `offset` on (write_at) and returns its size, records both in the header and renames the
  // file into place. Throws IoError when writing fails, Error when called out of turn.
  PtlV2WriteReport finish_uncommitted(const Aabb& bounds, const Sphere& view_sphere,
                                      const std::array<double, 3>& origin, Vec3f up,
                                      const std::string& metadata);
  const std::string& temp_path() const;
  void sync();  // for other processes reading temp_path() (AtomicFile::sync; a joiner's too)
  void write_at(std::uint64_t offset, const void* data, std::size_t size);
  void commit_with_features(const std::string& metadata,
                            const std::function<std::uint64_t(std::uint64_t)>& write_section);

 private:
  struct State;
  std::unique_ptr<State> state_;
};

// The sharp-features section written a page at a time (docs/ptl-format.md, "Sharp features"),
// for files whose features are found part by part: each page's block from the features of its
// records (`page`: per record in page order, surface id, clip mode and planes; options, stats and
// surface count unused), then the head (fixed fields and block table, ptl_v2_feature_head_size
// bytes) over the blocks' sizes and counts, from `summary`'s options, statistics and surface
// count. The section is the head, then the blocks in page order.
struct PtlV2FeatureBlock {
  std::vector<std::uint8_t> bytes;
  std::uint32_t clipped = 0, planes = 0;
};
PtlV2FeatureBlock encode_ptl_v2_feature_block(const TreeFeatures& page);
std::uint64_t ptl_v2_feature_head_size(std::uint32_t page_count);
// What the head needs of each block.
struct PtlV2FeatureBlockEntry {
  std::uint64_t size = 0;
  std::uint32_t clipped = 0, planes = 0;
};
std::vector<std::uint8_t> encode_ptl_v2_feature_head(
    const TreeFeatures& summary, std::uint64_t leaf_count,
    std::span<const PtlV2FeatureBlockEntry> blocks);

// A decoded page.
struct PtlV2Page {
  // Records in page order: the roots' children, then their children, level by level
  // (breadth-first over the page). Decoded values as in PtlV2File::decode_all; first_child is
  // the page-local index of the first child for nodes whose children are in this page, and 0
  // for leaves and for the interior nodes of the last level (their children are in child pages).
  std::vector<SphereNode> nodes;
  std::vector<Sphere> root_spheres;  // decoded root spheres, as stored in the page
  std::vector<std::uint8_t> root_child_counts;
  std::uint32_t last_level_begin = 0;  // nodes[last_level_begin..] is the last level
};

// A read-only memory-mapped .ptl version 2 file.
class PtlV2File {
 public:
  // Maps the file and validates the header, schema and page table (offsets and sizes inside the
  // file, record counts against byte sizes, page linkage, node count). Throws FormatError
  // "<path>: byte <offset>: <what>" (version 1 files get a message saying to use PtlFile or
  // read_ptl), or IoError.
  static std::unique_ptr<PtlV2File> open(const std::string& path);
  ~PtlV2File();
  PtlV2File(const PtlV2File&) = delete;
  PtlV2File& operator=(const PtlV2File&) = delete;

  std::uint32_t page_count() const { return static_cast<std::uint32_t>(pages_.size()); }
  const PtlV2PageInfo& page_info(std::uint32_t page) const { return pages_[page]; }

  // Decodes page `page` (< page_count()) from its own bytes only, validating every record
  // (sphere and normal codes, reserved bits, the level structure against the record count).
  // Reuses `out`'s buffers. Throws FormatError naming the file and byte offset.
  void decode_page(std::uint32_t page, PtlV2Page& out) const;

  // Copies page `page`'s records into `out` in their packed form (decoded later, during the
  // traversal), with last_level_begin, the link index (PackedPage::index_links), root_parent
  // (page 0) and leaf_trim; out.links is left empty for the caller, who knows the child pages.
  // Validates the page as decode_page does. With a `prefix` that ends before the page does,
  // only its first levels are copied (and validated), last_level_begin is the number copied
  // and the link index of the last copied level points past them (see HierarchyPage). Records
  // already in `out` (an earlier prefix of this page) are kept, not read again.
  void pack_page(std::uint32_t page, PackedPage& out, const PagePrefix& prefix = {}) const;
  // Says that page `page`'s bytes were copied out: a paged render keeps its pages packed, and
  // the mapped file pages it read would otherwise stay resident beside them. Every 64 MB of
  // such pages (or an eighth of the file), the whole mapping is let go of (FileBytes::forget).
  // Thread-safe.
  void forget_page(std::uint32_t page) const;
  // Record k (< node count) of page `page`, its bits 0..31 as stored (not validated).
  std::uint32_t page_record(std::uint32_t page, std::uint32_t k) const;

  // The whole hierarchy, breadth-first, node i being node i of the tree that was written:
  // decoded spheres (each enclosing the written sphere and its decoded children), decoded
  // normals, cone_sin ((k + 1)/4)² for cone codes k < 3, 2 (no bound) for 3, 0 for leaves,
  // colors expanded from 565. Checks the pages against each other (roots and child pages
  // match) and the header's counts. With `features` (and a file that stores them), also the
  // sharp features of every node. Throws FormatError.
  SphereTree decode_all(TreeFeatures* features = nullptr) const;

  bool has_colors() const { return has_colors_; }
  // How the leaves keep their radius trim (from the attribute schema).
  quant::LeafTrim leaf_trim() const { return leaf_trim_; }
  std::uint64_t node_count() const { return node_count_; }
  std::uint64_t leaf_count() const { return leaf_count_; }
  std::uint32_t depth() const { return depth_; }
  const Sphere& root_sphere() const { return root_sphere_; }
  const Aabb& bounds() const { return bounds_; }
  const Sphere& view_sphere() const { return view_sphere_; }
  // The model's coordinate frame: absolute position = origin + position, and its up axis.
  const std::array<double, 3>& origin() const { return origin_; }
  Vec3f up() const { return up_; }
  const std::string& metadata() const { return metadata_; }
  // Whether the file stores sharp features, and its leaves' features (indexed by leaf in node
  // order, as decode_all's leaves). Throws FormatError for a damaged section.
  bool has_features() const { return features_size_ != 0; }
  std::optional<FeatureData> features() const;
  // Their surface count, options and statistics (no per-node arrays), or null without them.
  const TreeFeatures* feature_summary() const;
  // Whether they are stored page by page (files of Pointillist 2026-11-26 and later; earlier ones
  // store the leaves' features for the whole model, drawn only when it is decoded whole).
  bool page_features_stored() const;
  // The features of page `page`'s records (page order); is_leaf(k) tells whether record k is a
  // leaf. Thread-safe. Throws FormatError for a damaged block or a file that stores none per
  // page.
  void page_features(std::uint32_t page, const std::function<bool(std::uint32_t)>& is_leaf,
                     PageFeatures& out) const;
  // Memory page `page`'s features take when loaded (PageFeatures::memory_bytes; 0 without page
  // features).
  std::uint64_t page_feature_memory(std::uint32_t page) const;
  // Whether the file keeps a mesh's faces, and the faces over the leaves (indices in node order
  // of the leaves, as decode_all's), every page's block in page order. Throws FormatError for a
  // damaged section.
  bool has_triangles() const { return mesh_offset_ != 0; }
  std::vector<std::array<std::uint32_t, 3>> triangles() const;
  std::uint64_t file_size() const { return size_; }
  const std::string& path() const { return path_; }

 private:
  struct Mapping;
  // A node of the hierarchy as decode_all finds it: record `record` of page `page`.
  struct NodeRef {
    std::uint32_t page, record;
  };
  const ptl2::FeatureSection& feature_section() const;
  // The features of `tree`'s nodes, found at `refs` in the decoded `pages` (decode_all).
  void gather_features(const SphereTree& tree, std::span<const PtlV2Page> pages,
                       std::span<const NodeRef> refs, TreeFeatures& out) const;
  // The parent of a record in its page: root `index` of the page's root table, or record `index`.
  struct PageParent {
    bool is_root = false;
    std::uint32_t index = 0;
  };
  PtlV2File() = default;
  // Validates page `page` (root table, page 0's root against the header's sphere, then each
  // record and the level structure) and calls
  // on_record(index, record bits 0..31, RGB 565 or 0, parent, is_first_child) for each record in
  // order. Returns the index of the first record of the last level. With a `prefix`, stops
  // after the first level where it is enough (`scanned`: the records seen). The `known` first
  // records (whole levels) are taken from there, not read, and not passed to on_record.
  // Without kParents, on_record is told no parent (a default PageParent, is_first_child false),
  // and the scan is faster: the same checks and errors.
  template <bool kParents = true, class OnRecord>
  std::uint32_t scan_page(std::uint32_t page, std::vector<Sphere>& root_spheres,
                          std::vector<std::uint8_t>& root_child_counts, OnRecord&& on_record,
                          const PagePrefix& prefix = {}, std::uint32_t* scanned = nullptr,
                          std::span<const std::uint32_t> known = {}) const;
  std::string path_;
  std::unique_ptr<Mapping> map_;
  std::uint64_t size_ = 0;
  std::uint32_t record_size_ = 4;
  bool has_colors_ = false;
  quant::LeafTrim leaf_trim_ = quant::LeafTrim::Eighths;
  std::uint64_t node_count_ = 0, leaf_count_ = 0;
  std::uint32_t depth_ = 0;
  Sphere root_sphere_;
  Aabb bounds_;
  Sphere view_sphere_;
  std::array<double, 3> origin_{};
  Vec3f up_{0, 1, 0};
  std::string metadata_;
  std::uint64_t features_offset_ = 0, features_size_ = 0;
  std::uint64_t mesh_offset_ = 0, mesh_size_ = 0;
  std::vector<PtlV2PageInfo> pages_;
};

// Any .ptl file as a hierarchy: version 1 copied from the mapped node array, version 2
// decoded with decode_all. Throws what PtlFile::open and PtlV2File::open throw; versions newer
// than 2 get "upgrade Pointillist".
struct PtlModel {
  SphereTree tree;
  std::string metadata;
  std::uint32_t version = 0;
  std::uint64_t file_size = 0;
};
PtlModel read_ptl(const std::string& path);

}  // namespace pointillist
