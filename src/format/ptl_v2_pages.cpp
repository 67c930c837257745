// PtlV2File pages as HierarchyPages (see ptl_v2_pages.hpp).
#include "pointillist/format/ptl_v2_pages.hpp"

#include <algorithm>
#include <string>
#include <vector>

#include "pointillist/core/error.hpp"

namespace pointillist {
namespace {

class PtlV2Pages final : public PageSource {
 public:
  explicit PtlV2Pages(const PtlV2File& file) : file_(file), children_(file.page_count()) {
    for (std::uint32_t q = 1; q < file.page_count(); ++q) {
      children_[file.page_info(q).parent_page].push_back(q);
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
  }

  std::uint32_t page_count() const override { return file_.page_count(); }
  std::uint64_t page_storage_bytes(std::uint32_t page) const override {
    return file_.page_info(page).byte_size;
  }
  std::uint32_t page_node_count(std::uint32_t page) const override {
    return file_.page_info(page).node_count;
  }
  std::uint64_t open_bytes() const override { return open_bytes_; }
  SphereTreeView summary() const override { return summary_; }

  void load(std::uint32_t page, const SphereNode*, HierarchyPage& out) const override {
    PtlV2Page decoded;
    file_.decode_page(page, decoded);
    out.nodes = std::move(decoded.nodes);
    out.child_page.assign(out.nodes.size(), kNoPage);
    for (const std::uint32_t q : children_[page]) {
      const PtlV2PageInfo& info = file_.page_info(q);
      std::uint32_t offset = 0;
      for (std::uint32_t j = 0; j < info.root_count; ++j) {
        SphereNode& anchor = out.nodes.at(info.first_root + j);
        out.child_page[info.first_root + j] = q;
        anchor.first_child = offset;
        offset += anchor.child_count;
      }
    }
    for (std::size_t i = decoded.last_level_begin; i < out.nodes.size(); ++i) {
      if (out.nodes[i].child_count > 0 && out.child_page[i] == kNoPage) {
        throw FormatError("page " + std::to_string(page) + ", node " + std::to_string(i) +
                          ": has children but no page holds them; the model file is corrupt "
                          "(convert it again)");
      }
    }
  }

 private:
  const PtlV2File& file_;
  std::vector<std::vector<std::uint32_t>> children_;  // child pages of each page, by first root
  std::uint64_t open_bytes_ = 0;
  SphereTreeView summary_;
};

}  // namespace

std::unique_ptr<PageSource> ptl_v2_page_source(const PtlV2File& file) {
  return std::make_unique<PtlV2Pages>(file);
}

}  // namespace pointillist
