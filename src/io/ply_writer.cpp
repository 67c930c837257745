// PLY writer: binary (either byte order) or ascii, through a temporary file renamed into place.
#include <bit>
#include <charconv>
#include <cstring>

#include "pointillist/core/atomic_file.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/io/ply.hpp"
#include "text_numbers.hpp"

namespace pointillist {
namespace {

void check_sizes(const std::string& path, const PointSet& points) {
  const std::size_t n = points.size();
  const auto check = [&](std::size_t size, const char* what) {
    if (size != 0 && size != n)
      throw Error("cannot write " + path + ": the point set has " + std::to_string(n) +
                  " positions but " + std::to_string(size) + " " + what +
                  " (attributes need one entry per position)");
  };
  check(points.normals.size(), "normals");
  check(points.colors.size(), "colors");
  check(points.radii.size(), "radii");
  for (std::size_t t = 0; t < points.triangles.size(); ++t)
    for (std::uint32_t v : points.triangles[t])
      if (v >= n)
        throw Error("cannot write " + path + ": triangle " + std::to_string(t) + " uses vertex " +
                    std::to_string(v) + " of " + std::to_string(n));
}

std::string make_header(const PointSet& points, const PlyWriteOptions& options, bool faces,
                        std::uint64_t count) {
  std::string h = "ply\nformat ";
  h += options.encoding == PlyEncoding::Ascii             ? "ascii"
       : options.encoding == PlyEncoding::BinaryBigEndian ? "binary_big_endian"
                                                          : "binary_little_endian";
  h += " 1.0\n";
  for (const std::string& comment : points.comments) {
    std::string line = comment;
    for (char& c : line)
      if (c == '\n' || c == '\r') c = ' ';
    h += "comment " + line + "\n";
  }
  using io_detail::format_double;
  if (points.origin != std::array<double, 3>{}) {
    h += "comment origin: " + format_double(points.origin[0]) + " " +
         format_double(points.origin[1]) + " " + format_double(points.origin[2]) + "\n";
  }
  if (!(points.up == Vec3f{0, 1, 0})) {
    h += "comment up: " + format_double(points.up.x) + " " + format_double(points.up.y) + " " +
         format_double(points.up.z) + "\n";
  }
  h += "element vertex " + std::to_string(count) + "\n";
  h += "property float x\nproperty float y\nproperty float z\n";
  if (points.has_normals()) h += "property float nx\nproperty float ny\nproperty float nz\n";
  if (points.has_colors()) h += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  if (points.has_radii()) h += "property float radius\n";
  if (faces) {
    h += "element face " + std::to_string(points.triangles.size()) + "\n";
    h += "property list uchar int vertex_indices\n";
  }
  h += "end_header\n";
  return h;
}

template <class T>
char* put(char* p, T value, bool swap) {
  static_assert(sizeof(T) == 4);
  std::uint32_t u = std::bit_cast<std::uint32_t>(value);
  if (swap) u = __builtin_bswap32(u);
  std::memcpy(p, &u, 4);
  return p + 4;
}

void write_binary_body(AtomicFile& file, const PointSet& points, bool faces,
                       bool big_endian) {
  const bool swap = big_endian != (std::endian::native == std::endian::big);
  const std::size_t stride = 12 + (points.has_normals() ? 12 : 0) + (points.has_colors() ? 3 : 0) +
                             (points.has_radii() ? 4 : 0);
  constexpr std::size_t kChunk = 1 << 14;
  std::vector<char> buffer(kChunk * std::max<std::size_t>(stride, 13));
  for (std::size_t first = 0; first < points.size(); first += kChunk) {
    const std::size_t n = std::min(kChunk, points.size() - first);
    char* p = buffer.data();
    for (std::size_t i = first; i < first + n; ++i) {
      const Vec3f v = points.positions[i];
      p = put(put(put(p, v.x, swap), v.y, swap), v.z, swap);
      if (points.has_normals()) {
        const Vec3f m = points.normals[i];
        p = put(put(put(p, m.x, swap), m.y, swap), m.z, swap);
      }
      if (points.has_colors()) {
        *p++ = static_cast<char>(points.colors[i].r);
        *p++ = static_cast<char>(points.colors[i].g);
        *p++ = static_cast<char>(points.colors[i].b);
      }
      if (points.has_radii()) p = put(p, points.radii[i], swap);
    }
    file.write(buffer.data(), static_cast<std::size_t>(p - buffer.data()));
  }
  if (!faces) return;
  for (std::size_t first = 0; first < points.triangles.size(); first += kChunk) {
    const std::size_t n = std::min(kChunk, points.triangles.size() - first);
    char* p = buffer.data();
    for (std::size_t t = first; t < first + n; ++t) {
      *p++ = 3;
      for (std::uint32_t v : points.triangles[t]) p = put(p, static_cast<std::int32_t>(v), swap);
    }
    file.write(buffer.data(), static_cast<std::size_t>(p - buffer.data()));
  }
}

// Shortest text that reads back as the same float.
char* put_text(char* p, float v) { return std::to_chars(p, p + 32, v).ptr; }
char* put_text(char* p, std::uint32_t v) { return std::to_chars(p, p + 16, v).ptr; }

void write_ascii_body(AtomicFile& file, const PointSet& points, bool faces) {
  std::vector<char> buffer(1 << 16);
  constexpr std::size_t kMaxLine = 11 * 32;
  char* p = buffer.data();
  const auto flush_if_full = [&] {
    if (static_cast<std::size_t>(buffer.data() + buffer.size() - p) < kMaxLine) {
      file.write(buffer.data(), static_cast<std::size_t>(p - buffer.data()));
      p = buffer.data();
    }
  };
  for (std::size_t i = 0; i < points.size(); ++i) {
    flush_if_full();
    const Vec3f v = points.positions[i];
    p = put_text(p, v.x);
    *p++ = ' ';
    p = put_text(p, v.y);
    *p++ = ' ';
    p = put_text(p, v.z);
    if (points.has_normals()) {
      for (int k = 0; k < 3; ++k) {
        *p++ = ' ';
        p = put_text(p, points.normals[i][k]);
      }
    }
    if (points.has_colors()) {
      for (std::uint8_t c : {points.colors[i].r, points.colors[i].g, points.colors[i].b}) {
        *p++ = ' ';
        p = put_text(p, std::uint32_t{c});
      }
    }
    if (points.has_radii()) {
      *p++ = ' ';
      p = put_text(p, points.radii[i]);
    }
    *p++ = '\n';
  }
  if (faces) {
    for (const auto& t : points.triangles) {
      flush_if_full();
      *p++ = '3';
      for (std::uint32_t v : t) {
        *p++ = ' ';
        p = put_text(p, v);
      }
      *p++ = '\n';
    }
  }
  file.write(buffer.data(), static_cast<std::size_t>(p - buffer.data()));
}

}  // namespace

void write_ply(const std::string& path, const PointSet& points, const PlyWriteOptions& options) {
  check_sizes(path, points);
  const bool faces = options.write_faces && points.is_mesh();
  AtomicFile file(path);
  file.write(make_header(points, options, faces, points.size()));
  if (options.encoding == PlyEncoding::Ascii)
    write_ascii_body(file, points, faces);
  else
    write_binary_body(file, points, faces, options.encoding == PlyEncoding::BinaryBigEndian);
  file.commit();
}

PlyPointWriter::PlyPointWriter(const std::string& path, const PointSet& layout,
                               std::uint64_t count)
    : file_(std::make_unique<AtomicFile>(path)), path_(path), count_(count),
      normals_(layout.has_normals()), colors_(layout.has_colors()), radii_(layout.has_radii()) {
  file_->write(make_header(layout, {}, false, count));
}

PlyPointWriter::~PlyPointWriter() = default;

void PlyPointWriter::write(const PointSet& batch) {
  const bool same = batch.has_normals() == normals_ && batch.has_colors() == colors_ &&
                    batch.has_radii() == radii_;
  if (!same || batch.is_mesh() || batch.size() > count_ - written_) {
    throw Error("cannot write " + path_ + ": a batch of " + std::to_string(batch.size()) +
                " points does not fit the header (other properties, or more than the " +
                std::to_string(count_) + " points announced)");
  }
  check_sizes(path_, batch);
  write_binary_body(*file_, batch, false, false);
  written_ += batch.size();
}

void PlyPointWriter::commit() {
  if (written_ != count_) {
    throw Error("cannot write " + path_ + ": " + std::to_string(written_) + " of the " +
                std::to_string(count_) + " points announced were written");
  }
  file_->commit();
}

}  // namespace pointillist
