// The lines of text point files (XYZ, PTS, CSV, TXT), shared by read_xyz and the streamed
// reader: the preamble (header, PTS count, comments), one point line's values, the statistics
// that tell a group of three values as normals or colors. Internal to io.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "ply_body.hpp"
#include "text_numbers.hpp"
#include "xyz_layout.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/core/point_set.hpp"
#include "pointillist/io/xyz.hpp"

namespace pointillist::xyz_detail {

using namespace io_detail;

// What a group's values looked like over the file, to tell normals from colors and a color
// scale from another.
struct GroupStats {
  float min = std::numeric_limits<float>::infinity();
  float max = -std::numeric_limits<float>::infinity();
  bool has_point = false;  // some token has a decimal point or an exponent
  bool all_unit = true;    // every row has length 1 (within 10%)

  void merge(const GroupStats& o) {
    min = std::min(min, o.min);
    max = std::max(max, o.max);
    has_point = has_point || o.has_point;
    all_unit = all_unit && o.all_unit;
  }
};

inline Group classify(const GroupStats& s) {
  if (s.min < 0.0f) return Group::Normals;
  if (s.all_unit && s.has_point) return Group::Normals;
  return Group::Colors;
}

inline ply::ColorScale color_scale(const GroupStats& s) {
  if (s.max > 255.0f) return ply::ColorScale::Word;
  if (s.max <= 1.0f && s.has_point) return ply::ColorScale::Unit;
  return ply::ColorScale::Byte;
}

struct LineValues {
  double xyz[3] = {};
  float group[2][3] = {};
};

struct Outputs {
  Vec3f* positions = nullptr;
  Vec3f* group[2] = {nullptr, nullptr};
};

inline bool is_comment_start(const char* t, const char* le) {
  return *t == '#' || (*t == '/' && t + 1 < le && t[1] == '/');
}

// A line that holds a point: anything but blanks and comments.
inline bool is_point_line(const char* t, const char* le) { return t < le && !is_comment_start(t, le); }

inline std::uint64_t count_point_lines(const char* begin, const char* end) {
  std::uint64_t count = 0;
  for (const char* p = begin; p < end;) {
    const char* le = line_end(p, end);
    count += is_point_line(skip_blanks(p, le), le);
    p = le + 1;
  }
  return count;
}

class LineParser {
 public:
  LineParser(const std::string& path, std::string_view data, const Layout& layout,
             Delimiter delimiter, std::size_t first_line, std::size_t first_count)
      : path_(path),
        data_(data),
        layout_(layout),
        delimiter_(delimiter),
        first_line_(first_line),
        first_count_(first_count) {}

  // Lines are then parsed from `data`, a window of the file that starts at a line start after
  // `lines_before` lines (for the line numbers in messages).
  void set_window(std::string_view data, std::size_t lines_before) {
    data_ = data;
    lines_before_ = lines_before;
  }

  // Parses the point line whose first non-blank character is `t` and which ends at `le`.
  void parse(const char* t, const char* le, LineValues& v, GroupStats stats[2]) const {
    const std::size_t n = layout_.slots.size();
    const char* p = t;
    for (std::size_t c = 0; c < n; ++c) {
      if (c > 0) p = next_field(p, le, c);
      const Slot slot = layout_.slots[c];
      if (slot == kSkip) {
        p = skip_field(p, le);
        continue;
      }
      if (slot <= kZ) {
        double d = 0;
        const char* q = parse_real(p, le, d);
        if (!q) fail_number(p, le, c);
        if (!std::isfinite(d)) fail_not_finite(p, le, c);
        v.xyz[slot] = d;
        p = q;
        continue;
      }
      const int g = slot >= kB0;
      float f = 0;
      const char* q = parse_real(p, le, f);
      if (!q) fail_number(p, le, c);
      for (const char* s = p; s < q; ++s)
        if (*s == '.' || *s == 'e' || *s == 'E') stats[g].has_point = true;
      v.group[g][slot - (g ? kB0 : kA0)] = f;
      p = q;
    }
    for (int g = 0; g < 2; ++g) {
      if ((g ? layout_.b : layout_.a) == Group::None) continue;
      const float* values = v.group[g];
      for (int k = 0; k < 3; ++k) {
        stats[g].min = std::min(stats[g].min, values[k]);
        stats[g].max = std::max(stats[g].max, values[k]);
      }
      const float length2 = values[0] * values[0] + values[1] * values[1] + values[2] * values[2];
      if (!(length2 >= 0.81f && length2 <= 1.21f)) stats[g].all_unit = false;
    }
    p = skip_blanks(p, le);
    if (p < le && delimiter_ != Delimiter::Blank && *p == char(delimiter_)) {
      // A delimiter at the end of the line (some CSV writers add one) or before more fields.
      const char* after = skip_blanks(p + 1, le);
      if (after == le) return;
      p = after;
    }
    if (p < le && layout_.exact) fail_extra(p, le);
  }

  std::size_t column_count() const { return layout_.slots.size(); }

 // Fails naming the line when a coordinate less the origin is beyond what a float holds.
 void check_fits_float(const char* line, const double (&xyz)[3],
                       const std::array<double, 3>& origin) const {
   if (const int a = io_detail::axis_beyond_float(xyz, origin); a >= 0) {
     fail(line, std::string(1, "xyz"[a]) + " = " + io_detail::short_number(xyz[a]) +
                    " is too far from the other points for a float coordinate (more than "
                    "3.4e38 from " + io_detail::short_number(origin[a]) +
                    "); remove the stray point");
   }
 }

 private:
  // Moves from the end of field c-1 to the start of field c.
  const char* next_field(const char* p, const char* le, std::size_t c) const {
    if (delimiter_ == Delimiter::Blank) {
      const char* q = skip_blanks(p, le);
      if (q == le) fail_short(q, c);
      if (q == p) fail_expected_delimiter(p, le);
      return q;
    }
    p = skip_blanks(p, le);
    if (p == le) fail_short(p, c);
    if (*p != char(delimiter_)) fail_expected_delimiter(p, le);
    const char* q = skip_blanks(p + 1, le);
    if (q == le) fail_short(q, c);
    if (*q == char(delimiter_))
      fail(q, "column " + std::to_string(c + 1) + " is empty (found '" +
                  std::string(1, char(delimiter_)) + "' right after the previous one)");
    return q;
  }

  const char* skip_field(const char* p, const char* le) const {
    if (delimiter_ == Delimiter::Blank) {
      while (p < le && !is_blank(*p)) ++p;
      return p;
    }
    while (p < le && *p != char(delimiter_)) ++p;
    return p;
  }

  std::string column_name(std::size_t c) const {
    static const char* kNames[] = {"x", "y", "z"};
    const Slot slot = layout_.slots[c];
    std::string name = "column " + std::to_string(c + 1);
    if (slot >= kX && slot <= kZ) name += std::string(" (") + kNames[slot] + ")";
    return name;
  }

  std::string layout_text() const {
    return std::to_string(column_count()) + (layout_.exact ? "" : " or more") + " values";
  }

  [[noreturn, gnu::cold]] void fail(const char* pos, const std::string& what) const {
    throw FormatError(path_ + ": line " + std::to_string(lines_before_ + line_number(data_, pos)) +
                      ": " + what);
  }
  [[noreturn, gnu::cold]] void fail_number(const char* p, const char* le, std::size_t c) const {
    fail(p, column_name(c) + ": expected a number, found " + quote_token(p, le) +
                (c < 3 ? "" : " (give the columns option and name this column 'skip' to ignore it)"));
  }
  [[noreturn, gnu::cold]] void fail_not_finite(const char* p, const char* le,
                                               std::size_t c) const {
    fail(p, column_name(c) + " is not a finite number (found " + quote_token(p, le) + ")");
  }
  [[noreturn, gnu::cold]] void fail_short(const char* p, std::size_t found) const {
    fail(p, "line ends early: expected " + layout_text() + ", found " + std::to_string(found) +
                (layout_.exact ? " (the first point line, line " + std::to_string(first_line_) +
                                     ", has " + std::to_string(first_count_) + ")"
                               : ""));
  }
  [[noreturn, gnu::cold]] void fail_extra(const char* p, const char* le) const {
    fail(p, "extra value " + quote_token(p, le) + ": expected " + layout_text() +
                " as on the first point line (line " + std::to_string(first_line_) +
                "); fix the line, or give the columns option to read a fixed set of columns");
  }
  [[noreturn, gnu::cold]] void fail_expected_delimiter(const char* p, const char* le) const {
    const std::string expected = delimiter_ == Delimiter::Blank
                                     ? "a blank"
                                     : "'" + std::string(1, char(delimiter_)) + "'";
    fail(p, "expected " + expected + " between values (the delimiter of the first point line), found " +
                quote_token(p, le));
  }

  const std::string& path_;
  std::string_view data_;
  const Layout& layout_;
  Delimiter delimiter_;
  std::size_t first_line_, first_count_;
  std::size_t lines_before_ = 0;
};

// Values on the first point line [t, le) (a trailing delimiter is not a value).
inline std::size_t count_fields(const char* t, const char* le, Delimiter delimiter) {
  std::size_t count = 0;
  if (delimiter == Delimiter::Blank) {
    for (const char* p = t; p < le;) {
      p = skip_blanks(p, le);
      if (p == le) break;
      ++count;
      while (p < le && !is_blank(*p)) ++p;
    }
    return count;
  }
  count = 1 + static_cast<std::size_t>(std::count(t, le, char(delimiter)));
  const char* last = le;
  while (last > t && is_blank(last[-1])) --last;
  if (last > t && last[-1] == char(delimiter)) --count;
  return count;
}

struct Preamble {
  const char* body = nullptr;  // start of the first point line
  std::size_t first_line = 0;  // its line number
  std::size_t first_count = 0;  // values on it
  Delimiter delimiter = Delimiter::Blank;
  Layout layout;
  std::string layout_source;
};

// Reads the lines before the first point line: header names, the PTS count line, comments.
inline Preamble read_preamble(const std::string& path, std::string_view data,
                       const XyzReadOptions& options) {
  const char* end = data.data() + data.size();
  std::optional<Layout> header_layout;
  std::size_t header_line = 0;
  bool count_line_seen = false;
  std::size_t line = 0;
  constexpr std::size_t kMaxPreambleLines = 1000;
  for (const char* p = data.data(); p < end; p = line_end(p, end) + 1) {
    ++line;
    const char* le = line_end(p, end);
    const char* t = skip_blanks(p, le);
    if (t == le) continue;
    if (line > kMaxPreambleLines)
      throw FormatError(path + ": line " + std::to_string(line) + ": no point line in the first " +
                        std::to_string(kMaxPreambleLines) +
                        " lines (expected lines of numbers x y z ...); is this a point text file?");
    const bool comment = is_comment_start(t, le);
    double first = 0;
    const char* q = comment ? nullptr : parse_real(t, le, first);
    if (!q) {
      // A header (or a comment) line; column names in it are used when they include x, y, z.
      std::string_view text(t, static_cast<std::size_t>(le - t));
      while (!text.empty() && (text.front() == '#' || text.front() == '/')) text.remove_prefix(1);
      if (auto layout = layout_from_names(split_names(text), false, std::string(text))) {
        header_layout = std::move(layout);
        header_line = line;
      }
      continue;
    }
    std::int64_t count = 0;
    if (!count_line_seen && parse_index(t, le, count) && skip_blanks(q, le) == le) {
      count_line_seen = true;  // a PTS point count: not checked, the lines are what counts
      continue;
    }
    Preamble pre;
    pre.body = p;
    pre.first_line = line;
    pre.delimiter = std::find(t, le, ';') != le   ? Delimiter::Semicolon
                    : std::find(t, le, ',') != le ? Delimiter::Comma
                                                  : Delimiter::Blank;
    pre.first_count = count_fields(t, le, pre.delimiter);
    if (!options.columns.empty()) {
      pre.layout = *layout_from_names(split_names(options.columns), true, options.columns);
      pre.layout_source = "the columns option";
    } else if (header_layout) {
      pre.layout = *header_layout;
      pre.layout_source = "the header on line " + std::to_string(header_line);
    } else {
      if (pre.first_count < 3)
        throw FormatError(path + ": line " + std::to_string(line) +
                          ": a point line needs at least 3 values (x y z), found " +
                          std::to_string(pre.first_count));
      pre.layout = layout_from_count(pre.first_count);
      pre.layout_source = "the " + std::to_string(pre.first_count) + " values on line " +
                          std::to_string(line);
    }
    if (!options.read_colors) {
      for (Slot& s : pre.layout.slots)
        if (s >= kB0) s = kSkip;
      pre.layout.b = Group::None;
    }
    return pre;
  }
  throw FormatError(path + ": line " + std::to_string(std::max<std::size_t>(line, 1)) +
                    ": no point lines (expected lines of numbers: x y z, optionally followed by "
                    "normals and colors)");
}

inline std::string columns_text(const Layout& layout, std::size_t first_count) {
  std::string text;
  static const char* kGroupNames[2][3] = {{"nx", "ny", "nz"}, {"r", "g", "b"}};
  for (const Slot s : layout.slots) {
    if (!text.empty()) text += ' ';
    if (s == kSkip) {
      text += "skip";
    } else if (s <= kZ) {
      text += "xyz"[s];
    } else {
      const int g = s >= kB0;
      const Group kind = g ? layout.b : layout.a;
      text += kGroupNames[kind == Group::Colors][s - (g ? kB0 : kA0)];
    }
  }
  if (first_count > layout.slots.size())
    text += " (" + std::to_string(first_count - layout.slots.size()) + " more ignored)";
  return text;
}

// Turns a parsed group into normals or colors in `points`.
inline void store_group(Group kind, const GroupStats& stats, std::vector<Vec3f>& values,
                 PointSet& points, bool read_colors) {
  if (kind == Group::Normals) {
    points.normals = std::move(values);
    finish_normals(points.normals);
  } else if (kind == Group::Colors && read_colors) {
    const ply::ColorScale scale = color_scale(stats);
    points.colors.resize(values.size());
    for (std::size_t i = 0; i < values.size(); ++i)
      points.colors[i] = {ply::to_color(values[i].x, scale), ply::to_color(values[i].y, scale),
                          ply::to_color(values[i].z, scale)};
  }
  values.clear();
  values.shrink_to_fit();
}


// The groups' kinds once every line's statistics are in: Detect becomes normals or colors.
inline void resolve_groups(Layout& layout, const GroupStats stats[2]) {
  if (layout.a == Group::Detect && layout.b == Group::Detect) {
    layout.a = classify(stats[0]);
    layout.b = classify(stats[1]);
    if (layout.a == layout.b) {  // both look alike: the usual order
      layout.a = Group::Normals;
      layout.b = Group::Colors;
    }
  } else {
    if (layout.a == Group::Detect) layout.a = classify(stats[0]);
    if (layout.b == Group::Detect) layout.b = classify(stats[1]);
  }
}

}  // namespace pointillist::xyz_detail
