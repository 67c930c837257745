// ASCII PLY files (plain or gzip) streamed a window of lines at a time: the vertex lines parsed
// by the whole-file reader's own parser (parse_ascii_lines), so the points and the messages for
// bad values (file line numbers included) are read_ply's. Lines of elements before the vertex
// element are skipped; faces after it are not read (the stream says the file is a mesh).
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

class AsciiPlyStream final : public PointStream {
 public:
  AsciiPlyStream(const std::string& path, const Header& header, std::size_t vertex,
                 const ElementPlan& plan, const ColorScale* scales, PointStreamInfo info)
      : lines_(path) {
    info_ = std::move(info);
    for (std::size_t e = 0; e < vertex; ++e) {
      if (!header.elements[e].properties.empty()) skip_ += header.elements[e].count;
    }
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
    for (std::uint64_t got = 0; got < n;) {
      const char *s = nullptr, *e = nullptr;
      if (!lines_.next_line(s, e)) {
        ctx_.data = text_;
        fail_ascii_ends_early(ctx_, got);
      }
      text_.append(s, e);
      text_.push_back('\n');
      ++line_no_;
      if (!blank_line(s, e)) ++got;
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
    lines_.rewind();
    line_no_ = 0;
    next_ = 0;
    const char *s = nullptr, *e = nullptr;
    for (;;) {  // the header, through its end_header line
      if (!lines_.next_line(s, e)) {
        throw FormatError(info_.path + ": line " + std::to_string(line_no_ + 1) +
                          ": the file ends in its header (no end_header line); the file is "
                          "truncated");
      }
      ++line_no_;
      if (trimmed(s, e) == "end_header") break;
    }
    for (std::uint64_t k = 0; k < skip_;) {  // lines of the elements before the vertices
      if (!lines_.next_line(s, e)) {
        throw FormatError(info_.path + ": line " + std::to_string(line_no_ + 1) +
                          ": file ends early: " + std::to_string(k) + " of the " +
                          std::to_string(skip_) +
                          " element lines before the vertices; the file is truncated");
      }
      ++line_no_;
      if (!blank_line(s, e)) ++k;
    }
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

}  // namespace

std::unique_ptr<PointStream> open_ascii_vertex_stream(const std::string& path,
                                                      const Header& header, std::size_t vertex,
                                                      const ElementPlan& plan,
                                                      const ColorScale* scales,
                                                      PointStreamInfo info) {
  return std::make_unique<AsciiPlyStream>(path, header, vertex, plan, scales, std::move(info));
}

}  // namespace pointillist::io_detail
