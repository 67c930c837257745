// MergedInputs (see chunk_inputs.hpp).
#include "chunk_inputs.hpp"

#include "pointillist/core/error.hpp"

namespace pointillist::chunking {

MergedInputs::MergedInputs(std::span<const std::string> paths, const std::string& columns) {
  for (const std::string& path : paths) {
    streams_.push_back(open_point_stream(path, {.columns = columns}));
    const PointStreamInfo& info = streams_.back()->info();
    if (info.is_mesh) {
      throw Error(path + ": is a mesh, which chunks cannot read (convert_chunked turns meshes "
                         "into points first); this is a bug");
    }
    count_ += info.point_count;
    normals_ = normals_ && info.has_normals;
    radii_ = radii_ && info.has_radii;
    colors_ = colors_ || info.has_colors;
    for (const std::string& c : info.comments) {
      if (paths.size() == 1 || seen_.insert(c).second) comments_.push_back(c);
    }
  }
  origin_ = streams_[0]->info().origin;
  up_ = streams_[0]->info().up;
}

std::optional<std::string> MergedInputs::colour_warning() const {
  std::vector<std::string> without;
  for (const auto& s : streams_) {
    if (!s->info().has_colors) without.push_back(s->info().path);
  }
  if (!colors_ || without.empty()) return std::nullopt;
  std::string list;
  for (std::size_t i = 0; i < without.size() && i < 5; ++i) list += (i ? ", " : "") + without[i];
  if (without.size() > 5) list += ", ...";
  return std::to_string(without.size()) + " of " + std::to_string(streams_.size()) +
         " input files have no colors; their points are grey (" + list + ")";
}

}  // namespace pointillist::chunking
