// Writing .ptl version 2 (docs/ptl-format.md, "Version 2"): a whole hierarchy encoded
// (ptl_v2_encode.hpp), cut into pages, written to a temporary file and renamed.
#include <string>
#include <vector>

#include "ptl_v2_encode.hpp"
#include "ptl_v2_features.hpp"
#include "ptl_v2_mesh.hpp"
#include "pointillist/core/atomic_file.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/format/ptl_v2.hpp"

namespace pointillist {

using namespace ptl2;

PtlV2WriteReport write_ptl_v2(const std::string& path, const SphereTree& tree,
                              const std::string& metadata, const PtlV2WriteOptions& options) {
  ThreadPool pool(1);
  return write_ptl_v2(path, tree, metadata, options, pool);
}

PtlV2WriteReport write_ptl_v2(const std::string& path, const SphereTree& tree,
                              const std::string& metadata, const PtlV2WriteOptions& options,
                              ThreadPool& pool) {
  if (options.page_bytes < kMinPageBytes) {
    throw OptionError("page_bytes " + std::to_string(options.page_bytes) +
                      " is below the minimum " + std::to_string(kMinPageBytes));
  }
  PtlV2WriteReport report;
  std::uint64_t leaves = 0;
  std::uint32_t depth = 0;
  const std::vector<std::uint32_t> parent = check_tree(path, tree.nodes, leaves, depth);
  const auto& nodes = tree.nodes;
  const std::size_t n = nodes.size();
  const bool colors = options.write_colors && tree.has_colors;
  const std::uint32_t record_size = colors ? 6 : 4;

  const std::vector<PagePlan> pages = plan_pages(nodes, record_size, options.page_bytes);
  if (pages.size() >= kPtlNoPage) throw Error("cannot write " + path + ": too many pages");

  // Layout: header, page table, pages, metadata, features.
  std::uint64_t page_offset = kHeaderSize + pages.size() * kPageEntrySize;
  std::vector<PtlV2PageInfo> table;
  table.reserve(pages.size());
  for (const PagePlan& pg : pages) {
    table.push_back(page_entry(pg, page_offset));
    page_offset += pg.byte_size;
  }
  std::vector<std::span<const std::uint32_t>> page_nodes;
  for (const PagePlan& pg : pages) page_nodes.emplace_back(pg.nodes);
  std::vector<std::uint8_t> feature_bytes, mesh_bytes;
  if (options.features) feature_bytes = encode_features(nodes, *options.features, page_nodes);
  if (!options.triangles.empty()) {
    for (std::size_t t = 0; t < options.triangles.size(); ++t) {
      for (const std::uint32_t c : options.triangles[t]) {
        if (c >= leaves) {
          throw Error("cannot write " + path + ": triangle " + std::to_string(t) +
                      " refers to leaf " + std::to_string(c) + " of " + std::to_string(leaves));
        }
      }
    }
    mesh_bytes = encode_mesh(nodes, options.triangles, page_nodes, pool);
  }
  // Encoded last: the mesh's working arrays are gone by then, so the peak holds one or the other.
  EncodeStats stats;
  const EncodedTree enc =
      encode_tree(nodes, parent, nullptr, nullptr, options.leaf_trim, colors, pool, stats);
  report.spheres_enlarged = stats.spheres_enlarged;
  report.parent_fallbacks = stats.parent_fallbacks;
  report.mean_leaf_radius_ratio =
      stats.leaf_ratio_count ? stats.leaf_ratio_sum / double(stats.leaf_ratio_count) : 1;
  for (int c = 0; c < 4; ++c) report.cone_codes[c] = stats.cone_codes[c];

  HeaderFields fields;
  fields.colors = colors;
  fields.record_size = record_size;
  fields.leaf_trim = options.leaf_trim;
  fields.node_count = n;
  fields.leaf_count = leaves;
  fields.depth = depth;
  fields.page_bytes = options.page_bytes;
  fields.metadata_offset = page_offset;
  fields.metadata_size = metadata.size();
  fields.features_offset = feature_bytes.empty() ? 0 : page_offset + metadata.size();
  fields.features_size = feature_bytes.size();
  fields.mesh_offset =
      mesh_bytes.empty() ? 0 : page_offset + metadata.size() + feature_bytes.size();
  fields.root_sphere = enc.root_parent;
  fields.bounds = tree.bounds;
  fields.view_sphere = tree.view_sphere;
  fields.origin = tree.origin;
  fields.up = tree.up;
  const std::vector<std::uint8_t> head = header_and_table(fields, table);

  AtomicFile file(path);
  file.write(head.data(), head.size());
  std::vector<std::uint8_t> bytes;
  std::vector<Sphere> root_spheres;
  std::vector<std::uint8_t> root_children;
  for (std::size_t p = 0; p < pages.size(); ++p) {
    const PagePlan& pg = pages[p];
    root_spheres.clear();
    root_children.clear();
    if (p == 0) {
      root_spheres.push_back(enc.root_parent);
      root_children.push_back(1);
    }
    for (const std::uint32_t r : pg.roots) {
      root_spheres.push_back(enc.decoded[r]);
      root_children.push_back(nodes[r].child_count);
    }
    page_bytes(pg, root_spheres, root_children, enc.record, record_size, bytes);
    file.write(bytes.data(), bytes.size());
  }
  file.write(metadata.data(), metadata.size());
  file.write(feature_bytes.data(), feature_bytes.size());
  file.write(mesh_bytes.data(), mesh_bytes.size());
  file.commit();

  report.file_size = page_offset + metadata.size() + feature_bytes.size() + mesh_bytes.size();
  report.mesh_bytes = mesh_bytes.size();
  report.record_bytes = std::uint64_t{n} * record_size;
  report.node_count = n;
  report.leaf_count = leaves;
  report.page_count = static_cast<std::uint32_t>(pages.size());
  report.record_size = record_size;
  report.bytes_per_leaf = double(report.file_size) / double(leaves);
  return report;
}

}  // namespace pointillist
