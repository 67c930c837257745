// Helpers shared by the text readers (XYZ/PTS/CSV, OBJ) and the LAS reader (private to the io
// module): fast number tokens over an in-memory buffer, line positions for messages, the
// coordinate origin that keeps float positions precise, normal clean-up and progress.
//
// The number fast paths are the ones of the ascii PLY decoder (ply_ascii.cpp), generalized so a
// token may also end at ',' or ';' (CSV files): a plain decimal token is converted with one
// correctly rounded operation (Clinger's fast path, equal to std::from_chars), anything unusual
// falls back to std::from_chars, which either parses it or reports failure to the caller.
#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <functional>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "decimal_scan.hpp"
#include "pointillist/core/file_bytes.hpp"
#include "pointillist/core/math.hpp"
#include "pointillist/core/progress.hpp"

namespace pointillist::io_detail {

// A number for a message: "1e+39", "0.5".
inline std::string short_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

// Characters -----------------------------------------------------------------------------------

inline bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r'; }
// A number token ends at a blank, the end of the line, or a CSV delimiter.
inline bool ends_number_at(const char* q, const char* end) {
  return q == end || is_blank(*q) || *q == '\n' || *q == ',' || *q == ';';
}

inline const char* skip_blanks(const char* p, const char* end) {
  while (p < end && is_blank(*p)) ++p;
  return p;
}

// The end of the line holding `p` (its '\n', or `end`).
inline const char* line_end(const char* p, const char* end) {
  const void* nl = std::memchr(p, '\n', static_cast<std::size_t>(end - p));
  return nl ? static_cast<const char*>(nl) : end;
}

// 1-based line number of `pos` in `data`.
inline std::size_t line_number(std::string_view data, const char* pos) {
  return 1 + static_cast<std::size_t>(std::count(data.data(), pos, '\n'));
}

// The token at `p` quoted for a message ('abc', cut after 40 characters, control characters
// shown as '?'); "end of line" when there is none.
inline std::string quote_token(const char* p, const char* end) {
  if (p == end || *p == '\n') return "end of line";
  const char* q = p;
  while (q < end && !is_blank(*q) && *q != '\n' && q - p < 40) ++q;
  std::string text(p, q);
  for (char& c : text)
    if (static_cast<unsigned char>(c) < 32 || c == 127) c = '?';
  return "'" + text + (q < end && !is_blank(*q) && *q != '\n' ? "...'" : "'");
}

// Numbers --------------------------------------------------------------------------------------


// Parses the number token at `p` (no leading blanks) into `out`. Returns the first character
// after it, or null when the token is not a number or is out of the type's range. Non-finite
// spellings ("inf", "nan") parse; callers that need finite values check.
template <class T>
const char* parse_real(const char* p, const char* end, T& out) {
  static_assert(std::is_same_v<T, float> || std::is_same_v<T, double>);
  Decimal d;
  if (const char* q = scan_decimal(p, end, d, ends_number_at)) {
    constexpr bool is_float = std::is_same_v<T, float>;
    constexpr std::uint64_t kMaxExact = is_float ? (1u << 24) : (std::uint64_t{1} << 53);
    constexpr int kMaxPow = is_float ? 10 : 22;
    constexpr double kPow10[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                 1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
    if (d.mantissa <= kMaxExact && d.exponent >= -kMaxPow && d.exponent <= kMaxPow) {
      T v = static_cast<T>(d.mantissa);
      const T scale = static_cast<T>(kPow10[d.exponent < 0 ? -d.exponent : d.exponent]);
      v = d.exponent < 0 ? v / scale : v * scale;
      out = d.negative ? -v : v;
      return q;
    }
  }
  const char* s = p + (p < end && *p == '+');
  auto [q, ec] = std::from_chars(s, end, out);
  if constexpr (std::is_same_v<T, float>) {
    // Beyond float but not double ("1e-50", "1e300"): the double, rounded to float (0 or inf).
    if (ec == std::errc::result_out_of_range) {
      double wide = 0;
      const auto r = std::from_chars(s, end, wide);
      q = r.ptr;
      ec = r.ec;
      // Converting a double beyond float's range is undefined: take the limit explicitly.
      out = std::fabs(wide) > double(std::numeric_limits<float>::max())
                ? (wide > 0 ? 1.0f : -1.0f) * std::numeric_limits<float>::infinity()
                : static_cast<float>(wide);
    }
  }
  if (ec != std::errc() || !ends_number_at(q, end)) return nullptr;
  return q;
}

// Parses a decimal integer token at `p` (optional sign) that ends at a number end or at '/'
// (OBJ face corners). Returns the first character after it, or null (not an integer, or more
// than 18 digits).
inline const char* parse_index(const char* p, const char* end, std::int64_t& out) {
  return scan_integer(p, end, out, [](const char* q, const char* e) {
    return ends_number_at(q, e) || (q < e && *q == '/');
  });
}

// Shortest text without an exponent that reads back as the same double ("700000", "0.25");
// "7e+05" style only for magnitudes that would take hundreds of digits.
inline std::string format_double(double v) {
  char buffer[128];
  auto r = std::to_chars(buffer, buffer + sizeof buffer, v, std::chars_format::fixed);
  if (r.ec != std::errc()) r = std::to_chars(buffer, buffer + sizeof buffer, v);
  return std::string(buffer, r.ptr);
}

// Coordinate origin ----------------------------------------------------------------------------
//
// PointSet positions are float: 24 significant bits, so a georeferenced coordinate such as a
// UTM northing of 5,400,000 m is stored to 0.5 m. Readers whose files hold large coordinates
// subtract an origin (kept in double) and record it as the comment "origin: X Y Z", so the
// absolute position is origin + position.

// The origin along one axis for coordinates in [lo, hi]: 0 when neither bound reaches `limit`
// (floats there are precise enough), else lo rounded down to a multiple of `grid` (a round
// number a person can read back; the remainder stays below hi - lo + grid).
inline double axis_origin(double lo, double hi, double limit, double grid) {
  if (std::max(std::fabs(lo), std::fabs(hi)) < limit) return 0.0;
  return std::floor(lo / grid) * grid;
}

// The largest power of ten not above `extent` (1 for a zero or non-finite extent).
inline double power_of_ten_below(double extent) {
  if (!(extent > 0.0) || !std::isfinite(extent)) return 1.0;
  return std::pow(10.0, std::floor(std::log10(extent)));
}

inline std::string origin_comment(const std::array<double, 3>& origin) {
  return "origin: " + format_double(origin[0]) + " " + format_double(origin[1]) + " " +
         format_double(origin[2]);
}

// Text readers do not know the extent before parsing: they take the first point, and shift an
// axis when its coordinate has a magnitude of 2^16 or more (float steps of 1/128 and coarser),
// by that coordinate rounded down to a multiple of 1000.
constexpr double kTextOriginLimit = 65536.0;
constexpr double kTextOriginGrid = 1000.0;

inline std::array<double, 3> text_origin(const double first[3]) {
  std::array<double, 3> origin{};
  for (int a = 0; a < 3; ++a)
    origin[a] = axis_origin(first[a], first[a], kTextOriginLimit, kTextOriginGrid);
  return origin;
}

// The first axis (0 to 2) whose coordinate less the origin no float holds (a stray point ~1e39
// away: converting it would be undefined), or -1.
inline int axis_beyond_float(const double xyz[3], const std::array<double, 3>& origin) {
  for (int a = 0; a < 3; ++a) {
    if (!(std::fabs(xyz[a] - origin[a]) <= double(std::numeric_limits<float>::max()))) return a;
  }
  return -1;
}

// Three numbers after `skip` characters of `text` (blank-separated, finite); false otherwise.
inline bool read_triple(const std::string& text, std::size_t skip, std::array<double, 3>& out) {
  const char* p = text.data() + skip;
  const char* end = text.data() + text.size();
  std::array<double, 3> v{};
  for (double& x : v) {
    while (p < end && *p == ' ') ++p;
    const auto r = std::from_chars(p, end, x);
    if (r.ec != std::errc() || !std::isfinite(x)) return false;
    p = r.ptr;
  }
  out = v;
  return true;
}

// Normals --------------------------------------------------------------------------------------


// Progress ------------------------------------------------------------------------------------

// One "read" phase of `total_units` (the file size): parts of the work report bytes of their
// own input, scaled to their share of the units. Safe to call from several threads.
class ReadProgress {
 public:
  ReadProgress(Progress& progress, std::uint64_t total_units)
      : phase_(progress, "read", total_units), total_(total_units) {}
  ReadProgress(const ReadProgress&) = delete;
  ReadProgress& operator=(const ReadProgress&) = delete;

  // The next `units` of the total are earned by processing `bytes` bytes of some input.
  void begin_part(std::uint64_t units, std::uint64_t bytes) {
    part_units_ = std::min(units, total_ - std::min(total_, reported_.load()));
    part_bytes_ = bytes;
    part_done_.store(0);
  }
  // `bytes` more bytes of the current part are processed.
  void advance(std::uint64_t bytes) {
    if (bytes == 0 || part_bytes_ == 0) return;
    const std::uint64_t before = part_done_.fetch_add(bytes);
    const auto units_at = [&](std::uint64_t done) {
      return static_cast<std::uint64_t>(double(std::min(done, part_bytes_)) /
                                        double(part_bytes_) * double(part_units_));
    };
    const std::uint64_t units = units_at(before + bytes) - units_at(before);
    if (units == 0) return;
    reported_.fetch_add(units);
    phase_.advance(units);
  }
  // Reports whatever is left of the total.
  void finish() {
    const std::uint64_t done = reported_.load();
    if (done < total_) phase_.advance(total_ - done);
    reported_.store(total_);
  }

 private:
  ProgressPhase phase_;
  std::uint64_t total_;
  std::atomic<std::uint64_t> reported_{0};
  std::uint64_t part_units_ = 0, part_bytes_ = 0;
  std::atomic<std::uint64_t> part_done_{0};
};

// `raw` (a file mapped from `path`) as is, or inflated when it starts with the gzip magic; the
// inflation earns the first half of `progress` (whose total is the file's size). `limit`: the
// most bytes the file's header allows (GzipInflater::set_limit), or empty.
inline FileBytes inflate_if_gzipped(FileBytes raw, const std::string& path,
                                    ReadProgress& progress,
                                    std::function<std::uint64_t(std::string_view)> limit = {}) {
  if (!has_gzip_magic(raw.view())) return raw;
  const std::uint64_t size = raw.file_size();
  progress.begin_part(size / 2, size);
  return FileBytes::inflate(raw, path, [&](std::uint64_t n) { progress.advance(n); },
                            std::move(limit));
}

}  // namespace pointillist::io_detail
