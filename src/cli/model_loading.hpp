// Getting from a file on disk to a hierarchy the renderer can draw: open a .ptl by memory mapping,
// or read a point/mesh file, prepare splats and build the hierarchy in memory.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "pointillist/core/point_set.hpp"
#include "pointillist/core/progress.hpp"
#include "pointillist/core/thread_pool.hpp"
#include "pointillist/format/ptl.hpp"
#include "pointillist/format/ptl_v2.hpp"
#include "pointillist/lod/sphere_tree.hpp"
#include "pointillist/prep/prepare.hpp"
#include "pointillist/render/paged.hpp"

namespace pointillist::cli {

// Reads and merges one or more input files (any extension read_point_file knows: PLY, XYZ/PTS/
// CSV text, OBJ, LAS). Parts whose readers shifted coordinates to a local origin (LAS, large text
// coordinates) are moved into the first part's frame, so tiles of one scan line up; the merged
// set keeps the first part's "origin:" comment. An attribute (normals, radii) survives only
// when every part has it; colors survive when any part has them (parts without get a neutral
// grey, and `warnings` says which). `columns` is passed to the text reader.
PointSet read_inputs(const std::vector<std::string>& paths, ThreadPool& pool, Progress& progress,
                     const std::string& columns = {},
                     std::vector<std::string>* warnings = nullptr);

// A hierarchy either mapped from a .ptl file, decoded from a QSplat .qs file, or built in memory
// from a point or mesh file.
class LoadedModel {
 public:
  const SphereTreeView& tree() const { return view_; }
  bool memory_mapped() const { return file_ != nullptr || v2_ != nullptr; }
  const PtlFile* ptl() const { return file_.get(); }
  bool qsplat() const { return qsplat_; }
  // The pages of a paged model file (rendered out of core), or null: the whole hierarchy is in
  // tree().
  const PageSource* pages() const { return pages_.get(); }
  std::uint64_t file_size = 0;
  std::string metadata;
  // Kept for `info` when the input was not a .ptl.
  std::size_t input_points = 0;
  bool input_has_normals = false, input_has_colors = false, input_has_radii = false;
  bool input_is_mesh = false;

  // With keep_source, a scan's prepared points (normals and radii computed, faces kept) stay in
  // `source` (for the triangle reference renderer); models (.ptl, .qs) leave it empty.
  // Paging (.ptl version 2 files only; other models are held whole): Never decodes the whole
  // hierarchy into tree(); Always keeps it in the file and gives pages() (tree() then has no
  // nodes, only the counts and boxes); WhenLarge pages when the decoded hierarchy would take
  // more than a quarter of the machine's memory.
  enum class Paging { Never, WhenLarge, Always };
  static LoadedModel open(const std::string& path, const PrepareOptions& prepare, ThreadPool& pool,
                          Progress& progress, const std::string& columns = {},
                          bool keep_source = false, Paging paging = Paging::Never);
  // The .ptl version (1 or 2), 0 for other inputs.
  std::uint32_t ptl_version() const { return ptl_version_; }
  const PtlV2File* ptl_v2() const { return v2_.get(); }
  PointSet source;

 private:
  std::unique_ptr<PtlFile> file_;
  std::unique_ptr<PtlV2File> v2_;
  std::uint32_t ptl_version_ = 0;
  std::unique_ptr<PageSource> pages_;
  bool qsplat_ = false;
  SphereTree built_;
  SphereTreeView view_;
};

// "1.23 MB"-style size.
std::string human_bytes(double bytes);

}  // namespace pointillist::cli

namespace pointillist::cli {
// Path of a model fetched by scripts/fetch-models.sh ($POINTILLIST_MODELS, else
// $XDG_CACHE_HOME/pointillist/models, else ~/.cache/pointillist/models), or "" if absent.
std::string cached_model_path(const std::string& file_name);
}  // namespace pointillist::cli
