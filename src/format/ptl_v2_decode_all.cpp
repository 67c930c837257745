// PtlV2File::decode_all: every page decoded, the pages joined into one breadth-first tree
// (each child page's roots checked against its parent's last level), the header's counts checked.
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "ptl_header.hpp"
#include "ptl_v2_layout.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/format/ptl_v2.hpp"

namespace pointillist {
namespace {

using namespace ptl2;
using ptl::fail_at;

std::string str(std::uint64_t v) { return std::to_string(v); }

}  // namespace

SphereTree PtlV2File::decode_all(TreeFeatures* features) const {
  const std::uint32_t page_count = this->page_count();
  std::vector<PtlV2Page> pages(page_count);
  for (std::uint32_t p = 0; p < page_count; ++p) decode_page(p, pages[p]);

  // Child page links: for each page, its last level's interior nodes in order, each mapped to
  // (child page, root index, first child record in that page).
  struct Link {
    std::uint32_t page = kPtlNoPage, first = 0;
  };
  std::vector<std::vector<Link>> links(page_count);
  std::vector<std::uint32_t> cursor(page_count, 0);  // next last-level node to link, per page
  for (std::uint32_t p = 0; p < page_count; ++p) links[p].assign(pages[p].nodes.size(), {});
  for (std::uint32_t c = 1; c < page_count; ++c) {
    const PtlV2PageInfo& info = pages_[c];
    const std::uint32_t p = info.parent_page;
    const PtlV2Page& parent = pages[p];
    const std::uint64_t parent_records =
        pages_[p].offset + std::uint64_t{pages_[p].root_count} * kRootEntrySize;
    std::uint32_t v = std::max(cursor[p], parent.last_level_begin);
    while (v < parent.nodes.size() && parent.nodes[v].child_count == 0) ++v;
    std::uint32_t first = 0;
    for (std::uint32_t r = 0; r < info.root_count; ++r) {
      while (v < parent.nodes.size() && parent.nodes[v].child_count == 0) ++v;
      if (v >= parent.nodes.size() || (r == 0 && v != info.first_root)) {
        fail_at(path_, pages_[c].offset,
                "page " + str(c) + ": its roots do not continue the last level of parent page " +
                    str(p) + " (expected record " + str(v) + ", the page table says " +
                    str(info.first_root) + ")");
      }
      const SphereNode& node = parent.nodes[v];
      const Sphere& stored = pages[c].root_spheres[r];
      if (std::memcmp(&stored.center, &node.center, sizeof(Vec3f)) != 0 ||
          std::memcmp(&stored.radius, &node.radius, sizeof(float)) != 0 ||
          pages[c].root_child_counts[r] != node.child_count) {
        fail_at(path_, pages_[c].offset + 16 * r,
                "page " + str(c) + ": root " + str(r) + " differs from record " + str(v) +
                    " of parent page " + str(p) + " (byte " +
                    str(parent_records + std::uint64_t{v} * record_size_) + ")");
      }
      links[p][v] = {c, first};
      first += node.child_count;
      ++v;
    }
    cursor[p] = v;
  }
  for (std::uint32_t p = 0; p < page_count; ++p) {
    const PtlV2Page& pg = pages[p];
    for (std::uint32_t v = pg.last_level_begin; v < pg.nodes.size(); ++v) {
      if (pg.nodes[v].child_count > 0 && links[p][v].page == kPtlNoPage) {
        fail_at(path_,
                pages_[p].offset + std::uint64_t{pages_[p].root_count} * kRootEntrySize +
                    std::uint64_t{v} * record_size_,
                "page " + str(p) + ": record " + str(v) + " has children, but no page holds them");
      }
    }
  }

  // Breadth-first over the linked pages: the order in which the tree was written.
  SphereTree tree;
  tree.nodes.reserve(node_count_);
  std::vector<NodeRef> refs;
  refs.reserve(node_count_);
  tree.nodes.push_back(pages[0].nodes[0]);
  refs.push_back({0, 0});
  std::uint64_t leaves = 0;
  std::uint32_t depth = 0;
  std::uint64_t level_end = 1;
  for (std::size_t i = 0; i < tree.nodes.size(); ++i) {
    if (i == level_end) {
      ++depth;
      level_end = tree.nodes.size();
    }
    const NodeRef ref = refs[i];
    const SphereNode& src = pages[ref.page].nodes[ref.record];
    if (src.child_count == 0) {
      ++leaves;
      continue;
    }
    NodeRef child{ref.page, src.first_child};
    if (ref.record >= pages[ref.page].last_level_begin) {
      const Link& l = links[ref.page][ref.record];
      child = {l.page, l.first};
    }
    if (tree.nodes.size() + src.child_count > node_count_) {
      fail_at(path_, offset::kNodeCount,
              "the pages hold more nodes than the header's " + str(node_count_));
    }
    tree.nodes[i].first_child = static_cast<std::uint32_t>(tree.nodes.size());
    for (std::uint32_t k = 0; k < src.child_count; ++k) {
      SphereNode n = pages[child.page].nodes[child.record + k];
      n.first_child = 0;
      tree.nodes.push_back(n);
      refs.push_back({child.page, child.record + k});
    }
  }
  if (leaves != leaf_count_) {
    fail_at(path_, offset::kLeafCount,
            "header says " + str(leaf_count_) + " leaves, the pages hold " + str(leaves));
  }
  if (depth != depth_) {
    fail_at(path_, offset::kDepth,
            "header says depth " + str(depth_) + ", the pages have depth " + str(depth));
  }
  tree.has_colors = has_colors_;
  tree.leaf_count = leaves;
  tree.depth = depth;
  tree.bounds = bounds_;
  tree.view_sphere = view_sphere_;
  tree.origin = origin_;
  tree.up = up_;
  if (features && features_size_ != 0) gather_features(tree, pages, refs, *features);
  return tree;
}

}  // namespace pointillist
