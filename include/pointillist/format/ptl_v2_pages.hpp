// A .ptl version 2 file as the page source of the paged renderer (lod/pages.hpp): each file
// page is one HierarchyPage kept in its packed form (the file's records and about a byte of links
// a node) and decoded during the traversal, so a model larger than memory renders with only the
// pages it needs resident, at about 5.1 bytes a node (7.1 with colour).
#pragma once

#include <memory>

#include "pointillist/format/ptl_v2.hpp"
#include "pointillist/lod/pages.hpp"

namespace pointillist {

// Pages of `file`, which must outlive the result. open_bytes() is everything before the first
// page (header, schema, page table); page_storage_bytes() a page's size in the file. load()
// throws FormatError for a corrupt page (including an interior node of a page's last level that
// no child page continues). With `with_features` and a file that stores sharp features page by
// page, each loaded page carries its nodes' features (PageFeatures); a damaged features section
// throws FormatError here (its fixed fields) or from load() (a page's block).
std::unique_ptr<PageSource> ptl_v2_page_source(const PtlV2File& file, bool with_features = true);

}  // namespace pointillist
