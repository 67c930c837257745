// Wavefront OBJ reader: one pass over the in-memory text, line by line. Face corners that refer
// forward (a vertex or normal defined later in the file) are checked and resolved at the end.
#include <cmath>
#include <cstring>
#include <limits>

#include "pointillist/core/file_bytes.hpp"
#include "obj_vertex.hpp"
#include "ply_body.hpp"
#include "text_numbers.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/io/obj.hpp"

namespace pointillist {
namespace {

using namespace io_detail;

constexpr std::int64_t kMaxVertices = std::numeric_limits<std::uint32_t>::max();

class ObjParser {
 public:
  ObjParser(const std::string& path, std::string_view data, const ObjReadOptions& options,
            ReadProgress& progress)
      : path_(path), data_(data), options_(options), progress_(progress) {}

  PointSet parse() {
    const char* end = data_.data() + data_.size();
    const char* reported = data_.data();
    std::size_t lines = 0;
    for (const char* p = data_.data(); p < end;) {
      const char* le = line_end(p, end);
      const char* t = skip_blanks(p, le);
      p = le + 1;
      if (t == le || *t == '#') continue;
      const char* k = t;
      while (k < le && !is_blank(*k)) ++k;
      const std::string_view keyword(t, static_cast<std::size_t>(k - t));
      if (keyword == "v")
        parse_vertex(k, le);
      else if (keyword == "vn")
        parse_normal(k, le);
      else if (keyword == "f")
        parse_face(k, le);
      if ((++lines & 0xffff) == 0) {
        const char* done = std::min(p, end);
        progress_.advance(static_cast<std::uint64_t>(done - reported));
        reported = done;
      }
    }
    progress_.advance(static_cast<std::uint64_t>(end - reported));
    return finish();
  }

 private:
  [[noreturn, gnu::cold]] void fail(const char* pos, const std::string& what) const {
    throw FormatError(path_ + ": line " + std::to_string(line_number(data_, pos)) + ": " + what);
  }

  // `v x y z [w]` or `v x y z r g b`.
  void parse_vertex(const char* p, const char* le) {
    double values[7] = {};
    const auto fail_at = [this](const char* pos, const std::string& what) { fail(pos, what); };
    const int count = parse_obj_vertex(p, le, values, fail_at);
    if (positions_.empty()) origin_ = text_origin(values);
    if (positions_.size() >= static_cast<std::size_t>(kMaxVertices))
      fail(p, "more than 2^32 - 1 vertices (triangles hold 32-bit indices)");
    check_obj_vertex_fits(values, origin_, le, fail_at);
    positions_.push_back({static_cast<float>(values[0] - origin_[0]),
                          static_cast<float>(values[1] - origin_[1]),
                          static_cast<float>(values[2] - origin_[2])});
    if (count == 6 && options_.read_colors) {
      // Vertices before the first colored one get a placeholder; colors are kept only when
      // every vertex has them.
      colors_.resize(positions_.size() - 1);
      colors_.push_back({static_cast<float>(values[3]), static_cast<float>(values[4]),
                         static_cast<float>(values[5])});
      for (int c = 3; c < 6; ++c) max_color_ = std::max(max_color_, values[c]);
      ++colored_count_;
    }
  }

  void parse_normal(const char* p, const char* le) {
    float values[3] = {};
    parse_obj_normal(p, le, values, [this](const char* pos, const std::string& what) {
      fail(pos, what);
    });
    normals_.push_back({values[0], values[1], values[2]});
  }

  void parse_face(const char* p, const char* le) {
    const auto fail_at = [this](const char* pos, const std::string& what) { fail(pos, what); };
    ply::FanBuilder fan;
    ObjCorner c;
    while ((p = parse_obj_corner(p, le, fan.seen + 1, c, fail_at))) {
      const std::int64_t vi =
          resolve_obj_index(c.v, positions_.size(), c.token, "vertex", forward_vertex_, fail_at);
      fan.add(static_cast<std::uint32_t>(vi), triangles_);
      if (!c.has_vn) continue;
      const std::int64_t ni =
          resolve_obj_index(c.vn, normals_.size(), c.token, "normal", forward_normal_, fail_at);
      has_normal_refs_ = true;
      if (static_cast<std::size_t>(vi) < positions_.size() &&
          static_cast<std::size_t>(ni) < normals_.size())
        add_normal(static_cast<std::size_t>(vi), normals_[static_cast<std::size_t>(ni)]);
      else
        deferred_normals_.push_back({static_cast<std::uint32_t>(vi), static_cast<std::uint32_t>(ni)});
    }
  }

  void add_normal(std::size_t vertex, Vec3f n) {
    if (normal_sum_.size() <= vertex) normal_sum_.resize(positions_.size());
    normal_sum_[vertex] += n;
  }

  PointSet finish();

  // A corner's normal reference with a forward part, applied at the end.
  struct DeferredNormal {
    std::uint32_t vertex, normal;  // 0-based
  };

  const std::string& path_;
  std::string_view data_;
  const ObjReadOptions& options_;
  ReadProgress& progress_;
  std::array<double, 3> origin_{};
  std::vector<Vec3f> positions_;
  std::vector<Vec3f> colors_;  // raw values, while every vertex so far may have one
  std::size_t colored_count_ = 0;
  double max_color_ = 0;
  std::vector<Vec3f> normals_;
  std::vector<ply::Triangle> triangles_;
  std::vector<Vec3f> normal_sum_;
  bool has_normal_refs_ = false;
  ForwardReference forward_vertex_, forward_normal_;
  std::vector<DeferredNormal> deferred_normals_;
};

// Vertices without a normal take the area-weighted normal of their faces (the cross product of
// two edges is twice the triangle's area along its normal).
void fill_from_faces(std::vector<Vec3f>& normals, const std::vector<Vec3f>& positions,
                     const std::vector<ply::Triangle>& triangles) {
  std::vector<bool> missing(normals.size());
  bool any_missing = false;
  for (std::size_t i = 0; i < normals.size(); ++i) {
    missing[i] = !(length_squared(normals[i]) > 0.0f) || !is_finite(normals[i]);
    any_missing = any_missing || missing[i];
  }
  if (!any_missing) return;
  for (std::size_t i = 0; i < normals.size(); ++i)
    if (missing[i]) normals[i] = {};
  for (const auto& t : triangles) {
    if (!missing[t[0]] && !missing[t[1]] && !missing[t[2]]) continue;
    const Vec3f n = cross(positions[t[1]] - positions[t[0]], positions[t[2]] - positions[t[0]]);
    for (const std::uint32_t v : t)
      if (missing[v]) normals[v] += n;
  }
}

PointSet ObjParser::finish() {
  const std::size_t n = positions_.size();
  const char* end = data_.data() + data_.size();
  if (n == 0) fail(end, "no vertices (expected 'v x y z' lines); is this an OBJ file?");
  if (forward_vertex_.index > static_cast<std::int64_t>(n))
    fail(forward_vertex_.token, "f: vertex index " + std::to_string(forward_vertex_.index) +
                                    " out of range (the file has " + std::to_string(n) +
                                    " vertices)");
  if (forward_normal_.index > static_cast<std::int64_t>(normals_.size()))
    fail(forward_normal_.token, "f: normal index " + std::to_string(forward_normal_.index) +
                                    " out of range (the file has " +
                                    std::to_string(normals_.size()) + " vn lines)");
  PointSet points;
  if (has_normal_refs_) {
    normal_sum_.resize(n);
    for (const DeferredNormal& d : deferred_normals_) normal_sum_[d.vertex] += normals_[d.normal];
  }
  points.positions = std::move(positions_);
  points.triangles = std::move(triangles_);
  if (has_normal_refs_) {
    fill_from_faces(normal_sum_, points.positions, points.triangles);
    points.normals = std::move(normal_sum_);
    for (Vec3f& normal : points.normals) normal = normalized(normal);
  }
  if (colored_count_ == n) {
    const ply::ColorScale scale = max_color_ > 1.0 ? ply::ColorScale::Byte : ply::ColorScale::Unit;
    points.colors.resize(n);
    for (std::size_t i = 0; i < n; ++i)
      points.colors[i] = {ply::to_color(colors_[i].x, scale), ply::to_color(colors_[i].y, scale),
                          ply::to_color(colors_[i].z, scale)};
  } else if (colored_count_ > 0) {
    points.comments.push_back("vertex colors ignored: only " + std::to_string(colored_count_) +
                              " of " + std::to_string(n) + " vertices have them");
  }
  if (origin_[0] != 0 || origin_[1] != 0 || origin_[2] != 0)
    points.origin = origin_;
  return points;
}

}  // namespace

PointSet read_obj(const std::string& path, Progress& progress, const ObjReadOptions& options) {
  FileBytes raw = FileBytes::map(path);
  const std::uint64_t file_size = raw.file_size();
  ReadProgress read_progress(progress, file_size);
  FileBytes bytes = inflate_if_gzipped(std::move(raw), path, read_progress);
  const bool gzip = bytes.was_compressed();
  read_progress.begin_part(file_size - (gzip ? file_size / 2 : 0), bytes.view().size());
  ObjParser parser(path, bytes.view(), options, read_progress);
  PointSet points = parser.parse();
  read_progress.finish();
  return points;
}

}  // namespace pointillist
