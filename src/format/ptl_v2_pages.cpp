// PtlV2File pages as packed HierarchyPages (see ptl_v2_pages.hpp).
#include "pointillist/format/ptl_v2_pages.hpp"

#include <algorithm>
#include <string>
#include <vector>

#include "pointillist/core/error.hpp"
#include "ptl_v2_layout.hpp"

namespace pointillist {
namespace {

std::string str(std::uint64_t v) { return std::to_string(v); }

class PtlV2Pages final : public PageSource {
 public:
  PtlV2Pages(const PtlV2File& file, bool with_features)
      : file_(file), children_(file.page_count()), link_count_(file.page_count(), 0),
        features_(with_features && file.page_features_stored() ? file.feature_summary()
                                                               : nullptr) {
    for (std::uint32_t q = 1; q < file.page_count(); ++q) {
      const PtlV2PageInfo& info = file.page_info(q);
      children_[info.parent_page].push_back(q);
      link_count_[info.parent_page] += info.root_count;
    }
    for (auto& c : children_) {
      std::sort(c.begin(), c.end(), [&](std::uint32_t a, std::uint32_t b) {
        return file.page_info(a).first_root < file.page_info(b).first_root;
      });
    }
    open_bytes_ = file.page_count() > 0 ? file.page_info(0).offset : file.file_size();
    summary_.has_colors = file.has_colors();
    summary_.leaf_count = file.leaf_count();
    summary_.depth = file.depth();
    summary_.bounds = file.bounds();
    summary_.view_sphere = file.view_sphere();
    summary_.origin = file.origin();
    summary_.up = file.up();
  }

  std::uint32_t page_count() const override { return file_.page_count(); }
  std::uint64_t page_storage_bytes(std::uint32_t page) const override {
    return file_.page_info(page).byte_size;
  }
  std::uint32_t page_node_count(std::uint32_t page) const override {
    return file_.page_info(page).node_count;
  }
  std::uint64_t page_memory_bytes(std::uint32_t page) const override {
    const std::uint32_t nodes = file_.page_info(page).node_count;
    return PackedPage::memory_bytes(nodes, link_count_[page], file_.has_colors()) +
           (features_ ? file_.page_feature_memory(page) : 0);
  }
  const TreeFeatures* features() const override { return features_; }
  std::uint64_t open_bytes() const override { return open_bytes_; }
  SphereTreeView summary() const override { return summary_; }

  void load(std::uint32_t page, HierarchyPage& out, const PagePrefix& prefix) const override {
    load_packed(page, out, prefix);
    // Packed now: the file's bytes need not stay mapped beside the copy.
    file_.forget_page(page);
  }

 private:
  void load_packed(std::uint32_t page, HierarchyPage& out, const PagePrefix& prefix) const {
    out.nodes.clear();
    out.child_page.clear();
    PackedPage& packed = out.packed;
    // What `out` holds already (an earlier prefix of this page) is kept, not read again.
    const auto had = static_cast<std::uint32_t>(packed.records.size());
    file_.pack_page(page, packed, prefix);
    const PtlV2PageInfo& info = file_.page_info(page);
    const auto count = static_cast<std::uint32_t>(packed.records.size());
    out.storage_bytes = std::uint64_t{info.root_count} * ptl2::kRootEntrySize +
                        std::uint64_t{count - had} * (file_.has_colors() ? 6 : 4);
    if (count < info.node_count) {
      load_prefix_rest(page, out);
      return;
    }
    const auto corrupt = [&](std::uint32_t node, const std::string& what) {
      throw FormatError(file_.path() + ": page " + str(page) + ", node " + str(node) + ": " + what +
                        "; the model file is corrupt (convert it again)");
    };
    // Link the last level's interior nodes to the child pages that hold their children.
    std::vector<std::uint8_t> linked(count - packed.last_level_begin, 0);
    std::uint32_t previous = 0;
    for (const std::uint32_t q : children_[page]) {
      const PtlV2PageInfo& child = file_.page_info(q);
      std::uint32_t offset = 0;
      for (std::uint32_t j = 0; j < child.root_count; ++j) {
        const std::uint32_t node = child.first_root + j;
        const std::uint32_t children = quant::record_child_count(packed.records[node]);
        if (node < packed.last_level_begin || children == 0) {
          corrupt(node, "page " + str(q) + " continues it, but it is not an interior node of the "
                            "page's last level");
        }
        if (linked[node - packed.last_level_begin]++) {
          corrupt(node, "two pages continue it");
        }
        // Child pages come by first root, so links follow the last level's interior nodes in
        // order: links[k] belongs to the k-th (PackedPage::link).
        if (!packed.links.empty() && node <= previous) corrupt(node, "child pages overlap");
        previous = node;
        packed.links.push_back({q, offset});
        offset += children;
      }
    }
    for (std::uint32_t i = packed.last_level_begin; i < count; ++i) {
      if (quant::record_child_count(packed.records[i]) != 0 &&
          !linked[i - packed.last_level_begin]) {
        corrupt(i, "has children but no page holds them");
      }
    }
    if (features_) {
      file_.page_features(
          page,
          [&](std::uint32_t k) { return quant::record_child_count(packed.records[k]) == 0; },
          out.features);
    } else {
      out.features.clear();
    }
  }

  // A page's first levels were packed: the features are the whole page's cut to the loaded
  // records.
  void load_prefix_rest(std::uint32_t page, HierarchyPage& out) const {
    PackedPage& packed = out.packed;
    const auto count = static_cast<std::uint32_t>(packed.records.size());
    if (!features_) {
      out.features.clear();
      return;
    }
    PageFeatures& f = out.features;
    file_.page_features(
        page,
        [&](std::uint32_t k) {
          const std::uint32_t rec = k < count ? packed.records[k] : file_.page_record(page, k);
          return quant::record_child_count(rec) == 0;
        },
        f);
    f.surface.resize(count);
    const auto kept = static_cast<std::size_t>(
        std::lower_bound(f.clipped.begin(), f.clipped.end(), count) - f.clipped.begin());
    f.clipped.resize(kept);
    f.clipped_mode.resize(kept);
    if (!f.clipped_first.empty()) {
      f.clipped_first.resize(kept + 1);
      f.planes.resize(f.clipped_first[kept]);
    }
  }

  const PtlV2File& file_;
  std::vector<std::vector<std::uint32_t>> children_;  // child pages of each page, by first root
  std::vector<std::uint64_t> link_count_;             // roots of each page's child pages
  std::uint64_t open_bytes_ = 0;
  SphereTreeView summary_;
  const TreeFeatures* features_;  // the file's, when its pages carry them and they are wanted
};

}  // namespace

std::unique_ptr<PageSource> ptl_v2_page_source(const PtlV2File& file, bool with_features) {
  return std::make_unique<PtlV2Pages>(file, with_features);
}

}  // namespace pointillist
