// open_model: every kind of model file, and scans built in memory (see model.hpp).
#include <unistd.h>

#include <filesystem>
#include <string>

#include "pointillist/core/error.hpp"
#include "pointillist/format/ptl.hpp"
#include "pointillist/format/ptl_v2.hpp"
#include "pointillist/format/ptl_v2_pages.hpp"
#include "pointillist/format/qs.hpp"
#include "pointillist/io/merge.hpp"
#include "pointillist/pipeline/model.hpp"

namespace pointillist {

Model::Model() : source_(std::make_unique<PointSet>()) {}
Model::Model(Model&&) noexcept = default;
Model& Model::operator=(Model&&) noexcept = default;
Model::~Model() = default;

bool is_model_file(const std::string& path) { return is_ptl_file(path) || is_qs_file(path); }

namespace {

std::uint64_t physical_memory_bytes() {
  return std::uint64_t(::sysconf(_SC_PHYS_PAGES)) * std::uint64_t(::sysconf(_SC_PAGESIZE));
}

std::string megabytes(double bytes) { return std::to_string(std::uint64_t(bytes / 1e6)) + " MB"; }
std::string milliseconds(double ns) { return std::to_string(std::uint64_t(ns / 1e6 + 0.5)) + " ms"; }

// The costs Paging::Auto weighs (see OpenModelOptions::frames).
constexpr double kDecodeNsPerNode = 100.0;
constexpr double kPagingNsPerPixel = 2.7;

}  // namespace

Model Model::open_file(const std::string& path, const OpenModelOptions& options, ThreadPool& pool,
                       Progress& progress) {
  Model model;
  model.path_ = path;
  if (!std::filesystem::exists(path)) {
    throw IoError(path + ": no such file; check the path");
  }
  model.file_size_ = std::filesystem::file_size(path);
  if (is_ptl_file(path) && ptl_file_version(path) == kPtlV2Version) {
    model.kind_ = ModelKind::PtlV2;
    model.v2_ = PtlV2File::open(path);
    model.metadata_ = model.v2_->metadata();
    const double decoded_bytes = double(model.v2_->node_count()) * sizeof(SphereNode);
    const double memory =
        double(options.memory_bytes ? options.memory_bytes : physical_memory_bytes());
    bool paged = false;
    switch (options.paging) {
      case Paging::Always:
        paged = true;
        model.paging_reason_ = "paged: asked for (a memory cap or progressive loading)";
        break;
      case Paging::Never:
        model.paging_reason_ = "decoded whole: the frames need the whole hierarchy";
        break;
      case Paging::Auto: {
        const double decode_ns = kDecodeNsPerNode * double(model.v2_->node_count());
        const double paging_ns =
            kPagingNsPerPixel * double(options.frames) * double(options.frame_pixels);
        const std::string frames = std::to_string(options.frames) +
                                   (options.frames == 1 ? " frame" : " frames");
        if (decoded_bytes > memory / 4) {
          paged = true;
          model.paging_reason_ = "paged: the decoded hierarchy would take " +
                                 megabytes(decoded_bytes) + ", more than a quarter of the memory (" +
                                 megabytes(memory) + ")";
        } else if (options.stored_features && model.v2_->has_features() &&
                   !model.v2_->page_features_stored()) {
          model.paging_reason_ =
              "decoded whole: its sharp features (stored by an earlier Pointillist for the whole "
              "model) are drawn from the whole hierarchy";
        } else if (options.frames > 1) {
          model.paging_reason_ =
              "decoded whole: the " + frames + " of a sequence draw from the whole hierarchy "
              "(paged, they would show pages still loading)";
        } else {
          paged = paging_ns < decode_ns;
          model.paging_reason_ =
              std::string(paged ? "paged" : "decoded whole") + ": for " + frames +
              ", drawing from pages adds about " + milliseconds(paging_ns) + (paged ? ", less" : ", more") +
              " than decoding the whole hierarchy takes (about " + milliseconds(decode_ns) + ")";
        }
        break;
      }
    }
    // The stored features, unless they are not wanted or computed anew (options.features).
    const bool stored = options.stored_features && !options.features && model.v2_->has_features();
    if (paged) {
      model.pages_ = ptl_v2_page_source(*model.v2_, stored);
      model.view_ = model.pages_->summary();
      if (stored && !model.v2_->page_features_stored()) {
        model.paging_reason_ += "; its sharp features (stored by an earlier Pointillist for the "
                                "whole model) are drawn only when it is decoded whole: convert it "
                                "again to draw them page by page";
      }
    } else {
      ProgressPhase phase(progress, "decode", 0);
      if (stored) model.features_ = std::make_unique<TreeFeatures>();
      model.built_ = model.v2_->decode_all(model.features_.get());
      model.view_ = model.built_.view();
      // A mesh's faces (hybrid rendering draws models held whole).
      if (model.v2_->has_triangles()) model.triangles_ = model.v2_->triangles();
    }
    return model;
  }
  // A .ptl or .qs name without the signature goes to its reader, whose error says what the
  // first bytes should have been.
  const auto named = [&](const char* ext) {
    const std::string e(ext);
    return path.size() >= e.size() && path.compare(path.size() - e.size(), e.size(), e) == 0;
  };
  if (is_ptl_file(path) || named(".ptl")) {
    model.kind_ = ModelKind::PtlV1;
    model.v1_ = PtlFile::open(path);
    model.view_ = model.v1_->tree();
    model.metadata_ = model.v1_->metadata();
    model.paging_reason_ = "mapped: .ptl version 1 files are read through a memory map";
    return model;
  }
  if (is_qs_file(path) || named(".qs")) {
    ProgressPhase phase(progress, "decode", 0);
    QsModel qs = read_qs(path);
    model.kind_ = ModelKind::Qsplat;
    model.metadata_ = qs.metadata();
    model.built_ = std::move(qs.tree);
    model.view_ = model.built_.view();
    model.paging_reason_ = "decoded whole: .qs files are decoded on opening";
    return model;
  }
  const std::string paths[] = {path};
  return from_scans(paths, options, pool, progress);
}

Model Model::from_scans(std::span<const std::string> paths, const OpenModelOptions& options,
                        ThreadPool& pool, Progress& progress) {
  Model model;
  model.path_ = paths.front();
  for (const std::string& p : paths) {
    std::error_code ec;
    model.file_size_ += std::filesystem::file_size(p, ec);
  }
  PointSet points = merge_inputs(paths, pool, progress, {.columns = options.columns});
  model.kind_ = ModelKind::Scan;
  model.scan_input_ = {.points = points.size(),
                       .has_normals = points.has_normals(),
                       .has_colors = points.has_colors(),
                       .has_radii = points.has_radii(),
                       .is_mesh = points.is_mesh()};
  // The Morton order of a cloud's neighbour search, which the hierarchy reuses.
  std::vector<std::uint32_t> morton;
  PrepareOptions prepare = options.prepare;
  prepare.morton_order = &morton;
  prepare_splats(points, pool, progress, prepare);
  std::vector<std::uint32_t> split_order;
  SphereTreeOptions tree_options;
  tree_options.morton_order = &morton;
  model.built_ = build_sphere_tree(points, pool, progress, tree_options,
                                   points.is_mesh() ? &split_order : nullptr);
  morton = {};
  model.view_ = model.built_.view();
  if (points.is_mesh()) model.triangles_ = leaf_triangles(model.view_, split_order, points.triangles);
  model.paging_reason_ = "in memory: built from the scan";
  if (options.keep_source) *model.source_ = std::move(points);
  return model;
}

Model open_model(const std::string& path, const OpenModelOptions& options, ThreadPool& pool,
                 Progress& progress) {
  return Model::finish(Model::open_file(path, options, pool, progress), options, pool, progress);
}

Model open_scans(std::span<const std::string> paths, const OpenModelOptions& options,
                 ThreadPool& pool, Progress& progress) {
  if (paths.empty()) throw OptionError("no scan to open; give at least one input file");
  for (const std::string& p : paths) {
    if (!std::filesystem::exists(p)) throw IoError(p + ": no such file; check the path");
  }
  Model model = Model::from_scans(paths, options, pool, progress);
  if (paths.size() > 1) {
    model.path_ += " (+" + std::to_string(paths.size() - 1) + " more)";
  }
  return Model::finish(std::move(model), options, pool, progress);
}

Model Model::finish(Model model, const OpenModelOptions& options, ThreadPool& pool,
                    Progress& progress) {
  if (options.features && !model.paged()) {
    const bool quantized = model.kind_ == ModelKind::PtlV2 || model.kind_ == ModelKind::Qsplat;
    const FeatureOptions fo =
        quantized ? for_quantized_model(*options.features) : *options.features;
    model.features_ =
        std::make_unique<TreeFeatures>(compute_tree_features(model.view_, pool, fo, progress));
    model.view_.features = model.features_.get();
  } else if (model.features_) {
    model.view_.features = model.features_.get();  // stored ones, decoded with the hierarchy
  }
  model.renderable_ = std::make_unique<RenderModel>(
      RenderModel{.tree = model.view_,
                  .pages = model.pages_.get(),
                  .mesh = options.keep_source && model.kind_ == ModelKind::Scan
                              ? model.source_.get()
                              : nullptr,
                  .triangles = model.triangles_,
                  .name = model.path_});
  return model;
}

}  // namespace pointillist
