#include "model_loading.hpp"

#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "pointillist/core/error.hpp"
#include "pointillist/core/thread_pool.hpp"
#include "pointillist/format/ptl_v2_pages.hpp"
#include "pointillist/format/qs.hpp"
#include "pointillist/io/point_file.hpp"

namespace pointillist::cli {

namespace {

constexpr Rgb8 kMissingColor{180, 180, 180};

// Appends `b` to `a` (see read_inputs for the rules). `b_origin` is where b's coordinates are
// relative to, `a_origin` a's.
void append_points(PointSet& a, PointSet&& b, const std::array<double, 3>& a_origin,
                   const std::array<double, 3>& b_origin) {
  const auto offset = static_cast<std::uint32_t>(a.positions.size());
  const std::size_t a_count = a.positions.size(), b_count = b.positions.size();
  const auto merge = [&](auto& dst, auto& src) {
    if (dst.empty() || src.empty()) {
      dst.clear();
      return;
    }
    dst.insert(dst.end(), src.begin(), src.end());
  };
  merge(a.normals, b.normals);
  merge(a.radii, b.radii);
  if (!a.colors.empty() || !b.colors.empty()) {
    if (a.colors.empty()) a.colors.assign(a_count, kMissingColor);
    if (b.colors.empty()) b.colors.assign(b_count, kMissingColor);
    a.colors.insert(a.colors.end(), b.colors.begin(), b.colors.end());
  }
  const double shift[3] = {b_origin[0] - a_origin[0], b_origin[1] - a_origin[1],
                           b_origin[2] - a_origin[2]};
  const bool shifted = shift[0] != 0 || shift[1] != 0 || shift[2] != 0;
  a.positions.reserve(a_count + b_count);
  for (const Vec3f& p : b.positions) {
    a.positions.push_back(shifted ? Vec3f{static_cast<float>(p.x + shift[0]),
                                          static_cast<float>(p.y + shift[1]),
                                          static_cast<float>(p.z + shift[2])}
                                  : p);
  }
  for (auto t : b.triangles) a.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  for (auto& c : b.comments) {
    if (c.rfind("origin: ", 0) != 0) a.comments.push_back(std::move(c));
  }
}

}  // namespace

PointSet read_inputs(const std::vector<std::string>& paths, ThreadPool& pool, Progress& progress,
                     const std::string& columns, std::vector<std::string>* warnings) {
  PointSet all;
  std::array<double, 3> all_origin{};
  std::vector<std::string> without_colors;
  bool any_colors = false;
  for (std::size_t i = 0; i < paths.size(); ++i) {
    const std::string& path = paths[i];
    if (!std::filesystem::exists(path)) {
      throw IoError(path + ": no such file; check the path (models fetched by "
                           "scripts/fetch-models.sh are in ~/.cache/pointillist/models)");
    }
    if (is_ptl_file(path) || is_qs_file(path)) {
      throw Error(path + ": is already a splat model (" + (is_ptl_file(path) ? ".ptl" : ".qs") +
                  "); give the source scan (" + supported_point_file_extensions() +
                  ") to convert, or render the model directly");
    }
    PointSet part = read_point_file(path, progress, {.pool = &pool, .columns = columns});
    const std::array<double, 3> origin = point_set_origin(part).value_or(std::array<double, 3>{});
    if (part.colors.empty()) without_colors.push_back(path);
    any_colors = any_colors || !part.colors.empty();
    if (i == 0) {
      all = std::move(part);
      all_origin = origin;
    } else {
      append_points(all, std::move(part), all_origin, origin);
    }
  }
  if (warnings && any_colors && !without_colors.empty()) {
    std::string list;
    for (std::size_t i = 0; i < without_colors.size() && i < 5; ++i) {
      list += (i ? ", " : "") + without_colors[i];
    }
    if (without_colors.size() > 5) list += ", ...";
    warnings->push_back(std::to_string(without_colors.size()) + " of " +
                        std::to_string(paths.size()) +
                        " input files have no colors; their points are grey (" + list + ")");
  }
  return all;
}

LoadedModel LoadedModel::open(const std::string& path, const PrepareOptions& prepare,
                              ThreadPool& pool, Progress& progress, const std::string& columns,
                              bool keep_source, Paging paging) {
  LoadedModel model;
  if (!std::filesystem::exists(path)) {
    throw IoError(path + ": no such file; check the path");
  }
  model.file_size = std::filesystem::file_size(path);
  if (is_ptl_file(path) && ptl_file_version(path) == kPtlV2Version) {
    model.v2_ = PtlV2File::open(path);
    model.ptl_version_ = kPtlV2Version;
    model.metadata = model.v2_->metadata();
    const double decoded_bytes = double(model.v2_->node_count()) * sizeof(SphereNode);
    const double memory = double(::sysconf(_SC_PHYS_PAGES)) * double(::sysconf(_SC_PAGESIZE));
    if (paging == Paging::Always || (paging == Paging::WhenLarge && decoded_bytes > memory / 4)) {
      model.pages_ = ptl_v2_page_source(*model.v2_);
      model.view_ = model.pages_->summary();
    } else {
      ProgressPhase phase(progress, "decode", 0);
      model.built_ = model.v2_->decode_all();
      model.view_ = model.built_.view();
    }
    return model;
  }
  if (is_ptl_file(path)) {
    model.ptl_version_ = 1;
    model.file_ = PtlFile::open(path);
    model.view_ = model.file_->tree();
    model.metadata = model.file_->metadata();
    return model;
  }
  if (is_qs_file(path)) {
    ProgressPhase phase(progress, "decode", 0);
    QsModel qs = read_qs(path);
    model.qsplat_ = true;
    model.metadata = qs.metadata();
    model.built_ = std::move(qs.tree);
    model.view_ = model.built_.view();
    return model;
  }
  PointSet points = read_inputs({path}, pool, progress, columns);
  model.input_points = points.size();
  model.input_has_normals = points.has_normals();
  model.input_has_colors = points.has_colors();
  model.input_has_radii = points.has_radii();
  model.input_is_mesh = points.is_mesh();
  prepare_splats(points, pool, progress, prepare);
  model.built_ = build_sphere_tree(points, pool, progress);
  model.view_ = model.built_.view();
  if (keep_source) model.source = std::move(points);
  return model;
}

std::string human_bytes(double bytes) {
  const char* units[] = {"B", "KB", "MB", "GB", "TB"};
  int u = 0;
  while (bytes >= 1000.0 && u < 4) {
    bytes /= 1000.0;
    ++u;
  }
  char buf[32];
  std::snprintf(buf, sizeof buf, u == 0 ? "%.0f %s" : "%.2f %s", bytes, units[u]);
  return buf;
}

}  // namespace pointillist::cli

namespace pointillist::cli {

std::string cached_model_path(const std::string& file_name) {
  std::filesystem::path dir;
  if (const char* env = std::getenv("POINTILLIST_MODELS"); env && *env) {
    dir = env;
  } else if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) {
    dir = std::filesystem::path(xdg) / "pointillist" / "models";
  } else if (const char* home = std::getenv("HOME"); home && *home) {
    dir = std::filesystem::path(home) / ".cache" / "pointillist" / "models";
  } else {
    return {};
  }
  const auto path = dir / file_name;
  return std::filesystem::exists(path) ? path.string() : std::string{};
}

}  // namespace pointillist::cli
