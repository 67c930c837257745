// Text point files (XYZ, PTS, CSV, TXT; gzip too) streamed a window of lines at a time: what
// read_xyz returns, in constant memory. Opening reads the preamble and counts the point lines in
// one pass (parsing them too when a group of three values must be told as normals or colours,
// or a colour scale found, over the whole file); each read parses the next lines.
#include <zlib.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <optional>

#include "decimal_scan.hpp"
#include "streams.hpp"
#include "line_window.hpp"
#include "xyz_lines.hpp"

namespace pointillist::io_detail {
namespace {

using namespace xyz_detail;

// The preamble (header, PTS count, comments) must lie in the file's first bytes.
constexpr std::size_t kPreambleBytes = std::size_t{16} << 20;


class XyzStream final : public PointStream {
 public:
  XyzStream(const std::string& path, const PointReadOptions& options)
      : path_(path), window_(path), read_colors_(options.read_colors) {
    XyzReadOptions xo{.read_colors = options.read_colors, .columns = options.columns};
    if (!options.columns.empty()) {
      layout_from_names(split_names(options.columns), true, options.columns);
    }
    const std::string head = window_.prefix(kPreambleBytes);
    if (head.empty()) {
      throw FormatError(path + ": line 1: file is empty (expected lines x y z ...)");
    }
    pre_ = read_preamble(path, head, xo);
    body_offset_ = std::size_t(pre_.body - head.data());
    parser_.emplace(path_, head, pre_.layout, pre_.delimiter, pre_.first_line,
                    pre_.first_count);
    {
      const char* le = line_end(pre_.body, head.data() + head.size());
      LineValues first;
      GroupStats unused[2];
      parser_->parse(skip_blanks(pre_.body, le), le, first, unused);
      origin_ = text_origin(first.xyz);
    }

    // The count, and the groups' statistics when the kinds or the colour scale need them.
    const Layout& layout = pre_.layout;
    const bool need_stats = layout.a != Group::None || layout.b != Group::None;
    GroupStats stats[2];
    std::uint64_t count = 0;
    start_body();
    const char* t;
    const char* le;
    while (next_point_line(t, le)) {
      ++count;
      if (need_stats) {
        LineValues v;
        parser_->parse(t, le, v, stats);
      }
    }
    resolve_groups(pre_.layout, stats);
    for (int g = 0; g < 2; ++g) {
      kind_[g] = g ? pre_.layout.b : pre_.layout.a;
      if (kind_[g] == Group::Colors) scale_[g] = color_scale(stats[g]);
      if (kind_[g] == Group::Colors && !read_colors_) {  // as read_xyz reports them
        for (Slot& s : pre_.layout.slots) {
          if (s >= (g ? kB0 : kA0) && s < (g ? kB0 + 3 : kA0 + 3)) s = kSkip;
        }
      }
    }
    info_.path = path;
    info_.point_count = count;
    info_.has_normals = kind_[0] == Group::Normals || kind_[1] == Group::Normals;
    info_.has_colors = read_colors_ && (kind_[0] == Group::Colors || kind_[1] == Group::Colors);
    info_.file_size = std::filesystem::file_size(path);
    info_.origin = origin_;
    info_.comments.push_back("columns: " + columns_text(pre_.layout, pre_.first_count) +
                             " (from " + pre_.layout_source + ")");
    window_.release();
    pending_start_ = true;
  }

  std::size_t read(PointSet& batch, std::size_t max) override {
    batch.positions.clear();
    batch.normals.clear();
    batch.colors.clear();
    batch.radii.clear();
    batch.triangles.clear();
    batch.comments.clear();
    if (pending_start_) start_body();
    pending_start_ = false;
    GroupStats unused[2];
    const char* t;
    const char* le;
    std::size_t n = 0;
    while (n < max && next_point_line(t, le)) {
      LineValues v;
      parser_->parse(t, le, v, unused);
      parser_->check_fits_float(t, v.xyz, origin_);
      batch.positions.push_back({static_cast<float>(v.xyz[0] - origin_[0]),
                                 static_cast<float>(v.xyz[1] - origin_[1]),
                                 static_cast<float>(v.xyz[2] - origin_[2])});
      for (int g = 0; g < 2; ++g) {
        const float* x = v.group[g];
        if (kind_[g] == Group::Normals) {
          batch.normals.push_back({x[0], x[1], x[2]});
        } else if (kind_[g] == Group::Colors && read_colors_) {
          batch.colors.push_back({ply::to_color(x[0], scale_[g]), ply::to_color(x[1], scale_[g]),
                                  ply::to_color(x[2], scale_[g])});
        }
      }
      ++n;
    }
    if (normalize_normals_window(batch.normals)) usable_normals_ = true;
    if (n < max) window_.release();  // the end: free the window until a rewind
    return n;
  }
  void rewind() override { pending_start_ = true; }
  std::uint64_t bytes_done() const override { return pending_start_ ? 0 : window_.bytes_done(); }
  bool saw_usable_normals() const override { return usable_normals_; }

 private:
  // Positions the window at the first point line.
  void start_body() {
    window_.rewind();
    std::size_t skipped = 0;
    const char* t;
    const char* le;
    while (skipped < body_offset_ && window_.next_line(t, le)) {
      skipped += std::size_t(le - t) + 1;
    }
  }
  // The next point line: its first non-blank character and its end.
  bool next_point_line(const char*& t, const char*& le) {
    const char* start;
    while (window_.next_line(start, le)) {
      t = skip_blanks(start, le);
      if (!is_point_line(t, le)) continue;
      const std::string_view w = window_.window();
      if (w.data() != window_data_ || w.size() != window_size_ ||
          window_.lines_before() != window_lines_) {
        parser_->set_window(w, window_.lines_before());
        window_data_ = w.data();
        window_size_ = w.size();
        window_lines_ = window_.lines_before();
      }
      return true;
    }
    return false;
  }

  std::string path_;  // before window_ and parser_, which use it
  LineWindow window_;
  bool read_colors_;
  Preamble pre_;
  std::size_t body_offset_ = 0;
  std::optional<LineParser> parser_;
  std::array<double, 3> origin_{};
  Group kind_[2] = {Group::None, Group::None};
  ply::ColorScale scale_[2] = {ply::ColorScale::Byte, ply::ColorScale::Byte};
  bool usable_normals_ = false;
  bool pending_start_ = true;  // the window goes to the first point line at the next read
  const char* window_data_ = nullptr;
  std::size_t window_size_ = 0, window_lines_ = 0;
};

}  // namespace

std::unique_ptr<PointStream> open_xyz_stream(const std::string& path,
                                             const PointReadOptions& options) {
  return std::make_unique<XyzStream>(path, options);
}

}  // namespace pointillist::io_detail
