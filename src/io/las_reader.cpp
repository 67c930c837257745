// ASPRS LAS reader ("LAS Specification 1.4 - R15", ASPRS 2019; the 1.0 to 1.3 layouts are the
// same prefix of the public header). The file is memory-mapped; a first pass over the records
// finds the coordinate bounds (for the origin) and the largest color value (for the color
// scale), a second pass decodes. Both passes run in chunks, in parallel when a pool is given.
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>

#include "pointillist/core/file_bytes.hpp"
#include "text_numbers.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/core/thread_pool.hpp"
#include "pointillist/io/las.hpp"
#include "file_window.hpp"
#include "streams.hpp"

namespace pointillist {
namespace {

using namespace io_detail;

// Little-endian loads from unaligned bytes (a single load on little-endian machines).
inline std::uint64_t load_le(const char* p, int size) {
  std::uint64_t v = 0;
  for (int i = 0; i < size; ++i) v |= std::uint64_t(static_cast<unsigned char>(p[i])) << (8 * i);
  return v;
}
inline std::uint8_t u8(const char* p) { return static_cast<std::uint8_t>(*p); }
inline std::uint16_t u16(const char* p) { return static_cast<std::uint16_t>(load_le(p, 2)); }
inline std::uint32_t u32(const char* p) { return static_cast<std::uint32_t>(load_le(p, 4)); }
inline std::int32_t i32(const char* p) { return static_cast<std::int32_t>(u32(p)); }
inline std::uint64_t u64(const char* p) { return load_le(p, 8); }
inline double f64(const char* p) { return std::bit_cast<double>(u64(p)); }

// Record sizes of point formats 0..10 and where their RGB starts (-1: none).
constexpr int kFormatCount = 11;
constexpr std::uint16_t kRecordSize[kFormatCount] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};
constexpr int kRgbOffset[kFormatCount] = {-1, -1, 20, 28, -1, 28, -1, 30, 30, -1, 30};

// Byte offsets of public header fields.
constexpr std::size_t kVersionAt = 24, kSystemAt = 26, kSoftwareAt = 58, kHeaderSizeAt = 94,
                      kPointOffsetAt = 96, kFormatAt = 104, kRecordLengthAt = 105,
                      kLegacyCountAt = 107, kScaleAt = 131, kOffsetAt = 155, kCount64At = 247;

struct LasHeader {
  int major = 0, minor = 0;
  std::uint32_t point_offset = 0;
  int format = 0;
  std::uint16_t record_length = 0;
  std::uint64_t point_count = 0;
  double scale[3] = {}, offset[3] = {};
  std::string system, software;
};

std::string fixed_text(const char* p, std::size_t size) {
  std::string text(p, strnlen(p, size));
  while (!text.empty() && (text.back() == ' ')) text.pop_back();
  for (char& c : text)
    if (static_cast<unsigned char>(c) < 32 || c == 127) c = '?';
  return text;
}

class LasFile {
 public:
  // `data`: the file, or a prefix of it holding the public header (a streamed file) whose
  // whole size is `file_size`.
  LasFile(const std::string& path, std::string_view data, bool compressed,
          std::uint64_t file_size = std::numeric_limits<std::uint64_t>::max())
      : path_(path), data_(data), compressed_(compressed),
        file_size_(file_size == std::numeric_limits<std::uint64_t>::max() ? data.size()
                                                                           : file_size) {}

  [[noreturn]] void fail(std::uint64_t offset, const std::string& what) const {
    throw FormatError(path_ + ": byte " + std::to_string(offset) +
                      (compressed_ ? " (decompressed)" : "") + ": " + what);
  }

  LasHeader parse_header() const {
    const char* d = data_.data();
    const std::uint64_t size = file_size_;
    if (size == 0) fail(0, "file is empty (expected a LAS file starting with 'LASF')");
    if (size < 4 || std::memcmp(d, "LASF", 4) != 0)
      fail(0, "not a LAS file: expected the signature 'LASF', found " +
                  quote_token(d, d + std::min<std::size_t>(size, 4)));
    constexpr std::size_t kMinHeader = 227;
    if (size < kMinHeader)
      fail(size, "file ends inside the public header (a LAS header has at least 227 bytes, the "
                 "file has " + std::to_string(size) + "); the file is truncated");
    LasHeader h;
    h.major = u8(d + kVersionAt);
    h.minor = u8(d + kVersionAt + 1);
    if (h.major != 1 || h.minor > 4)
      fail(kVersionAt, "unsupported LAS version " + std::to_string(h.major) + "." +
                           std::to_string(h.minor) + " (expected 1.0 to 1.4)");
    const std::uint16_t header_size = u16(d + kHeaderSizeAt);
    const std::size_t needed = h.minor >= 4 ? 375 : h.minor == 3 ? 235 : kMinHeader;
    if (header_size < needed)
      fail(kHeaderSizeAt, "header size " + std::to_string(header_size) + " is too small for LAS " +
                              std::to_string(h.major) + "." + std::to_string(h.minor) +
                              " (expected at least " + std::to_string(needed) + ")");
    if (header_size > data_.size() && data_.size() < size)
      fail(header_size, "the public header is larger than the part of the file read for it");
    if (header_size > size)
      fail(size, "file ends inside the public header (its size field says " +
                     std::to_string(header_size) + " bytes, the file has " + std::to_string(size) +
                     "); the file is truncated");
    h.point_offset = u32(d + kPointOffsetAt);
    if (h.point_offset < header_size)
      fail(kPointOffsetAt, "offset to point data " + std::to_string(h.point_offset) +
                               " lies inside the header (header size " +
                               std::to_string(header_size) + ")");
    const std::uint8_t format_byte = u8(d + kFormatAt);
    if (format_byte & 0xc0)
      fail(kFormatAt, "compressed LAS (LAZ) is not supported yet (point format byte " +
                          std::to_string(format_byte) +
                          " has the compression bit set); decompress it with laszip or pdal "
                          "first, e.g. 'laszip -i in.laz -o out.las' or "
                          "'pdal translate in.laz out.las'");
    if (format_byte >= kFormatCount)
      fail(kFormatAt, "unsupported point data record format " + std::to_string(format_byte) +
                          " (expected 0 to 10)");
    h.format = format_byte;
    h.record_length = u16(d + kRecordLengthAt);
    if (h.record_length < kRecordSize[h.format])
      fail(kRecordLengthAt, "point record length " + std::to_string(h.record_length) +
                                " is too small for point format " + std::to_string(h.format) +
                                " (it needs at least " + std::to_string(kRecordSize[h.format]) +
                                " bytes)");
    const std::uint32_t legacy_count = u32(d + kLegacyCountAt);
    const std::uint64_t count64 = h.minor >= 4 ? u64(d + kCount64At) : 0;
    h.point_count = count64 != 0 ? count64 : legacy_count;
    if (h.point_count == 0)
      fail(h.minor >= 4 ? kCount64At : kLegacyCountAt,
           std::string("the file has no points (point count 0") +
               (h.minor >= 4 ? ", legacy count at byte 107 also 0)" : ")"));
    for (int a = 0; a < 3; ++a) {
      h.scale[a] = f64(d + kScaleAt + 8 * a);
      h.offset[a] = f64(d + kOffsetAt + 8 * a);
      if (!std::isfinite(h.scale[a]) || h.scale[a] == 0.0)
        fail(kScaleAt + 8 * a, std::string(1, "XYZ"[a]) + " scale factor " +
                                   format_double(h.scale[a]) +
                                   " is not usable (expected a non-zero number such as 0.001)");
      if (!std::isfinite(h.offset[a]))
        fail(kOffsetAt + 8 * a, std::string(1, "XYZ"[a]) + " offset is not a finite number");
    }
    h.system = fixed_text(d + kSystemAt, 32);
    h.software = fixed_text(d + kSoftwareAt, 32);

    // Every record must be in the file.
    const std::uint64_t available = size > h.point_offset ? size - h.point_offset : 0;
    if (h.point_count > available / h.record_length) {
      const std::uint64_t complete = available / h.record_length;
      const bool fits64 =
          h.point_count <= (std::numeric_limits<std::uint64_t>::max() - h.point_offset) /
                               h.record_length;
      fail(size, "file ends early: point " + std::to_string(complete) + " of " +
                     std::to_string(h.point_count) + " is " + (complete * h.record_length < available ? "incomplete" : "missing") +
                     " (" + std::to_string(h.point_count) + " records of " +
                     std::to_string(h.record_length) + " bytes from byte " +
                     std::to_string(h.point_offset) + " need " +
                     (fits64 ? std::to_string(h.point_offset + h.point_count * h.record_length)
                             : std::string("more than 2^64")) +
                     " bytes, the file has " + std::to_string(size) + "); the file is truncated");
    }
    return h;
  }

 private:
  const std::string& path_;
  std::string_view data_;
  bool compressed_;
  std::uint64_t file_size_;
};

// What the first pass finds over a range of records.
struct RecordStats {
  std::int32_t lo[3] = {std::numeric_limits<std::int32_t>::max(),
                        std::numeric_limits<std::int32_t>::max(),
                        std::numeric_limits<std::int32_t>::max()};
  std::int32_t hi[3] = {std::numeric_limits<std::int32_t>::min(),
                        std::numeric_limits<std::int32_t>::min(),
                        std::numeric_limits<std::int32_t>::min()};
  std::uint16_t max_color = 0;

  void merge(const RecordStats& o) {
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], o.lo[a]);
      hi[a] = std::max(hi[a], o.hi[a]);
    }
    max_color = std::max(max_color, o.max_color);
  }
};

constexpr std::size_t kChunk = 1 << 16;  // records per chunk

// Calls fn(begin, end) for the chunks [k * kChunk, (k + 1) * kChunk) of [0, count), on the pool
// when there is one.
void for_chunks(ThreadPool* pool, std::size_t count,
                const std::function<void(std::size_t, std::size_t)>& fn) {
  const std::size_t chunks = (count + kChunk - 1) / kChunk;
  const auto chunk = [&](std::size_t k) { fn(k * kChunk, std::min(count, (k + 1) * kChunk)); };
  if (pool && pool->thread_count() >= 2 && chunks > 1) {
    pool->run(chunks, chunk);
    return;
  }
  for (std::size_t k = 0; k < chunks; ++k) chunk(k);
}

// For GzipInflater::set_limit: the most bytes the public header allows (point data offset +
// count x record length, plus 1 MiB for what writers leave after the points), once the header
// is in; no bound for a LAS 1.3/1.4 file with extended records after the points (their sizes
// are in them) or a header the parser will reject anyway.
std::uint64_t las_limit(std::string_view prefix) {
  constexpr std::uint64_t kNone = std::numeric_limits<std::uint64_t>::max();
  constexpr std::size_t kMinHeader = 227, kEvlrStartAt = 235, kEvlrCountAt = 243;
  if (prefix.size() < 375) return kNone;
  const char* d = prefix.data();
  if (std::memcmp(d, "LASF", 4) != 0 || u8(d + kVersionAt) != 1) return kNone;
  const int minor = u8(d + kVersionAt + 1);
  if (u16(d + kHeaderSizeAt) < kMinHeader) return kNone;
  if (minor >= 3 && u64(d + kEvlrStartAt) != 0 && (minor < 4 || u32(d + kEvlrCountAt) != 0)) {
    return kNone;
  }
  const std::uint64_t offset = u32(d + kPointOffsetAt), record = u16(d + kRecordLengthAt);
  const std::uint64_t count64 = minor >= 4 ? u64(d + kCount64At) : 0;
  const std::uint64_t count = count64 != 0 ? count64 : u32(d + kLegacyCountAt);
  if (record == 0 || count > (kNone - offset - (1u << 20)) / record) return kNone;
  return offset + count * record + (1u << 20);
}

void scan_records(const char* records, std::size_t count, std::size_t stride, int rgb,
                  RecordStats& s) {
  for (std::size_t i = 0; i < count; ++i) {
    const char* r = records + i * stride;
    for (int a = 0; a < 3; ++a) {
      const std::int32_t v = i32(r + 4 * a);
      s.lo[a] = std::min(s.lo[a], v);
      s.hi[a] = std::max(s.hi[a], v);
    }
    if (rgb >= 0)
      s.max_color = std::max({s.max_color, u16(r + rgb), u16(r + rgb + 2), u16(r + rgb + 4)});
  }
}

// How the records become points, from the first pass's statistics: positions are
// integer * scale + shift, colours shifted right by color_shift.
struct LasFrame {
  double shift[3] = {};
  std::array<double, 3> origin{};
  int rgb = -1;  // byte offset of RGB in a record, -1 when colours are not read
  int color_shift = 0;
};

// `find_record(axis, value)`: the index of the first record whose coordinate on `axis` is
// `value` (for the message when a coordinate overflows).
LasFrame las_frame(const std::string& path, const LasHeader& h, const RecordStats& stats,
                   bool read_colors, bool shift_origin, bool compressed,
                   const std::function<std::uint64_t(int, std::int32_t)>& find_record) {
  // Every decoded coordinate must be finite (a huge scale or offset can overflow): coordinates
  // are linear in the record's integer, so the axis extremes decide; the message names the
  // first record that overflows.
  const auto check_finite = [&](const double (&shift_by)[3]) {
    for (int a = 0; a < 3; ++a) {
      for (const std::int32_t v : {stats.lo[a], stats.hi[a]}) {
        const double w = double(v) * h.scale[a] + shift_by[a];
        if (std::isfinite(w) && std::fabs(w) <= double(std::numeric_limits<float>::max())) continue;
        const std::uint64_t i = find_record(a, v);
        LasFile(path, {}, compressed).fail(h.point_offset + i * h.record_length + 4 * a,
             "point record " + std::to_string(i) + ": " + std::string(1, "XYZ"[a]) +
                 " coordinate " + std::to_string(v) + " x scale " + format_double(h.scale[a]) +
                 " + offset " + format_double(h.offset[a]) +
                 " is not a finite number a float can hold; the header's scale or offset is "
                 "wrong (fix them, e.g. with las2las, or re-export the scan)");
      }
    }
  };
  check_finite(h.offset);
  LasFrame f;
  if (shift_origin) {
    for (int a = 0; a < 3; ++a) {
      const double s = h.scale[a];
      const double v0 = stats.lo[a] * s + h.offset[a], v1 = stats.hi[a] * s + h.offset[a];
      const double lo = std::min(v0, v1), hi = std::max(v0, v1);
      const double limit = std::ldexp(std::fabs(s), 23);
      f.origin[a] = axis_origin(lo, hi, limit, power_of_ten_below(std::max(hi - lo, std::fabs(s))));
    }
  }
  for (int a = 0; a < 3; ++a) f.shift[a] = h.offset[a] - f.origin[a];
  check_finite(f.shift);
  const int rgb = read_colors ? kRgbOffset[h.format] : -1;
  f.rgb = rgb >= 0 && stats.max_color > 0 ? rgb : -1;
  f.color_shift = stats.max_color > 255 ? 8 : 0;
  return f;
}

void decode_records(const char* records, std::size_t count, std::size_t stride,
                    const LasHeader& h, const LasFrame& f, Vec3f* positions, Rgb8* colors) {
  for (std::size_t i = 0; i < count; ++i) {
    const char* r = records + i * stride;
    positions[i] = {static_cast<float>(i32(r) * h.scale[0] + f.shift[0]),
                    static_cast<float>(i32(r + 4) * h.scale[1] + f.shift[1]),
                    static_cast<float>(i32(r + 8) * h.scale[2] + f.shift[2])};
    if (colors) {
      const int rgb = f.rgb;
      colors[i] = {static_cast<std::uint8_t>(u16(r + rgb) >> f.color_shift),
                   static_cast<std::uint8_t>(u16(r + rgb + 2) >> f.color_shift),
                   static_cast<std::uint8_t>(u16(r + rgb + 4) >> f.color_shift)};
    }
  }
}

std::vector<std::string> las_comments(const LasHeader& h) {
  std::vector<std::string> comments;
  comments.push_back("LAS " + std::to_string(h.major) + "." + std::to_string(h.minor) +
                     ", point format " + std::to_string(h.format) + ", " +
                     std::to_string(h.record_length) + "-byte records");
  if (!h.system.empty()) comments.push_back("system identifier: " + h.system);
  if (!h.software.empty()) comments.push_back("generating software: " + h.software);
  return comments;
}

}  // namespace

PointSet read_las(const std::string& path, Progress& progress, const LasReadOptions& options) {
  FileBytes raw = FileBytes::map(path);
  const std::uint64_t file_size = raw.file_size();
  ReadProgress read_progress(progress, file_size);
  FileBytes bytes = inflate_if_gzipped(std::move(raw), path, read_progress, las_limit);
  const bool gzip = bytes.was_compressed();
  const std::string_view data = bytes.view();
  const LasHeader h = LasFile(path, data, gzip).parse_header();

  const auto n = static_cast<std::size_t>(h.point_count);
  const char* records = data.data() + h.point_offset;
  const std::size_t stride = h.record_length;
  const int rgb = options.read_colors ? kRgbOffset[h.format] : -1;
  read_progress.begin_part(file_size - (gzip ? file_size / 2 : 0), 2 * std::uint64_t(n) * stride);

  std::vector<RecordStats> chunk_stats((n + kChunk - 1) / kChunk);
  for_chunks(options.pool, n, [&](std::size_t begin, std::size_t end) {
    RecordStats s;
    scan_records(records + begin * stride, end - begin, stride, rgb, s);
    chunk_stats[begin / kChunk] = s;
    read_progress.advance((end - begin) * stride);
  });
  RecordStats stats;
  for (const RecordStats& s : chunk_stats) stats.merge(s);
  const LasFrame frame =
      las_frame(path, h, stats, options.read_colors, options.shift_origin, gzip,
                [&](int axis, std::int32_t v) {
                  std::size_t i = 0;
                  while (i + 1 < n && i32(records + i * stride + 4 * axis) != v) ++i;
                  return std::uint64_t{i};
                });

  PointSet points;
  points.positions.resize(n);
  if (frame.rgb >= 0) points.colors.resize(n);
  Vec3f* positions = points.positions.data();
  Rgb8* colors = frame.rgb >= 0 ? points.colors.data() : nullptr;
  for_chunks(options.pool, n, [&](std::size_t begin, std::size_t end) {
    decode_records(records + begin * stride, end - begin, stride, h, frame, positions + begin,
                   colors ? colors + begin : nullptr);
    read_progress.advance((end - begin) * stride);
  });

  points.comments = las_comments(h);
  points.origin = frame.origin;
  points.up = {0, 0, 1};  // LAS coordinates are projected: x east, y north, z up
  read_progress.finish();
  return points;
}

namespace io_detail {
namespace {

class LasStream final : public PointStream {
 public:
  LasStream(std::unique_ptr<FileWindow> file, const LasHeader& header, const LasFrame& frame)
      : file_(std::move(file)), header_(header), frame_(frame) {}

  std::size_t read(PointSet& batch, std::size_t max) override {
    const std::size_t stride = header_.record_length;
    const std::uint64_t n =
        std::min<std::uint64_t>({max, info_.point_count - next_,
                                 std::max<std::uint64_t>(1, kStreamWindowBytes / stride)});
    batch.positions.resize(n);
    batch.colors.resize(frame_.rgb >= 0 ? n : 0);
    batch.normals.clear();
    batch.radii.clear();
    batch.triangles.clear();
    batch.comments.clear();
    if (n == 0) return 0;
    file_->read(header_.point_offset + next_ * stride, n * stride, buffer_);
    decode_records(buffer_.data(), n, stride, header_, frame_, batch.positions.data(),
                   frame_.rgb >= 0 ? batch.colors.data() : nullptr);
    next_ += n;
    return n;
  }
  void rewind() override { next_ = 0; }
  std::uint64_t bytes_done() const override {
    return header_.point_offset + next_ * header_.record_length;
  }

  void set_info(PointStreamInfo info) { info_ = std::move(info); }

 private:
  std::unique_ptr<FileWindow> file_;
  LasHeader header_;
  LasFrame frame_;
  std::uint64_t next_ = 0;
  std::vector<char> buffer_;
};

}  // namespace

// The size LasFile checks the header against: the file's, or for gzip data (whose length is
// known only at its end) no bound, a short file failing when its records are read.
std::uint64_t data_size(const FileWindow& file) {
  return file.compressed() ? std::numeric_limits<std::uint64_t>::max() - 1 : file.size();
}

// A gzip file's records against what its data can hold (parse_header checked a plain file's).
void check_records_fit(const FileWindow& file, const LasHeader& h) {
  file.check_holds(h.point_offset + h.point_count * h.record_length,
                   std::to_string(h.point_count) + " points of " +
                       std::to_string(h.record_length) + " bytes from byte " +
                       std::to_string(h.point_offset));
}

std::unique_ptr<PointStream> open_las_stream(const std::string& path,
                                             const PointReadOptions& options) {
  auto file = std::make_unique<FileWindow>(path);
  std::vector<char> prefix;
  file->read_some(0, 1 << 16, prefix);  // decompressed for a gzip file
  const std::string_view head(prefix.data(), prefix.size());
  const LasHeader h = LasFile(path, head, file->compressed(), data_size(*file)).parse_header();
  check_records_fit(*file, h);

  // The first pass: the statistics read_las finds, a window at a time.
  const std::size_t stride = h.record_length;
  const std::uint64_t per_window = std::max<std::uint64_t>(1, kStreamWindowBytes / stride);
  const int rgb = options.read_colors ? kRgbOffset[h.format] : -1;
  RecordStats stats;
  std::vector<char> window;
  const auto for_windows = [&](const std::function<bool(std::uint64_t, std::uint64_t)>& fn) {
    for (std::uint64_t first = 0; first < h.point_count; first += per_window) {
      const std::uint64_t n = std::min(per_window, h.point_count - first);
      file->read(h.point_offset + first * stride, static_cast<std::size_t>(n * stride), window);
      if (!fn(first, n)) return;
    }
  };
  for_windows([&](std::uint64_t, std::uint64_t n) {
    scan_records(window.data(), static_cast<std::size_t>(n), stride, rgb, stats);
    return true;
  });
  const LasFrame frame = las_frame(
      path, h, stats, options.read_colors, true, false, [&](int axis, std::int32_t v) {
        std::uint64_t found = h.point_count - 1;
        for_windows([&](std::uint64_t first, std::uint64_t n) {
          for (std::uint64_t i = 0; i < n; ++i) {
            if (i32(window.data() + i * stride + 4 * axis) == v) {
              found = first + i;
              return false;
            }
          }
          return true;
        });
        return found;
      });

  PointStreamInfo info;
  info.path = path;
  info.point_count = h.point_count;
  info.has_colors = frame.rgb >= 0;
  // Progress counts decompressed bytes of a gzip file, up to the last record.
  info.file_size = file->compressed() ? h.point_offset + h.point_count * stride : file->size();
  info.origin = frame.origin;
  info.up = {0, 0, 1};
  info.comments = las_comments(h);
  auto stream = std::make_unique<LasStream>(std::move(file), h, frame);
  stream->set_info(std::move(info));
  return stream;
}

std::optional<std::uint64_t> las_header_point_count(const std::string& path) {
  FileWindow file(path);
  std::vector<char> prefix;
  file.read_some(0, 1 << 16, prefix);
  const LasHeader h =
      LasFile(path, {prefix.data(), prefix.size()}, file.compressed(), data_size(file))
          .parse_header();
  check_records_fit(file, h);
  return h.point_count;
}

}  // namespace io_detail
}  // namespace pointillist
