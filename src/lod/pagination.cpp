// An in-memory hierarchy cut into pages (paginate): the page layout of paged model files, for
// tests and for models held in memory.
#include <algorithm>
#include <cassert>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "pointillist/core/error.hpp"
#include "pointillist/lod/pages.hpp"
#include "pointillist/lod/tree_features.hpp"

namespace pointillist {
namespace {

constexpr std::uint64_t kStorageBytesPerNode = sizeof(SphereNode);  // 40, as in .ptl v1

class InMemoryPages final : public PageSource {
 public:
  InMemoryPages(const SphereTreeView& tree, std::uint64_t page_bytes, std::uint32_t max_levels) {
    summary_ = tree;
    summary_.nodes = {};
    summary_.features = nullptr;
    if (tree.features) {
      features_.emplace();
      features_->surface_count = tree.features->surface_count;
      features_->options = tree.features->options;
      features_->stats = tree.features->stats;
    }
    if (tree.nodes.empty()) return;
    // Global indices of each page's nodes, in page order, and of the anchors of new pages.
    struct Pending {
      std::uint32_t anchor;  // global index; kNoPage for page 0
    };
    std::vector<Pending> starts{{kNoPage}};
    for (std::size_t p = 0; p < starts.size(); ++p) {
      std::vector<std::uint32_t> global;
      HierarchyPage page;
      if (starts[p].anchor == kNoPage) {
        global.push_back(0);
      } else {
        const SphereNode& a = tree.nodes[starts[p].anchor];
        for (std::uint32_t c = 0; c < a.child_count; ++c) global.push_back(a.first_child + c);
      }
      std::uint64_t bytes = global.size() * kStorageBytesPerNode;
      std::vector<std::uint32_t> level(global.size(), 1);  // levels of the page, 1-based
      for (std::size_t k = 0; k < global.size(); ++k) {
        SphereNode n = tree.nodes[global[k]];
        std::uint32_t child_page = kNoPage;
        if (n.child_count > 0) {
          const std::uint64_t more = std::uint64_t{n.child_count} * kStorageBytesPerNode;
          if (bytes + more <= page_bytes && (p == 0 || level[k] < max_levels)) {
            const std::uint32_t first = static_cast<std::uint32_t>(global.size());
            for (std::uint32_t c = 0; c < n.child_count; ++c) {
              global.push_back(n.first_child + c);
              level.push_back(level[k] + 1);
            }
            n.first_child = first;
            bytes += more;
          } else {
            child_page = static_cast<std::uint32_t>(starts.size());
            starts.push_back({global[k]});
            n.first_child = 0;
          }
        }
        page.nodes.push_back(n);
        page.child_page.push_back(child_page);
      }
      if (tree.features) add_features(*tree.features, global, page.features);
      pages_.push_back(std::move(page));
    }
  }

  std::uint32_t page_count() const override { return static_cast<std::uint32_t>(pages_.size()); }
  std::uint64_t page_storage_bytes(std::uint32_t page) const override {
    return pages_.at(page).nodes.size() * kStorageBytesPerNode;
  }
  std::uint32_t page_node_count(std::uint32_t page) const override {
    return static_cast<std::uint32_t>(pages_.at(page).nodes.size());
  }
  std::uint64_t page_memory_bytes(std::uint32_t page) const override {
    const HierarchyPage& p = pages_.at(page);
    return HierarchyPage::memory_bytes(p.nodes.size()) +
           (p.features.empty() ? 0 : p.features.memory_bytes());
  }
  const TreeFeatures* features() const override {
    return features_ ? &*features_ : nullptr;
  }
  std::uint64_t open_bytes() const override { return 0; }
  SphereTreeView summary() const override { return summary_; }
  void load(std::uint32_t page, HierarchyPage& out, const PagePrefix&) const override {
    out = pages_.at(page);
    out.storage_bytes = page_storage_bytes(page);
  }

 private:
  // The features of the nodes `global` (tree indices, in page order).
  static void add_features(const TreeFeatures& f, const std::vector<std::uint32_t>& global,
                           PageFeatures& out) {
    out.clipped_first.assign(1, 0);
    for (std::size_t k = 0; k < global.size(); ++k) {
      const std::uint32_t g = global[k];
      out.surface.push_back(f.surface[g]);
      const auto planes = f.planes(g);
      if (planes.empty()) continue;
      out.clipped.push_back(static_cast<std::uint32_t>(k));
      out.clipped_mode.push_back(f.clip_mode[g]);
      out.planes.insert(out.planes.end(), planes.begin(), planes.end());
      out.clipped_first.push_back(static_cast<std::uint32_t>(out.planes.size()));
    }
  }

  SphereTreeView summary_;
  std::vector<HierarchyPage> pages_;
  std::optional<TreeFeatures> features_;  // counts, options and statistics only
};

}  // namespace

void PageFeatures::clear() {
  surface.clear();
  clipped.clear();
  clipped_mode.clear();
  clipped_first.clear();
  planes.clear();
}

std::span<const ClipPlane> PageFeatures::planes_of(std::uint32_t node, ClipMode& mode) const {
  const auto it = std::lower_bound(clipped.begin(), clipped.end(), node);
  if (it == clipped.end() || *it != node) {
    mode = ClipMode::None;
    return {};
  }
  const std::size_t k = static_cast<std::size_t>(it - clipped.begin());
  mode = clipped_mode[k];
  return {planes.data() + clipped_first[k], planes.data() + clipped_first[k + 1]};
}

void PackedPage::index_links(std::uint32_t first_level_count) {
  const auto count = static_cast<std::uint32_t>(records.size());
  assert(last_level_begin <= count);
  // Blocks below last_level_begin, then blocks from it; the +2 of memory_bytes covers the
  // partial block on either side.
  link_base.assign((count >> kBlockShift) + 2, 0);
  link_step.resize(count);  // every entry is written below
  // Each part block by block: a block's base, then a running sum of its records' child counts
  // (on the last level, link indices count its interior nodes: one each). A loop a part,
  // without a test of which part a record is in (a full-detail frame of a 100 M-point model
  // spent 9 % of its time here).
  const auto part = [&]<bool kLastLevel>(std::uint32_t begin, std::uint32_t end,
                                         std::uint32_t value, std::uint32_t block) {
    for (std::uint32_t b = begin; b < end; b += 1u << kBlockShift, ++block) {
      link_base[block] = value;
      const std::uint32_t stop = std::min(end, b + (1u << kBlockShift));
      std::uint32_t step = 0;  // at most 4 · 63
      for (std::uint32_t i = b; i < stop; ++i) {
        link_step[i] = static_cast<std::uint8_t>(step);
        const std::uint32_t children = quant::record_child_count(records[i]);
        step += kLastLevel ? std::uint32_t{children != 0} : children;
      }
      value += step;
    }
  };
  part.template operator()<false>(0, last_level_begin, first_level_count, 0);
  part.template operator()<true>(last_level_begin, count, 0, first_last_level_block());
}

std::unique_ptr<PageSource> paginate(const SphereTreeView& tree, std::uint64_t page_bytes,
                                     std::uint32_t max_levels) {
  if (page_bytes < 5 * kStorageBytesPerNode) {
    throw OptionError("page size " + std::to_string(page_bytes) +
                      " bytes is too small; a page must hold a node and 4 children (200 bytes)");
  }
  if (max_levels < 1) throw OptionError("pages must hold at least 1 level of the hierarchy");
  return std::make_unique<InMemoryPages>(tree, page_bytes, max_levels);
}

}  // namespace pointillist
