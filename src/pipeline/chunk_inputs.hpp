// The inputs of a chunked conversion as one stream (private to pipeline; chunked_convert.cpp).
#pragma once

#include <algorithm>
#include <array>
#include <memory>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <vector>

#include "pointillist/core/point_set.hpp"
#include "pointillist/core/progress.hpp"
#include "pointillist/io/point_stream.hpp"

namespace pointillist::chunking {

constexpr Rgb8 kMissingColor{180, 180, 180};  // as merge_inputs gives parts without colours
constexpr std::size_t kBatch = 1 << 20;      // points per read, at most

// The inputs as one stream, with merge_inputs' rules: parts move into the first part's frame,
// normals and radii survive when every part has them, colours when any has them (grey else).
class MergedInputs {
 public:
  // Opens every input (a mesh is refused). Throws what open_point_stream throws.
  MergedInputs(std::span<const std::string> paths, const std::string& columns);

  // Reads batches that take about a 256th of `budget` (a point and its window bytes, about
  // 64 bytes, in 1 M-point batches from a 256 MB budget up).
  void fit_batches(std::uint64_t budget) {
    batch_ = static_cast<std::size_t>(std::clamp<std::uint64_t>(budget / 256, 4096, kBatch));
  }

  // As merge_inputs warns: files without colours among files with them are drawn grey.
  std::optional<std::string> colour_warning() const;

  // Points the passes see: the inputs' less the dropped.
  std::uint64_t count() const { return count_ - dropped_.size(); }
  // From now on the passes skip these points (input indices, ascending, unique) and number the
  // others consecutively.
  void drop(std::vector<std::uint64_t> indices) { dropped_ = std::move(indices); }
  bool has_normals() const { return normals_; }
  bool has_radii() const { return radii_; }
  bool has_colors() const { return colors_; }
  const std::array<double, 3>& origin() const { return origin_; }
  Vec3f up() const { return up_; }
  const std::vector<std::string>& comments() const { return comments_; }
  const std::vector<std::unique_ptr<PointStream>>& streams() const { return streams_; }
  std::size_t batch_points() const { return batch_; }
  // After a full pass: a part whose normals were all unusable has none (as read_point_file).
  void drop_unusable_normals() {
    for (const auto& s : streams_) normals_ = normals_ && s->saw_usable_normals();
  }

  // Calls fn(batch, index of its first point) over every point not dropped, in order; tells
  // `progress` which file it reads when there are several.
  template <class Fn>
  void for_each_batch(Progress& progress, Fn&& fn) {
    std::uint64_t next = 0, read = 0;  // points passed on; points read
    std::size_t skip = 0;              // the next dropped index
    std::vector<std::uint8_t> keep;
    PointSet batch;
    for (std::size_t k = 0; k < streams_.size(); ++k) {
      const auto& stream = streams_[k];
      if (streams_.size() > 1) {
        const std::string& path = stream->info().path;
        const std::size_t slash = path.find_last_of('/');
        progress.detail(path.substr(slash == std::string::npos ? 0 : slash + 1) + " (" +
                        std::to_string(k + 1) + "/" + std::to_string(streams_.size()) + ")");
      }
      stream->rewind();
      const std::array<double, 3>& o = stream->info().origin;
      const double shift[3] = {o[0] - origin_[0], o[1] - origin_[1], o[2] - origin_[2]};
      const bool shifted = shift[0] != 0 || shift[1] != 0 || shift[2] != 0;
      while (const std::size_t n = stream->read(batch, batch_)) {
        if (shifted) {
          for (Vec3f& p : batch.positions) {
            p = {float(p.x + shift[0]), float(p.y + shift[1]), float(p.z + shift[2])};
          }
        }
        if (!normals_) batch.normals.clear();
        if (!radii_) batch.radii.clear();
        if (colors_ && batch.colors.empty()) batch.colors.assign(n, kMissingColor);
        if (skip < dropped_.size() && dropped_[skip] < read + n) {
          keep.assign(n, 1);
          for (; skip < dropped_.size() && dropped_[skip] < read + n; ++skip) {
            keep[dropped_[skip] - read] = 0;
          }
          keep_points(batch, keep);
        }
        read += n;
        if (batch.size() == 0) continue;
        fn(batch, next);
        next += batch.size();
      }
    }
  }

 private:
  std::vector<std::unique_ptr<PointStream>> streams_;
  std::size_t batch_ = kBatch;
  std::uint64_t count_ = 0;
  bool normals_ = true, radii_ = true, colors_ = false;
  std::array<double, 3> origin_{};
  Vec3f up_{0, 1, 0};
  std::vector<std::string> comments_;
  std::set<std::string> seen_;
  std::vector<std::uint64_t> dropped_;
};

}  // namespace pointillist::chunking
