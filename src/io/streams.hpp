// The streaming forms of the readers (private to io; see point_stream.hpp).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "pointillist/io/point_stream.hpp"

namespace pointillist::io_detail {

// A PLY file (plain or gzip) read a window of vertices at a time: binary when the vertex
// element has fixed-size records and follows only fixed-size elements, ASCII always (a window
// of lines, ply_ascii_stream.cpp); null for other binary files (lists before or in the vertex
// element), which the caller reads whole. Throws what read_ply throws for a bad header or a
// file too short for its vertices.
std::unique_ptr<PointStream> open_ply_stream(const std::string& path,
                                             const PointReadOptions& options);

// The faces of a PLY file (binary or ASCII, plain or gzip) as a stream, a binary file's windows
// of at most `window_bytes`; null for a file without faces. Throws what read_ply throws for a
// bad header.
std::unique_ptr<FaceStream> open_ply_face_stream(const std::string& path,
                                                 std::size_t window_bytes);

// The faces of an OBJ file (plain or gzip) as a stream, checked as read_obj checks them; null
// for a file without `f` lines.
std::unique_ptr<FaceStream> open_obj_face_stream(const std::string& path);

// A LAS file (plain or gzip), read a window of records at a time after one pass over all of
// them (the origin and the colour scale, as read_las finds them). Throws what read_las throws.
std::unique_ptr<PointStream> open_las_stream(const std::string& path,
                                             const PointReadOptions& options);

// A text point file (XYZ, PTS, CSV, TXT; gzip too), read a window of lines at a time after one
// pass over all of them at open (the point count, and the values' statistics that read_xyz uses
// to tell normals from colours and a colour scale). Throws what read_xyz throws.
std::unique_ptr<PointStream> open_xyz_stream(const std::string& path,
                                             const PointReadOptions& options);

// A Wavefront OBJ file (gzip too), its `v` lines read a window of lines at a time after one
// pass over all of them at open (the count, the origin, the colours' presence and scale, and
// whether faces make it a mesh). Throws what read_obj throws for a bad vertex line.
std::unique_ptr<PointStream> open_obj_stream(const std::string& path,
                                             const PointReadOptions& options);

// The point count a LAS file's header states (checked as read_las checks it: every record must
// be in the file; for gzip data, what it can inflate to). Throws what read_las throws for a bad
// header.
std::optional<std::uint64_t> las_header_point_count(const std::string& path);

// Sizes `batch` for `n` points of a stream: positions, and normals, colours and radii as `info`
// has them; no triangles or comments.
inline void size_batch(PointSet& batch, std::size_t n, const PointStreamInfo& info) {
  batch.positions.resize(n);
  batch.normals.resize(info.has_normals ? n : 0);
  batch.colors.resize(info.has_colors ? n : 0);
  batch.radii.resize(info.has_radii ? n : 0);
  batch.triangles.clear();
  batch.comments.clear();
}

// The bytes of a window: enough for a few million records without holding many at once.
inline constexpr std::size_t kStreamWindowBytes = std::size_t{32} << 20;

}  // namespace pointillist::io_detail
