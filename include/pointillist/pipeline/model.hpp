// A model ready to render, whatever it was on disk: a hierarchy built in memory from a scan, a
// mapped .ptl version 1 file, a .ptl version 2 file decoded whole or paged (drawn page by page
// from a page cache when it is too large to decode), or a decoded QSplat .qs file.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>

#include "pointillist/core/point_set.hpp"
#include "pointillist/core/progress.hpp"
#include "pointillist/core/thread_pool.hpp"
#include "pointillist/lod/pages.hpp"
#include "pointillist/lod/sphere_tree.hpp"
#include "pointillist/lod/tree_features.hpp"
#include "pointillist/prep/prepare.hpp"
#include "pointillist/render/renderer.hpp"

namespace pointillist {

class PtlFile;
class PtlV2File;

enum class ModelKind {
  Scan,   // a point or mesh file, prepared and built in memory
  PtlV1,  // .ptl version 1, memory-mapped float nodes
  PtlV2,  // .ptl version 2, quantized pages
  Qsplat, // QSplat .qs, decoded
};

// Whether a .ptl version 2 model is drawn from its pages (out of core) or decoded whole.
enum class Paging {
  Never,   // decode the whole hierarchy
  Auto,    // the faster way for the frames to come (OpenModelOptions::frames), or paged when the
           // decoded hierarchy would take more than a quarter of the memory
  Always,  // page (other kinds of model are cut into pages in memory by the renderer)
};

struct OpenModelOptions {
  PrepareOptions prepare;    // scans: how normals and radii are computed
  std::string columns;       // text scans: the column layout (empty = detected)
  bool keep_source = false;  // scans: keep the prepared points and faces (mesh reference)
  Paging paging = Paging::Auto;
  // The machine's memory for Paging::Auto (bytes); 0 = ask the operating system.
  std::uint64_t memory_bytes = 0;
  // What Paging::Auto weighs: the frames that will be drawn and their pixels. A sequence of
  // frames is decoded whole (paged, its frames would show pages still loading, unlike the
  // same frames of a decoded model). A single image, drawn once its pages are loaded, is the
  // same image either way: decoding a .ptl v2 whole costs about 100 ns a node, drawing from its
  // pages about 2.7 ns a pixel more (both measured on the dragon and a 5-million-point cloud at
  // 1280x720), and a view reads only the pages it needs; so one image is paged unless the model
  // is tiny (the dragon 1.4x faster to its PNG, a 5M cloud 2.9x with 0.57x the memory).
  std::uint64_t frames = 1;
  std::uint64_t frame_pixels = 1280 * 720;
  // Compute sharp features (surface ids, clip planes) on the leaves of a model held whole, with
  // these options (render --features). A paged model gets none.
  std::optional<FeatureOptions> features;
  // Load the sharp features a .ptl file stores: with the hierarchy when it is decoded, with
  // each page when it is paged (files that store them for the whole model, written before
  // 2026-11-26, are then decoded whole by Paging::Auto, unless that would take more than a
  // quarter of the memory).
  bool stored_features = true;
};

class Model {
 public:
  Model();
  Model(Model&&) noexcept;
  Model& operator=(Model&&) noexcept;
  ~Model();

  const std::string& path() const { return path_; }
  ModelKind kind() const { return kind_; }
  // The whole hierarchy; for a paged model only its counts and boxes (no nodes).
  const SphereTreeView& tree() const { return view_; }
  // The pages of a paged model (render them page by page), or null.
  const PageSource* pages() const { return pages_.get(); }
  bool paged() const { return pages_ != nullptr; }
  // Why the model is paged or held whole, for --stats and messages.
  const std::string& paging_reason() const { return paging_reason_; }
  // A scan's prepared points (with OpenModelOptions::keep_source; empty otherwise).
  const PointSet& source() const { return *source_; }
  // A mesh's faces over the hierarchy's leaves (sphere_tree_leaves order): scans with faces and
  // .ptl files converted from them; empty otherwise.
  std::span<const std::array<std::uint32_t, 3>> triangles() const { return triangles_; }
  // What the renderer draws (its address stays the same for the model's life, moves included).
  const RenderModel& renderable() const { return *renderable_; }
  // The file's metadata text (.ptl, .qs), one "key: value" per line.
  const std::string& metadata() const { return metadata_; }
  std::uint64_t file_size() const { return file_size_; }
  // Sharp features of the hierarchy's nodes, or for a paged model whose pages carry them their
  // surface count, options and statistics only (no per-node arrays); null without features.
  const TreeFeatures* features() const {
    return features_ ? features_.get() : pages_ ? pages_->features() : nullptr;
  }
  // .ptl files (null for other kinds).
  const PtlFile* ptl_v1() const { return v1_.get(); }
  const PtlV2File* ptl_v2() const { return v2_.get(); }

  // What a scan held before preparation (kind() == Scan).
  struct ScanInput {
    std::size_t points = 0;
    bool has_normals = false, has_colors = false, has_radii = false, is_mesh = false;
  };
  const ScanInput& scan_input() const { return scan_input_; }

 private:
  friend Model open_model(const std::string&, const OpenModelOptions&, ThreadPool&, Progress&);
  friend Model open_scans(std::span<const std::string>, const OpenModelOptions&, ThreadPool&,
                          Progress&);
  static Model open_file(const std::string&, const OpenModelOptions&, ThreadPool&, Progress&);
  static Model from_scans(std::span<const std::string>, const OpenModelOptions&, ThreadPool&,
                          Progress&);
  // Sharp features and the renderable, once the hierarchy is there.
  static Model finish(Model model, const OpenModelOptions&, ThreadPool&, Progress&);
  std::string path_;
  ModelKind kind_ = ModelKind::Scan;
  std::unique_ptr<PtlFile> v1_;
  std::unique_ptr<PtlV2File> v2_;
  std::unique_ptr<PageSource> pages_;
  std::string paging_reason_;
  SphereTree built_;
  SphereTreeView view_;
  std::unique_ptr<PointSet> source_;
  std::unique_ptr<RenderModel> renderable_;
  std::string metadata_;
  std::uint64_t file_size_ = 0;
  ScanInput scan_input_;
  std::unique_ptr<TreeFeatures> features_;
  // A mesh's faces over the hierarchy's leaves (scans with faces, .ptl files that keep them).
  std::vector<std::array<std::uint32_t, 3>> triangles_;
};

// Opens the model at `path`, chosen by its contents (.ptl, .qs) or, for anything else, read as a
// scan (any input of read_point_file), prepared (options.prepare) and built into a sphere tree
// in memory. Throws IoError for a missing file, and what the readers and builders throw.
Model open_model(const std::string& path, const OpenModelOptions& options, ThreadPool& pool,
                 Progress& progress);

// Several scans read as one (merge_inputs: tiles of one survey line up, normals and radii near a
// tile's border see its neighbours), prepared and built into one hierarchy in memory. The
// model's path is the first file's, followed by " (+N more)". Throws IoError for a missing file
// and what the readers and builders throw.
Model open_scans(std::span<const std::string> paths, const OpenModelOptions& options,
                 ThreadPool& pool, Progress& progress);

// True when `path` is a splat model (.ptl or .qs) rather than a scan.
bool is_model_file(const std::string& path);

}  // namespace pointillist
