// The paged-hierarchy model: a sphere tree stored as pages that are loaded on demand, as QSplat
// streams a model in (Rusinkiewicz & Levoy 2000, section 4.3). A page is a connected part of the
// hierarchy, kept decoded or in the packed form of a quantized model file; a PageSource gives
// pages (a .ptl v2 file in format, or an in-memory hierarchy cut into pages by paginate); the
// PageCache (page_cache.hpp) keeps the resident ones under a memory cap.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "pointillist/features/features.hpp"
#include "pointillist/lod/quantization.hpp"
#include "pointillist/lod/sphere_tree.hpp"

namespace pointillist {

struct TreeFeatures;  // tree_features.hpp

inline constexpr std::uint32_t kNoPage = 0xffffffffu;

// Where the children of a node are when another page holds them: nodes [first, first +
// child_count) of page `page`.
struct PageLink {
  std::uint32_t page = kNoPage;
  std::uint32_t first = 0;
};

// A page kept in the packed form of a quantized model file (lod/quantization.hpp) and decoded
// during the traversal, each node against its decoded parent: 4 bytes a node (6 with colour)
// and about 1.06 bytes of links, where decoded nodes take 44.
struct PackedPage {
  static constexpr unsigned kBlockShift = 6;  // links are stored as 64-node blocks
  std::vector<std::uint32_t> records;  // packed node records, breadth-first over the page
  std::vector<std::uint16_t> colors;   // RGB 565, one per record, when the model has colours
  // Records [0, last_level_begin) have their children (if any) in this page; the interior
  // records of the last level have theirs in child pages, links[k] for the k-th of them.
  std::uint32_t last_level_begin = 0;
  std::vector<PageLink> links;
  // Page 0: the sphere its first record (the root) decodes against.
  Sphere root_parent;
  quant::LeafTrim leaf_trim = quant::LeafTrim::Eighths;
  // link(i) for an interior record i: its first child's index in this page (i <
  // last_level_begin: the first level's size plus the children of the records before it, by
  // breadth-first order), or its index in `links` (i >= last_level_begin). Stored as a 32-bit
  // base per block of 64 records (blocks start afresh at last_level_begin) plus an 8-bit step
  // per record: within a block the value grows by at most 4 a record.
  std::vector<std::uint32_t> link_base;
  std::vector<std::uint8_t> link_step;

  std::uint32_t link(std::uint32_t i) const {
    const std::uint32_t block =
        i < last_level_begin ? i >> kBlockShift
                             : first_last_level_block() + ((i - last_level_begin) >> kBlockShift);
    return link_base[block] + link_step[i];
  }
  std::uint32_t first_last_level_block() const {
    return (last_level_begin + (1u << kBlockShift) - 1) >> kBlockShift;
  }
  // Fills link_base and link_step from the records, last_level_begin and the number of records
  // in the page's first level (the children of its roots).
  void index_links(std::uint32_t first_level_count);

  // Bytes of memory a packed page of `node_count` nodes and `link_count` links takes.
  static std::uint64_t memory_bytes(std::uint64_t node_count, std::uint64_t link_count,
                                    bool has_colors) {
    return node_count * (sizeof(std::uint32_t) + (has_colors ? sizeof(std::uint16_t) : 0) +
                         sizeof(std::uint8_t)) +
           ((node_count >> kBlockShift) + 2) * sizeof(std::uint32_t) +
           link_count * sizeof(PageLink);
  }
};

// Sharp features of a page's nodes (tree_features.hpp, per page): every node's surface id (a
// leaf's splat's, an inner node's the common id of its subtree or kMixedSurface), and the clip
// planes of the leaves that have some. Empty when the model has none.
struct PageFeatures {
  std::vector<std::uint32_t> surface;        // per node of the page, in page order
  std::vector<std::uint32_t> clipped;        // nodes with clip planes, increasing
  std::vector<ClipMode> clipped_mode;        // per clipped node
  std::vector<std::uint32_t> clipped_first;  // per clipped node, and one more: into planes
  std::vector<ClipPlane> planes;

  bool empty() const { return surface.empty(); }
  void clear();
  // Node `node`'s planes and how they combine (none: an empty span and ClipMode::None).
  std::span<const ClipPlane> planes_of(std::uint32_t node, ClipMode& mode) const;
  // Memory while resident (counted by size, not capacity, so a page source can say it before
  // loading), and the same for counts of nodes, clipped nodes and planes.
  std::uint64_t memory_bytes() const {
    return memory_bytes(surface.size(), clipped.size(), planes.size());
  }
  static std::uint64_t memory_bytes(std::uint64_t nodes, std::uint64_t clipped,
                                    std::uint64_t planes) {
    return nodes * 4 + clipped * 9 + 4 + planes * sizeof(ClipPlane);
  }
};

// One page: a connected part of the hierarchy. Page 0 holds the root and the levels below it;
// any other page holds the children of one or more nodes of another page (its anchors), then
// their descendants.
//
// Decoded form (`nodes` not empty): a node's children are nodes[first_child .. first_child +
// child_count) of its own page when child_page[i] is kNoPage, and of page child_page[i]
// otherwise. Packed form (`nodes` empty): see PackedPage.
//
// A packed page may hold only its first levels (PageSource::load's prefix): its
// last_level_begin is then its record count, and the interior nodes of its last loaded level
// have link() indices past the loaded records (where their children are in the whole page).
struct HierarchyPage {
  std::vector<SphereNode> nodes;
  std::vector<std::uint32_t> child_page;  // one per node; kNoPage: children (if any) are here
  PackedPage packed;
  PageFeatures features;  // the nodes' sharp features, when the model has them
  std::uint64_t storage_bytes = 0;  // bytes read from storage to load what is here

  bool is_packed() const { return nodes.empty(); }
  std::uint32_t node_count() const {
    return static_cast<std::uint32_t>(is_packed() ? packed.records.size() : nodes.size());
  }
  // What a decoded page of `node_count` nodes costs in memory while it is resident.
  static std::uint64_t memory_bytes(std::uint64_t node_count) {
    return node_count * (sizeof(SphereNode) + sizeof(std::uint32_t));
  }
  // What this page costs in memory while it is resident.
  std::uint64_t memory_bytes() const {
    return (is_packed() ? PackedPage::memory_bytes(packed.records.size(), packed.links.size(),
                                                   !packed.colors.empty())
                        : memory_bytes(nodes.size())) +
           (features.empty() ? 0 : features.memory_bytes());
  }
};

// How much of a page to load: whole levels, through the one holding record `node`, then
// `extra_levels` more, and on until they hold at least `min_nodes` records. The default is the
// whole page.
struct PagePrefix {
  std::uint32_t node = UINT32_MAX;
  std::uint32_t extra_levels = 0;
  std::uint32_t min_nodes = 0;

  // Whether a prefix of `levels` whole levels ending before record `end` is enough, where the
  // level holding `node` is the `node_level`-th (0 while not reached).
  bool enough(std::uint32_t levels, std::uint64_t end, std::uint32_t node_level) const {
    return node_level != 0 && levels >= node_level + extra_levels && end >= min_nodes;
  }
};

// Where pages come from: a paged model file, or (tests) an in-memory hierarchy cut into pages.
class PageSource {
 public:
  virtual ~PageSource() = default;
  virtual std::uint32_t page_count() const = 0;
  // Bytes read from storage to load the page.
  virtual std::uint64_t page_storage_bytes(std::uint32_t page) const = 0;
  // Nodes in the page.
  virtual std::uint32_t page_node_count(std::uint32_t page) const = 0;
  // Memory the loaded page takes while resident (HierarchyPage::memory_bytes()).
  virtual std::uint64_t page_memory_bytes(std::uint32_t page) const = 0;
  // Bytes read to open the model (header, page table), before any page.
  virtual std::uint64_t open_bytes() const = 0;
  // Counts and boxes of the whole model (nodes stays empty): leaf_count, depth, bounds,
  // view_sphere (for the camera) and has_colors.
  virtual SphereTreeView summary() const = 0;
  // The sharp features the pages carry (HierarchyPage::features): only their surface count
  // (ids of one model are 0 .. surface_count − 1), options and statistics are set (no per-node
  // arrays); null when the pages carry none.
  virtual const TreeFeatures* features() const { return nullptr; }
  // Loads page `page` into `out`, decoded or packed (every page of a source in the same form),
  // with its features when the source has them, and out.storage_bytes. A packed source may load
  // only the page's first levels (`prefix`; see HierarchyPage), and continues a prefix of the
  // page that `out` holds (from an earlier load) without reading it again; a decoded one loads
  // the whole page. Safe to call concurrently for different pages. Throws FormatError or
  // IoError.
  virtual void load(std::uint32_t page, HierarchyPage& out, const PagePrefix& prefix = {}) const = 0;
};

// `tree` cut into pages (with its features, when tree.features is set): page 0 takes the root and then whole sibling groups breadth-first while
// it stays within `page_bytes` (at 40 bytes a node, the .ptl v1 node size); each node whose
// children do not fit starts a new page, filled the same way but with at most `max_levels`
// levels. Shallow pages make a model stream in coarse to fine everywhere rather than region by
// region; a full first page makes the first frame a good one. The
// pages are copies; summary() keeps `tree`'s bounds and counts. Throws OptionError when
// page_bytes cannot hold a node and 4 children (200 bytes) or max_levels is 0.
std::unique_ptr<PageSource> paginate(const SphereTreeView& tree, std::uint64_t page_bytes,
                                     std::uint32_t max_levels = 64);

}  // namespace pointillist
