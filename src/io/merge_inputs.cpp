// Several scans merged into one point set (see merge.hpp).
#include <array>
#include <filesystem>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "pointillist/core/error.hpp"
#include "pointillist/io/merge.hpp"
#include "pointillist/io/point_file.hpp"

namespace pointillist {
namespace {

constexpr Rgb8 kMissingColor{180, 180, 180};

// Appends `b` to `a` (see merge_inputs for the rules). `b_origin` is where b's coordinates are
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
  for (auto& c : b.comments) a.comments.push_back(std::move(c));
}

// Keeps the first of equal comments (tiles of one survey repeat their header comments).
void drop_repeated_comments(std::vector<std::string>& comments) {
  std::set<std::string> seen;
  std::vector<std::string> kept;
  for (auto& c : comments) {
    if (seen.insert(c).second) kept.push_back(std::move(c));
  }
  comments = std::move(kept);
}

}  // namespace

PointSet merge_inputs(std::span<const std::string> paths, ThreadPool& pool, Progress& progress,
                      const MergeOptions& options, std::vector<std::string>* warnings) {
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
    PointSet part = read_point_file(path, progress, {.pool = &pool, .columns = options.columns});
    const std::array<double, 3> origin = point_set_origin(part).value_or(std::array<double, 3>{});
    if (part.colors.empty()) without_colors.push_back(path);
    any_colors = any_colors || !part.colors.empty();
    if (i == 0) {
      all = std::move(part);
      all_origin = origin;
      all.origin = origin;
    } else {
      append_points(all, std::move(part), all_origin, origin);
    }
  }
  if (paths.size() > 1) drop_repeated_comments(all.comments);
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

}  // namespace pointillist
