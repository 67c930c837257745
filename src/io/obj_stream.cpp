// Wavefront OBJ files (gzip too) streamed a window of lines at a time: the `v` lines of a point
// cloud written as OBJ, as read_obj gives them, in constant memory. Opening reads every line
// once: the vertex count, the first vertex (the origin of a file far from zero), whether every
// vertex has a colour and on which scale, and whether faces make triangles (a mesh: its vertices
// stream, but the chunked conversion refuses meshes). Each read parses the next `v` lines.
#include <filesystem>
#include <string_view>

#include "line_window.hpp"
#include "obj_vertex.hpp"
#include "ply_body.hpp"
#include "streams.hpp"

namespace pointillist::io_detail {
namespace {

class ObjStream final : public PointStream {
  // Errors name the line being parsed, as read_obj's do.
  struct Fail {
    const std::string& path;
    const std::uint64_t& line;
    [[noreturn]] void operator()(const char*, const std::string& what) const {
      throw FormatError(path + ": line " + std::to_string(line) + ": " + what);
    }
  };

 public:
  ObjStream(const std::string& path, const PointReadOptions& options)
      : path_(path), window_(path) {
    std::uint64_t count = 0, colored = 0;
    double max_color = 0;
    bool faces = false;
    window_.rewind();
    line_ = 0;
    const char* t;
    const char* le;
    std::string_view keyword;
    while (next(t, le, keyword)) {
      if (keyword == "f") faces = faces || corners(t, le) >= 3;  // a triangle, as read_obj fans
      if (keyword != "v") continue;
      double values[7] = {};
      const int n = parse_obj_vertex(t, le, values, fail_at());
      if (count == 0) origin_ = text_origin(values);
      check_obj_vertex_fits(values, origin_, le, fail_at());
      ++count;
      if (n == 6) {
        ++colored;
        for (int c = 3; c < 6; ++c) max_color = std::max(max_color, values[c]);
      }
    }
    if (count == 0) {
      throw FormatError(path + ": line " + std::to_string(line_) +
                        ": no vertices (expected 'v x y z' lines); is this an OBJ file?");
    }
    colors_ = options.read_colors && colored == count;
    scale_ = max_color > 1.0 ? ply::ColorScale::Byte : ply::ColorScale::Unit;
    info_.path = path;
    info_.point_count = count;
    info_.has_colors = colors_;
    info_.is_mesh = faces;
    info_.file_size = std::filesystem::file_size(path);
    info_.origin = origin_;
    if (options.read_colors && colored > 0 && colored < count) {
      info_.comments.push_back("vertex colors ignored: only " + std::to_string(colored) + " of " +
                               std::to_string(count) + " vertices have them");
    }
    window_.release();
    pending_start_ = true;
  }

  std::size_t read(PointSet& batch, std::size_t max) override {
    size_batch(batch, 0, info_);
    if (pending_start_) {
      window_.rewind();
      line_ = 0;
    }
    pending_start_ = false;
    const char* t;
    const char* le;
    std::string_view keyword;
    std::size_t n = 0;
    while (n < max && next(t, le, keyword)) {
      if (keyword != "v") continue;
      double values[7] = {};
      parse_obj_vertex(t, le, values, fail_at());
      check_obj_vertex_fits(values, origin_, le, fail_at());
      batch.positions.push_back({static_cast<float>(values[0] - origin_[0]),
                                 static_cast<float>(values[1] - origin_[1]),
                                 static_cast<float>(values[2] - origin_[2])});
      if (colors_) {
        batch.colors.push_back({ply::to_color(values[3], scale_), ply::to_color(values[4], scale_),
                                ply::to_color(values[5], scale_)});
      }
      ++n;
    }
    if (n < max) window_.release();  // the end: free the window until a rewind
    return n;
  }
  void rewind() override { pending_start_ = true; }
  std::uint64_t bytes_done() const override { return pending_start_ ? 0 : window_.bytes_done(); }
  bool saw_usable_normals() const override { return false; }

 private:
  // The blank-separated tokens of [p, le).
  static int corners(const char* p, const char* le) {
    int n = 0;
    for (p = skip_blanks(p, le); p < le; p = skip_blanks(p, le)) {
      ++n;
      while (p < le && !is_blank(*p)) ++p;
    }
    return n;
  }
  // The next line that is not blank or a comment: t after its keyword, its end, the keyword.
  bool next(const char*& t, const char*& le, std::string_view& keyword) {
    const char* start;
    while (window_.next_line(start, le)) {
      ++line_;
      const char* k = skip_blanks(start, le);
      if (k == le || *k == '#') continue;
      t = k;
      while (t < le && !is_blank(*t)) ++t;
      keyword = std::string_view(k, std::size_t(t - k));
      return true;
    }
    return false;
  }
  Fail fail_at() const { return {path_, line_}; }

  std::string path_;  // before window_, which uses it
  LineWindow window_;
  std::uint64_t line_ = 0;  // 1-based number of the line last read
  std::array<double, 3> origin_{};
  bool colors_ = false;
  ply::ColorScale scale_ = ply::ColorScale::Byte;
  bool pending_start_ = true;
};

}  // namespace

std::unique_ptr<PointStream> open_obj_stream(const std::string& path,
                                             const PointReadOptions& options) {
  return std::make_unique<ObjStream>(path, options);
}

}  // namespace pointillist::io_detail
