// The files of a chunked conversion (see chunk_files.hpp).
#include "chunk_files.hpp"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <fstream>

#include "pointillist/core/error.hpp"

namespace pointillist::chunking {
namespace {

[[noreturn]] void write_failed(const std::string& path) {
  throw IoError(path + ": cannot write a chunk file (is the disk full?); the output was not "
                       "written and the input is untouched");
}

}  // namespace

WorkFolder::WorkFolder(const std::string& output) : path_(output + ".chunks") {
  std::error_code error;
  std::filesystem::remove_all(path_, error);
  if (!std::filesystem::create_directory(path_, error) || error) {
    throw IoError(path_.string() + ": cannot create the folder for the chunks: " +
                  error.message() + " (the output's folder must be writable)");
  }
}

WorkFolder::~WorkFolder() {
  if (!owner_) return;
  std::error_code error;
  std::filesystem::remove_all(path_, error);
}

ChunkFiles::ChunkFiles(const WorkFolder& folder, std::size_t chunks, const char* kind,
                       std::size_t buffer_bytes)
    : buffers_(chunks), buffer_bytes_(buffer_bytes) {
  // Room for a record past the threshold, so that appending never doubles a buffer.
  for (std::vector<char>& b : buffers_) b.reserve(buffer_bytes + 256);
  for (std::size_t c = 0; c < chunks; ++c) paths_.push_back(folder.file(name(kind, c)));
}

std::size_t ChunkFiles::buffer_bytes(std::size_t chunks, std::uint64_t most,
                                     std::uint64_t budget) {
  const std::uint64_t all = std::min(most, budget / 8);
  return static_cast<std::size_t>(
      std::clamp<std::uint64_t>(all / std::max<std::size_t>(chunks, 1), 4096, 1 << 20));
}

std::string ChunkFiles::name(const char* kind, std::size_t c) {
  char text[48];
  std::snprintf(text, sizeof text, "%s-%05zu", kind, c);
  return text;
}

void ChunkFiles::append(std::size_t c, const void* data, std::size_t size) {
  std::vector<char>& b = buffers_[c];
  const char* bytes = static_cast<const char*>(data);
  b.insert(b.end(), bytes, bytes + size);
  if (b.size() >= buffer_bytes_) flush(c);
}

void ChunkFiles::flush_all() {
  for (std::size_t c = 0; c < buffers_.size(); ++c) flush(c);
}

void ChunkFiles::flush(std::size_t c) {
  std::vector<char>& b = buffers_[c];
  if (b.empty()) return;
  std::ofstream out(paths_[c], std::ios::binary | std::ios::app);
  out.write(b.data(), std::streamsize(b.size()));
  if (!out) write_failed(paths_[c]);
  b.clear();
}

void encode_record(const RecordLayout& l, const PointSet& b, std::size_t i, std::uint64_t index,
                   bool halo, char* out) {
  std::memcpy(out, &b.positions[i], 12);
  const Rgb8 c = b.colors.empty() ? Rgb8{} : b.colors[i];
  out[12] = char(c.r);
  out[13] = char(c.g);
  out[14] = char(c.b);
  out[15] = halo ? 1 : 0;
  std::memcpy(out + 16, &index, 8);
  std::size_t at = 24;
  if (l.normals) {
    std::memcpy(out + at, &b.normals[i], 12);
    at += 12;
  }
  if (l.radii) std::memcpy(out + at, &b.radii[i], 4);
}

std::vector<char> read_whole(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw IoError(path + ": cannot read a chunk file back");
  std::vector<char> bytes(static_cast<std::size_t>(in.tellg()));
  in.seekg(0);
  in.read(bytes.data(), std::streamsize(bytes.size()));
  if (!in) throw IoError(path + ": cannot read a chunk file back");
  return bytes;
}

PointSet read_chunk(const std::string& path, const RecordLayout& l, bool colors,
                    std::vector<std::uint8_t>& own, std::vector<std::uint64_t>& index) {
  const std::vector<char> bytes = read_whole(path);
  const std::size_t n = bytes.size() / l.size();
  PointSet p;
  p.positions.resize(n);
  if (colors) p.colors.resize(n);
  if (l.normals) p.normals.resize(n);
  if (l.radii) p.radii.resize(n);
  own.resize(n);
  index.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const char* r = bytes.data() + i * l.size();
    std::memcpy(&p.positions[i], r, 12);
    if (colors) p.colors[i] = {std::uint8_t(r[12]), std::uint8_t(r[13]), std::uint8_t(r[14])};
    own[i] = r[15] == 0;
    std::memcpy(&index[i], r + 16, 8);
    std::size_t at = 24;
    if (l.normals) {
      std::memcpy(&p.normals[i], r + at, 12);
      at += 12;
    }
    if (l.radii) std::memcpy(&p.radii[i], r + at, 4);
  }
  return p;
}

void write_splats(const std::string& path, const Splats& s) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  const auto put = [&](const auto& v) {
    out.write(reinterpret_cast<const char*>(v.data()), std::streamsize(v.size() * sizeof(v[0])));
  };
  put(s.points.positions);
  put(s.points.normals);
  put(s.points.radii);
  put(s.points.colors);
  put(s.index);
  put(s.piece);
  if (!out) write_failed(path);
}

Splats read_splats(const std::string& path, std::size_t n, bool colors, bool index, bool piece,
                   bool geometry) {
  // Each array is read straight into its vector (no copy of the whole file first); those not
  // asked for are skipped.
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw IoError(path + ": cannot read a chunk file back");
  const std::size_t need = n * (28 + (colors ? 3 : 0) + (index ? 8 : 0) + (piece ? 4 : 0));
  if (static_cast<std::size_t>(in.tellg()) != need) {
    throw IoError(path + ": a chunk file changed on disk");
  }
  in.seekg(0);
  Splats s;
  const auto get = [&](auto& v, bool wanted) {
    const auto bytes = std::streamsize(n * sizeof(v[0]));
    if (!wanted) {
      in.seekg(bytes, std::ios::cur);
      return;
    }
    v.resize(n);
    if (n != 0) in.read(reinterpret_cast<char*>(v.data()), bytes);
  };
  get(s.points.positions, geometry);
  get(s.points.normals, true);
  get(s.points.radii, geometry);
  if (colors) get(s.points.colors, geometry);
  if (index) get(s.index, true);
  if (piece) get(s.piece, true);
  if (!in) throw IoError(path + ": cannot read a chunk file back");
  return s;
}

}  // namespace pointillist::chunking
