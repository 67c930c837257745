// Ascii PLY body decoder: std::from_chars on the in-memory text, one element per line. With a
// thread pool, the body is cut into pieces at line starts; a first parallel pass counts the
// element lines of each piece, so every piece knows the index of its first element, and a second
// pass parses the pieces independently (triangles are merged in piece order).
#include <algorithm>
#include <atomic>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>

#include "decimal_scan.hpp"
#include "ply_body.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/core/thread_pool.hpp"

namespace pointillist::ply {
namespace {

using io_detail::Decimal;
using io_detail::is_digit;
using io_detail::scan_decimal;

inline bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r'; }

std::string token_text(const char* p, const char* end) {
  const char* q = p;
  while (q < end && !is_blank(*q) && *q != '\n' && q - p < 40) ++q;
  std::string text(p, q);
  for (char& c : text)
    if (static_cast<unsigned char>(c) < 32 || c == 127) c = '?';
  return "'" + text + (q < end && !is_blank(*q) && *q != '\n' ? "...'" : "'");
}

struct Range {
  std::int64_t lo, hi;
};

inline Range integer_range(ScalarType type) {
  static constexpr Range kRanges[kScalarTypeCount] = {
      {-128, 127},
      {0, 255},
      {-32768, 32767},
      {0, 65535},
      {std::numeric_limits<std::int32_t>::min(), std::numeric_limits<std::int32_t>::max()},
      {0, std::numeric_limits<std::uint32_t>::max()},
      {0, 0},
      {0, 0}};
  return kRanges[static_cast<int>(type)];
}

inline bool ends_token_at(const char* q, const char* end) {
  return q == end || is_blank(*q) || *q == '\n';
}

// Fast paths for plain decimal tokens. They return null for anything unusual (no digits, too
// many digits, a large exponent, "nan", a bad character), and the caller then takes the slow,
// fully checked path, which either parses the token or throws a message naming it.


// Exact when the mantissa and the power of ten are exact in the type: one correctly rounded
// multiplication or division (Clinger's fast path), so the result equals std::from_chars.
inline const char* fast_float(const char* p, const char* end, float& out) {
  constexpr float kPow10[] = {1e0f, 1e1f, 1e2f, 1e3f, 1e4f, 1e5f, 1e6f, 1e7f, 1e8f, 1e9f, 1e10f};
  Decimal d;
  p = scan_decimal(p, end, d, ends_token_at);
  if (!p || d.mantissa > (1u << 24) || d.exponent < -10 || d.exponent > 10) return nullptr;
  float v = static_cast<float>(d.mantissa);
  v = d.exponent < 0 ? v / kPow10[-d.exponent] : v * kPow10[d.exponent];
  out = d.negative ? -v : v;
  return p;
}

inline const char* fast_double(const char* p, const char* end, double& out) {
  constexpr double kPow10[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                               1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                               1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
  Decimal d;
  p = scan_decimal(p, end, d, ends_token_at);
  if (!p || d.mantissa > (std::uint64_t{1} << 53) || d.exponent < -22 || d.exponent > 22)
    return nullptr;
  double v = static_cast<double>(d.mantissa);
  v = d.exponent < 0 ? v / kPow10[-d.exponent] : v * kPow10[d.exponent];
  out = d.negative ? -v : v;
  return p;
}

inline const char* fast_integer(const char* p, const char* end, std::int64_t& out) {
  return io_detail::scan_integer(p, end, out, ends_token_at);
}

class AsciiParser {
 public:
  AsciiParser(const BodyContext& ctx, std::vector<Triangle>& triangles)
      : ctx_(ctx),
        header_(*ctx.header),
        triangles_(triangles),
        end_(ctx.data.data() + ctx.data.size()) {
    std::uint64_t total = 0;
    first_of_.push_back(0);
    for (const Element& element : header_.elements) {
      // An element without properties takes no line (as it takes no byte in binary files).
      total += element.properties.empty() ? 0 : element.count;
      first_of_.push_back(total);
    }
    total_ = total;
  }

  std::uint64_t total() const { return total_; }

  // Parses the element lines in [begin, end) (a whole number of lines), the first being element
  // `first` in file order. Returns the number of element lines parsed.
  std::uint64_t parse(const char* begin, const char* end, std::uint64_t first) {
    end_ = end;
    const char* p = begin;
    std::uint64_t flat = first;
    std::size_t e = 0;
    while (e + 1 < first_of_.size() && first_of_[e + 1] <= flat) ++e;
    const char* reported = begin;
    for (;;) {
      while (p < end && (is_blank(*p) || *p == '\n')) ++p;
      if (p == end) break;
      if (flat >= total_)
        ctx_.fail_at_char(p, "extra data after the last element (the header declares " +
                                 counts_text() + "), found " + token_text(p, end_));
      while (first_of_[e + 1] <= flat) ++e;
      p = parse_line(p, e, flat - first_of_[e]);
      ++flat;
      if (((flat - first) & 0xffff) == 0 && ctx_.on_bytes) {
        ctx_.on_bytes(static_cast<std::uint64_t>(p - reported));
        reported = p;
      }
    }
    if (ctx_.on_bytes && end > reported) ctx_.on_bytes(static_cast<std::uint64_t>(end - reported));
    return flat - first;
  }

  // `data_end`: the end of the whole body.
  [[noreturn]] void fail_ends_early(std::uint64_t lines, const char* data_end) const {
    std::size_t e = 0;
    while (first_of_[e + 1] <= lines) ++e;
    ctx_.fail_at_char(data_end, "file ends early: " + ctx_.instance(e, lines - first_of_[e]) +
                                    " is missing (the header declares " + counts_text() +
                                    ", found " + std::to_string(lines) + " element lines)");
  }

 private:
  std::string counts_text() const {
    std::string text;
    for (const Element& element : header_.elements) {
      if (!text.empty()) text += " and ";
      text += std::to_string(element.count) + " " + element.name;
    }
    return text;
  }

  // Start of the next token on this line; fails when the line has ended.
  const char* next_token(const char* p, std::size_t e, std::uint64_t i, std::size_t j,
                         const char* what) const {
    while (p < end_ && is_blank(*p)) ++p;
    if (p == end_ || *p == '\n')
      ctx_.fail_at_char(p, ctx_.instance(e, i) + ": " + ctx_.property(e, j) +
                               ": line ends early (expected " + what + ", found end of line)");
    return p;
  }

  bool ends_token(const char* q) const { return q == end_ || is_blank(*q) || *q == '\n'; }

  [[gnu::noinline]] const char* parse_float(const char* p, std::size_t e, std::uint64_t i,
                                            std::size_t j, ScalarType type, float& value) const {
    p = next_token(p, e, i, j, "a number");
    const char* s = p + (*p == '+');
    std::from_chars_result r;
    if (type == ScalarType::Float32) {
      r = std::from_chars(s, end_, value);
    } else {
      double d = 0;
      r = std::from_chars(s, end_, d);
      value = static_cast<float>(d);
    }
    if (r.ec == std::errc::result_out_of_range) {
      // Too large or too small for the type: the double tells which.
      double d = 0;
      r = std::from_chars(s, end_, d);
      if (r.ec == std::errc::result_out_of_range) {
        // Beyond double too: a negative exponent means it underflows to zero.
        const std::string_view token(s, static_cast<std::size_t>(r.ptr - s));
        const bool tiny = token.find("e-") != token.npos || token.find("E-") != token.npos;
        d = tiny ? 0.0 : (*s == '-' ? -HUGE_VAL : HUGE_VAL);
        r.ec = std::errc();
      }
      value = static_cast<float>(d);
    }
    const char* q = r.ptr;
    const std::errc ec = r.ec;
    if (ec != std::errc() || !ends_token(q))
      ctx_.fail_at_char(p, ctx_.instance(e, i) + ": " + ctx_.property(e, j) +
                               ": expected a number, found " + token_text(p, end_));
    return q;
  }

  [[gnu::noinline]] const char* parse_integer(const char* p, std::size_t e, std::uint64_t i,
                                              std::size_t j, ScalarType type,
                                              std::int64_t& value) const {
    p = next_token(p, e, i, j, "an integer");
    const char* s = p + (*p == '+');
    const auto [q, ec] = std::from_chars(s, end_, value);
    if (ec != std::errc() || !ends_token(q))
      ctx_.fail_at_char(p, ctx_.instance(e, i) + ": " + ctx_.property(e, j) +
                               ": expected an integer (" + scalar_name(type) + "), found " +
                               token_text(p, end_));
    const Range range = integer_range(type);
    if (value < range.lo || value > range.hi)
      ctx_.fail_at_char(p, ctx_.instance(e, i) + ": " + ctx_.property(e, j) + ": value " +
                               std::to_string(value) + " out of range for " + scalar_name(type));
    return q;
  }

  [[gnu::noinline]] const char* parse_scalar(const char* p, std::size_t e, std::uint64_t i,
                                             std::size_t j, ScalarType type, float& value) const {
    if (!is_integer(type)) return parse_float(p, e, i, j, type, value);
    std::int64_t v = 0;
    p = parse_integer(p, e, i, j, type, v);
    value = static_cast<float>(v);
    return p;
  }

  // One value of `property` (item values for lists) as float: fast path, else the checked path.
  const char* value(const char* p, std::size_t e, std::uint64_t i, std::size_t j, ScalarType type,
                    float& v) const {
    while (p < end_ && is_blank(*p)) ++p;
    const char* q = nullptr;
    if (type == ScalarType::Float32) {
      q = fast_float(p, end_, v);
    } else if (type == ScalarType::Float64) {
      double d = 0;
      q = fast_double(p, end_, d);
      v = static_cast<float>(d);
    } else {
      std::int64_t n = 0;
      q = fast_integer(p, end_, n);
      const Range range = integer_range(type);
      if (q && n >= range.lo && n <= range.hi) {
        v = static_cast<float>(n);
        return q;
      }
      q = nullptr;
    }
    return q ? q : parse_scalar(p, e, i, j, type, v);
  }

  const char* integer(const char* p, std::size_t e, std::uint64_t i, std::size_t j, ScalarType type,
                      std::int64_t& n) const {
    while (p < end_ && is_blank(*p)) ++p;
    const char* q = fast_integer(p, end_, n);
    const Range range = integer_range(type);
    if (q && n >= range.lo && n <= range.hi) return q;
    return parse_integer(p, e, i, j, type, n);
  }

  const char* parse_line(const char* p, std::size_t e, std::uint64_t i) {
    const Element& element = header_.elements[e];
    const ElementPlan& plan = ctx_.plans[e];
    float values[kTargetCount] = {};
    for (std::size_t j = 0; j < element.properties.size(); ++j) {
      const Property& property = element.properties[j];
      const PropertyPlan& target = plan.properties[j];
      if (!property.is_list) {
        const char* token = p;
        float v = 0;
        p = value(p, e, i, j, property.type, v);
        if (target.target != kNoTarget) {
          if (must_be_finite(target.target) && !std::isfinite(v)) fail_not_finite(token, e, i, j);
          values[target.target] = v;
        }
        continue;
      }
      std::int64_t n = 0;
      const char* count_token = p;
      p = integer(p, e, i, j, property.count_type, n);
      if (n < 0) {
        while (is_blank(*count_token)) ++count_token;
        ctx_.fail_at_char(count_token, ctx_.instance(e, i) + ": " + ctx_.property(e, j) +
                                           ": negative count " + std::to_string(n));
      }
      if (target.is_face_indices) {
        FanBuilder fan;
        for (std::int64_t k = 0; k < n; ++k) {
          std::int64_t index = 0;
          const char* token = p;
          p = integer(p, e, i, j, property.type, index);
          if (index < 0 || static_cast<std::uint64_t>(index) >= ctx_.vertex_count)
            fail_bad_index(token, e, i, j, index);
          fan.add(static_cast<std::uint32_t>(index), triangles_);
        }
      } else {
        for (std::int64_t k = 0; k < n; ++k) {
          float ignored = 0;
          p = value(p, e, i, j, property.type, ignored);
        }
      }
    }
    while (p < end_ && is_blank(*p)) ++p;
    if (p < end_ && *p != '\n') fail_extra_value(p, e, i);
    if (plan.kind == ElementPlan::Kind::Vertex)
      store_vertex(ctx_.vertex, static_cast<std::size_t>(i), values);
    return p;
  }

  [[noreturn, gnu::cold, gnu::noinline]] void fail_not_finite(const char* token, std::size_t e,
                                                              std::uint64_t i,
                                                              std::size_t j) const {
    while (is_blank(*token)) ++token;
    ctx_.fail_at_char(token, ctx_.instance(e, i) + ": " + ctx_.property(e, j) +
                                 " is not a finite number (found " + token_text(token, end_) + ")");
  }

  [[noreturn, gnu::cold, gnu::noinline]] void fail_bad_index(const char* token, std::size_t e,
                                                             std::uint64_t i, std::size_t j,
                                                             std::int64_t index) const {
    while (is_blank(*token)) ++token;
    ctx_.fail_at_char(token, ctx_.instance(e, i) + ": " + ctx_.property(e, j) + ": vertex index " +
                                 std::to_string(index) + " out of range (expected 0 to " +
                                 std::to_string(ctx_.vertex_count) + " - 1)");
  }

  [[noreturn, gnu::cold, gnu::noinline]] void fail_extra_value(const char* p, std::size_t e,
                                                               std::uint64_t i) const {
    const Element& element = header_.elements[e];
    ctx_.fail_at_char(p, ctx_.instance(e, i) + ": extra value " + token_text(p, end_) + " after " +
                             ctx_.property(e, element.properties.size() - 1) + " (expected " +
                             std::to_string(element.properties.size()) + " values on this line)");
  }

  const BodyContext& ctx_;
  const Header& header_;
  std::vector<Triangle>& triangles_;
  const char* end_;
  std::vector<std::uint64_t> first_of_;  // flat index of each element's first instance
  std::uint64_t total_ = 0;
};

}  // namespace

std::uint64_t count_element_lines(const char* begin, const char* end) {
  std::uint64_t lines = 0;
  const char* p = begin;
  while (p < end) {
    const char* nl =
        static_cast<const char*>(std::memchr(p, '\n', static_cast<std::size_t>(end - p)));
    const char* line_end = nl ? nl : end;
    const char* q = p;
    while (q < line_end && is_blank(*q)) ++q;
    lines += q < line_end;
    p = nl ? nl + 1 : end;
  }
  return lines;
}

std::uint64_t parse_ascii_lines(const BodyContext& ctx, const char* begin, const char* end,
                                std::uint64_t first, std::vector<Triangle>* triangles) {
  std::vector<Triangle> unused;
  return AsciiParser(ctx, triangles ? *triangles : unused).parse(begin, end, first);
}

void fail_ascii_ends_early(const BodyContext& ctx, std::uint64_t lines) {
  std::vector<Triangle> unused;
  AsciiParser(ctx, unused).fail_ends_early(lines, ctx.data.data() + ctx.data.size());
}

void decode_ascii_body(const BodyContext& ctx, std::vector<Triangle>& triangles) {
  const char* begin = ctx.data.data() + ctx.header->body_offset;
  const char* end = ctx.data.data() + ctx.data.size();
  constexpr std::size_t kMinPieceBytes = 1 << 20;
  const std::size_t bytes = static_cast<std::size_t>(end - begin);

  if (!ctx.pool || ctx.pool->thread_count() < 2 || bytes < 2 * kMinPieceBytes) {
    AsciiParser parser(ctx, triangles);
    const std::uint64_t lines = parser.parse(begin, end, 0);
    if (lines < parser.total()) parser.fail_ends_early(lines, end);
    return;
  }

  // Pieces start right after a newline, so each holds whole lines.
  const std::size_t piece_count =
      std::min<std::size_t>(ctx.pool->thread_count() * 4, bytes / kMinPieceBytes);
  std::vector<const char*> cuts{begin};
  for (std::size_t k = 1; k < piece_count; ++k) {
    const char* guess = std::max(begin + bytes * k / piece_count, cuts.back());
    const char* nl =
        static_cast<const char*>(std::memchr(guess, '\n', static_cast<std::size_t>(end - guess)));
    cuts.push_back(nl ? nl + 1 : end);
  }
  cuts.push_back(end);

  std::vector<std::uint64_t> firsts(piece_count + 1, 0);
  ctx.pool->run(piece_count,
                [&](std::size_t k) { firsts[k + 1] = count_element_lines(cuts[k], cuts[k + 1]); });
  for (std::size_t k = 0; k < piece_count; ++k) firsts[k + 1] += firsts[k];

  std::vector<std::vector<Triangle>> piece_triangles(piece_count);
  AsciiParser check(ctx, triangles);
  ctx.pool->run(piece_count, [&](std::size_t k) {
    piece_triangles[k].reserve(static_cast<std::size_t>(firsts[k + 1] - firsts[k]));
    AsciiParser parser(ctx, piece_triangles[k]);
    parser.parse(cuts[k], cuts[k + 1], firsts[k]);
  });
  if (firsts[piece_count] < check.total()) check.fail_ends_early(firsts[piece_count], end);

  std::size_t total_triangles = triangles.size();
  for (const auto& piece : piece_triangles) total_triangles += piece.size();
  triangles.reserve(total_triangles);
  for (const auto& piece : piece_triangles)
    triangles.insert(triangles.end(), piece.begin(), piece.end());
}

void decode_ascii_stream(const BodyContext& ctx, std::vector<Triangle>& triangles,
                         const std::function<StreamState(std::size_t)>& wait) {
  constexpr std::size_t kStep = 1 << 20;
  const char* data = ctx.data.data();
  std::size_t cursor = ctx.header->body_offset;
  std::uint64_t lines = 0;
  AsciiParser parser(ctx, triangles);
  std::size_t want = cursor + kStep;
  for (;;) {
    const StreamState state = wait(want);
    std::size_t end = state.available;
    if (!state.finished) {
      // Parse whole lines only; a line longer than a step waits for more.
      const void* nl = end > cursor ? memrchr(data + cursor, '\n', end - cursor) : nullptr;
      if (!nl) {
        want = end + kStep;
        continue;
      }
      end = static_cast<std::size_t>(static_cast<const char*>(nl) - data) + 1;
    }
    lines += parser.parse(data + cursor, data + end, lines);
    cursor = end;
    if (state.finished) {
      if (lines < parser.total()) parser.fail_ends_early(lines, data + end);
      return;
    }
    want = state.available + kStep;
  }
}

}  // namespace pointillist::ply
