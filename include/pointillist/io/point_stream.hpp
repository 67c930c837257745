// Scan files read a batch of points at a time, in constant memory: the input side of the
// chunked conversion (pipeline/chunked_convert.hpp), which reads its inputs several times and
// never holds them whole.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "pointillist/core/point_set.hpp"
#include "pointillist/io/point_file.hpp"

namespace pointillist {

// What a stream knows once it is open.
struct PointStreamInfo {
  std::string path;
  std::uint64_t point_count = 0;  // points the stream yields
  bool has_normals = false;
  bool has_colors = false;
  bool has_radii = false;
  // The file has faces (a mesh): its vertices stream like points, but the faces do not; the
  // chunked conversion takes point clouds only.
  bool is_mesh = false;
  // Read in windows of the file, so memory does not grow with the file. False: the reader has
  // no streaming form for this file (binary PLY files with lists before or in the vertex
  // element are read whole when the stream opens) and `resident_bytes` says what it holds.
  bool streamed = true;
  std::uint64_t resident_bytes = 0;
  std::uint64_t file_size = 0;
  // The frame and comments read_point_file would give (origin = 0 when positions are absolute).
  std::array<double, 3> origin{};
  Vec3f up{0, 1, 0};
  std::vector<std::string> comments;
};

class PointStream {
 public:
  virtual ~PointStream() = default;
  const PointStreamInfo& info() const { return info_; }
  // Replaces `batch`'s positions (and normals, colors, radii as info() says; triangles and
  // comments are left empty) with the next points, at most `max`; returns how many (0 at the
  // end). The points are those read_point_file returns, in the same order and bits. Throws
  // FormatError naming the file and byte (or line) of bad data, IoError when reading fails.
  virtual std::size_t read(PointSet& batch, std::size_t max) = 0;
  // Starts again from the first point.
  virtual void rewind() = 0;
  // Bytes of the file consumed by the reads since the last rewind (for progress).
  virtual std::uint64_t bytes_done() const = 0;
  // Whether some normal read so far was usable (not zero, finite). A file whose normals are all
  // unusable has none in substance: read_point_file drops them, and a caller that streams the
  // whole file should too.
  virtual bool saw_usable_normals() const { return info_.has_normals; }

 protected:
  PointStreamInfo info_;
};

// Opens `path` as read_point_file would read it (the reader chosen by the extension). PLY
// (binary with a vertex element of fixed-size records, or ASCII), LAS and text files (XYZ, PTS,
// CSV, TXT), plain or gzip, are streamed (gzip data decompressed as it is read, again from its
// start on rewind); LAS and text run one pass over the file at open (LAS: the origin and
// colour scale read_las uses; text: the point count, and the statistics that tell normals from
// colours when the columns leave it open). Other files are read whole at open
// (info().streamed false). Throws what read_point_file throws for a bad file, and
// IoError for a missing one.
std::unique_ptr<PointStream> open_point_stream(const std::string& path,
                                               const PointReadOptions& options = {});

// How many points `path` holds, found cheaply (no pass over the points): the header's count for
// binary PLY and LAS (gzip too); for other files an upper estimate from the file's size (a text line holds
// at least 6 bytes; a gzip file is taken to inflate 16 times). Throws what open_point_stream
// throws for a bad PLY or LAS header, IoError for a missing file.
std::uint64_t point_count_estimate(const std::string& path);
// The header's count of a PLY (binary with a vertex element of fixed-size records, or ASCII) or
// a LAS file, plain or gzip, read cheaply; nothing for other files. Throws as
// point_count_estimate (IoError for a missing file).
std::optional<std::uint64_t> exact_point_count(const std::string& path);

// The faces of a mesh file read a window at a time, in constant memory: the triangles
// read_point_file gives (polygons fan-triangulated), in the same order, checked the same way.
// What a mesh larger than memory is prepared from (pipeline/mesh_streamed.cpp).
class FaceStream {
 public:
  virtual ~FaceStream() = default;
  // Replaces `triangles` with the triangles of the next whole faces (about a window of the
  // file; faces of fewer than 3 vertices give none); false at the end. Throws FormatError
  // naming the file, the byte and the face of bad data (an index out of range, a negative
  // count, the file ending early), IoError when reading fails.
  virtual bool read(std::vector<std::array<std::uint32_t, 3>>& triangles) = 0;
  // Faces read so far (for progress).
  virtual std::uint64_t faces_done() const = 0;
  std::uint64_t vertex_count() const { return vertex_count_; }
  std::uint64_t face_count() const { return face_count_; }

  // OBJ's file normals: the corners of the faces just read that name one (`f v//vn`), as
  // (vertex, normal) 0-based indices in file order (read_obj sums each vertex's), and the `vn`
  // lines themselves, a window at a time in a pass of their own (false at the end). PLY has
  // none.
  const std::vector<std::array<std::uint32_t, 2>>& normal_refs() const { return normal_refs_; }
  std::uint64_t normal_count() const { return normal_count_; }
  virtual bool read_normals(std::vector<Vec3f>& normals) {
    normals.clear();
    return false;
  }

 protected:
  std::uint64_t vertex_count_ = 0, face_count_ = 0, normal_count_ = 0;
  std::vector<std::array<std::uint32_t, 2>> normal_refs_;
};

// The faces of `path` as a stream: PLY files, binary or ASCII, whatever their element layout,
// and OBJ files, plain or gzip. Null for a file without faces. Throws what read_point_file
// throws for a bad header (PLY) or a bad line found by the OBJ stream's first pass (which
// counts the lines), and IoError for a missing file. `window_bytes`: the most a binary PLY's
// face window holds (its triangles take about as much again; text files read windows of at most
// 128 K lines).
std::unique_ptr<FaceStream> open_face_stream(const std::string& path,
                                             std::size_t window_bytes = std::size_t{32} << 20);

}  // namespace pointillist
