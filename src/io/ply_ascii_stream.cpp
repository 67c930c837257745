// ASCII PLY files (plain or gzip) streamed a window of lines at a time: the vertex lines, or
// the face lines (a FaceStream), parsed by the whole-file reader's own parser
// (parse_ascii_lines), so the points, the triangles and the messages for bad values (file line
// numbers included) are read_ply's. Lines of the elements before the one read are skipped.
#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "decimal_scan.hpp"
#include "line_window.hpp"
#include "ply_body.hpp"
#include "pointillist/core/error.hpp"
#include "streams.hpp"

namespace pointillist::io_detail {
namespace {

using namespace ply;

bool blank_line(const char* s, const char* e) {
  for (; s < e; ++s) {
    if (*s != ' ' && *s != '\t' && *s != '\r') return false;
  }
  return true;
}

std::string_view trimmed(const char* s, const char* e) {
  while (s < e && (*s == ' ' || *s == '\t')) ++s;
  while (e > s && (e[-1] == ' ' || e[-1] == '\t' || e[-1] == '\r')) --e;
  return {s, std::size_t(e - s)};
}

// Vertex lines parsed at a time (a few MB of text).
constexpr std::uint64_t kWindowLines = 1 << 17;

// Element lines before element `element` (elements without properties have none).
std::uint64_t lines_before(const Header& header, std::size_t element) {
  std::uint64_t skip = 0;
  for (std::size_t e = 0; e < element; ++e) {
    if (!header.elements[e].properties.empty()) skip += header.elements[e].count;
  }
  return skip;
}

// Moves `lines` past the header and `skip` element lines; returns the file lines consumed.
std::uint64_t position_after(LineWindow& lines, const std::string& path, std::uint64_t skip,
                             const char* what) {
  lines.rewind();
  std::uint64_t line_no = 0;
  const char *s = nullptr, *e = nullptr;
  for (;;) {  // the header, through its end_header line
    if (!lines.next_line(s, e)) {
      throw FormatError(path + ": line " + std::to_string(line_no + 1) +
                        ": the file ends in its header (no end_header line); the file is "
                        "truncated");
    }
    ++line_no;
    if (trimmed(s, e) == "end_header") break;
  }
  for (std::uint64_t k = 0; k < skip;) {  // lines of the elements before
    if (!lines.next_line(s, e)) {
      throw FormatError(path + ": line " + std::to_string(line_no + 1) + ": file ends early: " +
                        std::to_string(k) + " of the " + std::to_string(skip) +
                        " element lines before the " + what + "; the file is truncated");
    }
    ++line_no;
    if (!blank_line(s, e)) ++k;
  }
  return line_no;
}

// Appends the next `n` element lines (blank ones kept, but not counted) to `text`; the window
// ends early only at the end of the file. Returns how many it found.
std::uint64_t take_lines(LineWindow& lines, std::uint64_t n, std::string& text,
                         std::uint64_t& line_no) {
  std::uint64_t got = 0;
  while (got < n) {
    const char *s = nullptr, *e = nullptr;
    if (!lines.next_line(s, e)) break;
    text.append(s, e);
    text.push_back('\n');
    ++line_no;
    if (!blank_line(s, e)) ++got;
  }
  return got;
}

class AsciiPlyStream final : public PointStream {
 public:
  AsciiPlyStream(const std::string& path, const Header& header, std::size_t vertex,
                 const ElementPlan& plan, const ColorScale* scales, PointStreamInfo info)
      : lines_(path) {
    info_ = std::move(info);
    skip_ = lines_before(header, vertex);
    window_header_.format = header.format;
    window_header_.elements = {header.elements[vertex]};
    window_header_.body_offset = 0;
    ctx_.path = path;
    ctx_.header = &window_header_;
    ctx_.plans = {plan};
    std::copy_n(scales, 3, ctx_.vertex.color_scale);
    rewind();          // finds the first vertex line (and fails now on a short file)
    lines_.release();  // the window and the file are held only while reading
    positioned_ = false;
  }

  std::size_t read(PointSet& batch, std::size_t max) override {
    if (!positioned_) rewind();
    const std::uint64_t n =
        std::min<std::uint64_t>({max, info_.point_count - next_, kWindowLines});
    size_batch(batch, static_cast<std::size_t>(n), info_);
    if (n == 0) {
      lines_.release();
      return 0;
    }
    text_.clear();
    const std::uint64_t first_line = line_no_;
    window_header_.elements[0].count = n;
    ctx_.line_base = first_line;
    ctx_.index_base = next_;
    ctx_.index_total = info_.point_count;
    ctx_.vertex_count = n;
    if (const std::uint64_t got = take_lines(lines_, n, text_, line_no_); got < n) {
      ctx_.data = text_;
      fail_ascii_ends_early(ctx_, got);
    }
    ctx_.data = text_;
    ctx_.vertex.positions = batch.positions.data();
    ctx_.vertex.normals = info_.has_normals ? batch.normals.data() : nullptr;
    ctx_.vertex.colors = info_.has_colors ? batch.colors.data() : nullptr;
    ctx_.vertex.radii = info_.has_radii ? batch.radii.data() : nullptr;
    parse_ascii_lines(ctx_, text_.data(), text_.data() + text_.size(), 0);
    if (info_.has_normals && normalize_normals_window(batch.normals)) usable_normals_ = true;
    next_ += n;
    if (next_ == info_.point_count) lines_.release();
    return static_cast<std::size_t>(n);
  }

  void rewind() override {
    line_no_ = position_after(lines_, info_.path, skip_, "vertices");
    next_ = 0;
    positioned_ = true;
  }

  std::uint64_t bytes_done() const override { return lines_.bytes_done(); }
  bool saw_usable_normals() const override { return usable_normals_; }

 private:
  LineWindow lines_;
  Header window_header_;
  BodyContext ctx_;
  std::uint64_t skip_ = 0;     // element lines before the vertex lines
  std::uint64_t line_no_ = 0;  // file lines consumed
  std::uint64_t next_ = 0;     // vertices read
  bool positioned_ = false;
  bool usable_normals_ = false;
  std::string text_;
};

class AsciiPlyFaceStream final : public FaceStream {
 public:
  AsciiPlyFaceStream(const std::string& path, const Header& header, std::size_t face,
                     const ElementPlan& plan, std::uint64_t vertex_count)
      : lines_(path), path_(path) {
    vertex_count_ = vertex_count;
    face_count_ = header.elements[face].count;
    window_header_.format = header.format;
    window_header_.elements = {header.elements[face]};
    window_header_.body_offset = 0;
    ctx_.path = path;
    ctx_.header = &window_header_;
    ctx_.plans = {plan};
    ctx_.vertex_count = vertex_count;
    ctx_.index_total = face_count_;
    line_no_ = position_after(lines_, path, lines_before(header, face), "faces");
  }

  bool read(std::vector<std::array<std::uint32_t, 3>>& triangles) override {
    triangles.clear();
    if (next_ == face_count_) {
      lines_.release();
      return false;
    }
    const std::uint64_t n = std::min<std::uint64_t>(face_count_ - next_, kWindowLines);
    text_.clear();
    window_header_.elements[0].count = n;
    ctx_.line_base = line_no_;
    ctx_.index_base = next_;
    if (const std::uint64_t got = take_lines(lines_, n, text_, line_no_); got < n) {
      ctx_.data = text_;
      fail_ascii_ends_early(ctx_, got);
    }
    ctx_.data = text_;
    parse_ascii_lines(ctx_, text_.data(), text_.data() + text_.size(), 0, &triangles);
    next_ += n;
    return true;
  }
  std::uint64_t faces_done() const override { return next_; }

 private:
  LineWindow lines_;
  std::string path_;
  Header window_header_;
  BodyContext ctx_;
  std::uint64_t line_no_ = 0, next_ = 0;
  std::string text_;
};

}  // namespace

std::unique_ptr<FaceStream> open_ascii_face_stream(const std::string& path, const Header& header,
                                                   std::size_t face, const ElementPlan& plan,
                                                   std::uint64_t vertex_count) {
  return std::make_unique<AsciiPlyFaceStream>(path, header, face, plan, vertex_count);
}

std::unique_ptr<PointStream> open_ascii_vertex_stream(const std::string& path,
                                                      const Header& header, std::size_t vertex,
                                                      const ElementPlan& plan,
                                                      const ColorScale* scales,
                                                      PointStreamInfo info) {
  return std::make_unique<AsciiPlyStream>(path, header, vertex, plan, scales, std::move(info));
}

}  // namespace pointillist::io_detail
