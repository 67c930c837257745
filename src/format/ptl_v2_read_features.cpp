// The sharp-features section of a .ptl version 2 file as PtlV2File reads it
// (docs/ptl-format.md, "Sharp features"): its fixed fields once, a page's block when the page is
// loaded, every node's features when the whole hierarchy is decoded.
#include <string>
#include <vector>

#include "ptl_v2_features.hpp"
#include "ptl_v2_mesh.hpp"
#include "ptl_v2_mapping.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/format/ptl_v2.hpp"
#include "pointillist/lod/pages.hpp"

namespace pointillist {

using namespace ptl2;

const ptl2::FeatureSection& PtlV2File::feature_section() const {
  std::call_once(map_->features_once, [&] {
    const std::string_view view = map_->bytes.view();
    map_->features = decode_feature_header(view.substr(features_offset_, features_size_),
                                           features_offset_, leaf_count_, page_count(), path_);
    map_->summary.surface_count = map_->features.surfaces;
    map_->summary.options = map_->features.options;
    map_->summary.stats = map_->features.stats;
  });
  return map_->features;
}

const TreeFeatures* PtlV2File::feature_summary() const {
  if (features_size_ == 0) return nullptr;
  feature_section();
  return &map_->summary;
}

bool PtlV2File::page_features_stored() const {
  return features_size_ != 0 && feature_section().version >= 2;
}

void PtlV2File::page_features(std::uint32_t page, const std::function<bool(std::uint32_t)>& is_leaf,
                              PageFeatures& out) const {
  const ptl2::FeatureSection& section = feature_section();
  if (section.version < 2) {
    throw FormatError(path_ + ": its sharp features are stored for the whole model (a file of an "
                      "earlier Pointillist), not per page; convert it again to draw them page by "
                      "page");
  }
  const std::string_view view = map_->bytes.view();
  decode_page_features(view.substr(features_offset_, features_size_), features_offset_, section,
                       page, pages_.at(page).node_count, is_leaf, path_, out);
}

std::uint64_t PtlV2File::page_feature_memory(std::uint32_t page) const {
  if (!page_features_stored()) return 0;
  const ptl2::FeatureSection& f = feature_section();
  return PageFeatures::memory_bytes(pages_.at(page).node_count, f.clipped.at(page),
                                    f.planes.at(page));
}

std::optional<FeatureData> PtlV2File::features() const {
  if (features_size_ == 0) return std::nullopt;
  const ptl2::FeatureSection& section = feature_section();
  if (section.version == 1) {
    const std::string_view view = map_->bytes.view();
    return decode_leaf_features(view.substr(features_offset_, features_size_), features_offset_,
                                section, leaf_count_, path_);
  }
  TreeFeatures tree;
  const SphereTree whole = decode_all(&tree);
  FeatureData out;
  out.options = tree.options;
  out.stats = tree.stats;
  out.clip_offset.push_back(0);
  for (std::size_t k = 0; k < whole.nodes.size(); ++k) {
    if (whole.nodes[k].child_count != 0) continue;
    out.surface_id.push_back(tree.surface[k]);
    out.clip_mode.push_back(tree.clip_mode[k]);
    const auto planes = tree.planes(k);
    out.clip_planes.insert(out.clip_planes.end(), planes.begin(), planes.end());
    out.clip_offset.push_back(static_cast<std::uint32_t>(out.clip_planes.size()));
  }
  return out;
}

void PtlV2File::gather_features(const SphereTree& tree, std::span<const PtlV2Page> pages,
                                std::span<const NodeRef> refs, TreeFeatures& out) const {
  const ptl2::FeatureSection& section = feature_section();
  if (section.version == 1) {
    out = tree_features(tree.nodes, *features());
    return;
  }
  // Each page's block, then every node's features from its page and record.
  std::vector<PageFeatures> blocks(pages.size());
  for (std::uint32_t p = 0; p < pages.size(); ++p) {
    const PtlV2Page& pg = pages[p];
    page_features(
        p, [&](std::uint32_t k) { return pg.nodes[k].child_count == 0; }, blocks[p]);
  }
  out = {};
  out.surface_count = section.surfaces;
  out.options = section.options;
  out.stats = section.stats;
  out.surface.resize(tree.nodes.size());
  out.clip_mode.resize(tree.nodes.size());
  out.clip_offset.assign(tree.nodes.size() + 1, 0);
  for (std::size_t i = 0; i < tree.nodes.size(); ++i) {
    const NodeRef ref = refs[i];
    out.surface[i] = blocks[ref.page].surface[ref.record];
    const auto planes = blocks[ref.page].planes_of(ref.record, out.clip_mode[i]);
    out.clip_planes.insert(out.clip_planes.end(), planes.begin(), planes.end());
    out.clip_offset[i + 1] = static_cast<std::uint32_t>(out.clip_planes.size());
  }
}

std::vector<std::array<std::uint32_t, 3>> PtlV2File::triangles() const {
  if (mesh_offset_ == 0) return {};
  return decode_mesh(map_->bytes.view().substr(mesh_offset_, mesh_size_), mesh_offset_,
                     leaf_count_, page_count(), path_);
}

}  // namespace pointillist
