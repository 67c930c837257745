#include "cli/model_loading.hpp"

#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "pointillist/core/error.hpp"
#include "pointillist/core/thread_pool.hpp"
#include "pointillist/io/ply.hpp"

namespace pointillist::cli {

namespace {

// Appends `b` to `a`. An attribute survives only when every part has it, so the merged set stays
// consistent (one entry per position or none).
void append_points(PointSet& a, PointSet&& b) {
  const bool first = a.positions.empty() && a.triangles.empty();
  if (first) {
    a = std::move(b);
    return;
  }
  const auto offset = static_cast<std::uint32_t>(a.positions.size());
  const auto merge = [&](auto& dst, auto& src) {
    if (dst.empty() || src.empty()) {
      dst.clear();
      return;
    }
    dst.insert(dst.end(), src.begin(), src.end());
  };
  merge(a.normals, b.normals);
  merge(a.colors, b.colors);
  merge(a.radii, b.radii);
  a.positions.insert(a.positions.end(), b.positions.begin(), b.positions.end());
  for (auto t : b.triangles) a.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  a.comments.insert(a.comments.end(), b.comments.begin(), b.comments.end());
}

}  // namespace

PointSet read_inputs(const std::vector<std::string>& paths, ThreadPool& pool, Progress& progress) {
  PointSet all;
  for (const std::string& path : paths) {
    if (!std::filesystem::exists(path)) {
      throw IoError(path + ": no such file; check the path (models fetched by "
                           "scripts/fetch-models.sh are in ~/.cache/pointillist/models)");
    }
    if (is_ptl_file(path)) {
      throw Error(path + ": is already a Pointillist model (.ptl); give the source scan (.ply, "
                         ".ply.gz) to convert, or render the .ptl directly");
    }
    append_points(all, read_ply(path, progress, {.pool = &pool}));
  }
  return all;
}

LoadedModel LoadedModel::open(const std::string& path, const PrepareOptions& prepare,
                              ThreadPool& pool, Progress& progress) {
  LoadedModel model;
  if (!std::filesystem::exists(path)) {
    throw IoError(path + ": no such file; check the path");
  }
  model.file_size = std::filesystem::file_size(path);
  if (is_ptl_file(path)) {
    model.file_ = PtlFile::open(path);
    model.view_ = model.file_->tree();
    model.metadata = model.file_->metadata();
    return model;
  }
  PointSet points = read_inputs({path}, pool, progress);
  model.input_points = points.size();
  model.input_has_normals = points.has_normals();
  model.input_has_colors = points.has_colors();
  model.input_has_radii = points.has_radii();
  model.input_is_mesh = points.is_mesh();
  prepare_splats(points, pool, progress, prepare);
  model.built_ = build_sphere_tree(points, pool, progress);
  model.view_ = model.built_.view();
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
