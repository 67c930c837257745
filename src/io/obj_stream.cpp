// Wavefront OBJ files (gzip too) streamed a window of lines at a time: the `v` lines of a point
// cloud written as OBJ, as read_obj gives them, in constant memory. Opening reads every line
// once: the vertex count, the first vertex (the origin of a file far from zero), whether every
// vertex has a colour and on which scale, and whether faces make triangles (a mesh: its vertices
// stream, but the chunked conversion refuses meshes). Each read parses the next `v` lines.
#include <filesystem>
#include <memory>
#include <string_view>

#include "line_window.hpp"
#include "obj_vertex.hpp"
#include "ply_body.hpp"
#include "streams.hpp"

namespace pointillist::io_detail {
namespace {

// Errors name the line being parsed, as read_obj's do.
struct Fail {
  const std::string& path;
  const std::uint64_t& line;
  [[noreturn]] void operator()(const char*, const std::string& what) const {
    throw FormatError(path + ": line " + std::to_string(line) + ": " + what);
  }
};

// The next line of `window` that is not blank or a comment (`line` counts the lines read): t
// after its keyword, its end, the keyword.
bool next_obj_line(LineWindow& window, std::uint64_t& line, const char*& t, const char*& le,
                   std::string_view& keyword) {
  const char* start;
  while (window.next_line(start, le)) {
    ++line;
    const char* k = skip_blanks(start, le);
    if (k == le || *k == '#') continue;
    t = k;
    while (t < le && !is_blank(*t)) ++t;
    keyword = std::string_view(k, std::size_t(t - k));
    return true;
  }
  return false;
}

class ObjStream final : public PointStream {
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
  bool next(const char*& t, const char*& le, std::string_view& keyword) {
    return next_obj_line(window_, line_, t, le, keyword);
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

// The faces of an OBJ file a window of lines at a time, with the corners that name file normals,
// and the `vn` lines in a pass of their own. Opening counts the v, vn and f lines, so a corner
// naming a vertex or normal defined later is checked at once against the file's count.
class ObjFaceStream final : public FaceStream {
 public:
  explicit ObjFaceStream(const std::string& path) : path_(path), window_(path) {
    window_.rewind();
    const char* t;
    const char* le;
    std::string_view keyword;
    while (next_obj_line(window_, line_, t, le, keyword)) {
      if (keyword == "v") ++vertex_count_;
      if (keyword == "vn") ++normal_count_;
      if (keyword == "f") ++face_count_;
    }
    if (vertex_count_ > 0xffffffffu) {
      throw FormatError(path + ": more than 2^32 - 1 vertices (triangles hold 32-bit indices)");
    }
    window_.rewind();
    line_ = 0;
  }

  bool read(std::vector<std::array<std::uint32_t, 3>>& triangles) override {
    triangles.clear();
    normal_refs_.clear();
    if (done_) return false;
    const Fail fail{path_, line_};
    const char* t;
    const char* le;
    std::string_view keyword;
    for (std::uint64_t faces = 0; faces < kWindowFaces;) {
      if (!next_obj_line(window_, line_, t, le, keyword)) {
        done_ = true;
        window_.release();
        break;
      }
      if (keyword == "v") ++defined_v_;
      if (keyword == "vn") ++defined_vn_;
      if (keyword != "f") continue;
      ply::FanBuilder fan;
      ObjCorner c;
      for (const char* p = t; (p = parse_obj_corner(p, le, fan.seen + 1, c, fail));) {
        const std::int64_t v =
            resolve_obj_index(c.v, defined_v_, c.token, "vertex", forward_, fail);
        if (std::uint64_t(v) >= vertex_count_) {
          fail(c.token, "f: vertex index " + std::to_string(c.v) + " out of range (the file has " +
                            std::to_string(vertex_count_) + " vertices)");
        }
        fan.add(static_cast<std::uint32_t>(v), triangles);
        if (!c.has_vn) continue;
        const std::int64_t n =
            resolve_obj_index(c.vn, defined_vn_, c.token, "normal", forward_, fail);
        if (std::uint64_t(n) >= normal_count_) {
          fail(c.token, "f: normal index " + std::to_string(c.vn) + " out of range (the file has " +
                            std::to_string(normal_count_) + " vn lines)");
        }
        normal_refs_.push_back({static_cast<std::uint32_t>(v), static_cast<std::uint32_t>(n)});
      }
      ++faces;
      ++faces_done_;
    }
    return true;
  }
  std::uint64_t faces_done() const override { return faces_done_; }

  bool read_normals(std::vector<Vec3f>& normals) override {
    normals.clear();
    if (!normal_window_) {
      normal_window_ = std::make_unique<LineWindow>(path_);
      normal_window_->rewind();
      normal_line_ = 0;
    }
    const Fail fail{path_, normal_line_};
    const char* t;
    const char* le;
    std::string_view keyword;
    while (normals.size() < kWindowFaces) {
      if (!next_obj_line(*normal_window_, normal_line_, t, le, keyword)) {
        normal_window_->release();
        break;
      }
      if (keyword != "vn") continue;
      float values[3] = {};
      parse_obj_normal(t, le, values, fail);
      normals.push_back({values[0], values[1], values[2]});
    }
    return !normals.empty();
  }

 private:
  static constexpr std::uint64_t kWindowFaces = 1 << 16;

  std::string path_;  // before window_, which uses it
  LineWindow window_;
  std::unique_ptr<LineWindow> normal_window_;
  std::uint64_t line_ = 0, normal_line_ = 0;
  std::uint64_t defined_v_ = 0, defined_vn_ = 0, faces_done_ = 0;
  ForwardReference forward_;  // (checked at once against the counts)
  bool done_ = false;
};

}  // namespace

std::unique_ptr<FaceStream> open_obj_face_stream(const std::string& path) {
  auto stream = std::make_unique<ObjFaceStream>(path);
  if (stream->face_count() == 0) return nullptr;
  return stream;
}

std::unique_ptr<PointStream> open_obj_stream(const std::string& path,
                                             const PointReadOptions& options) {
  return std::make_unique<ObjStream>(path, options);
}

}  // namespace pointillist::io_detail
