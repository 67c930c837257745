// One entry point for every supported input: picks the reader by the file's extension.
#pragma once

#include <array>
#include <optional>
#include <string>

#include "pointillist/core/point_set.hpp"
#include "pointillist/core/progress.hpp"

namespace pointillist {

class ThreadPool;

struct PointReadOptions {
  // Read colors when the file has them. Off: PointSet::colors stays empty.
  bool read_colors = true;
  // Optional pool for the readers that use one (PLY, text, LAS). Null: the calling thread.
  ThreadPool* pool = nullptr;
  // Text files only (.xyz .pts .csv .txt): what each column holds, e.g. "x,y,z,skip,r,g,b"
  // (see XyzReadOptions::columns). Empty: detect.
  std::string columns = {};
};

// Reads `path` with the reader its extension names (case-insensitive):
//   .ply .ply.gz                                  read_ply
//   .xyz .pts .csv .txt, and the same with .gz   read_xyz
//   .obj .obj.gz                                  read_obj
//   .las .las.gz                                  read_las
// Throws FormatError for .laz (compressed LAS is not supported yet; the message says how to
// decompress) and for any other extension (the message lists the supported ones), and whatever
// the chosen reader throws.
PointSet read_point_file(const std::string& path, Progress& progress = Progress::none(),
                         const PointReadOptions& options = {});

// True when read_point_file has a reader for `path`'s extension (.laz is false).
bool is_point_file_extension(const std::string& path);

// True when `path`'s format can hold faces (PLY and OBJ, plain or .gz): only these can be meshes.
bool may_hold_faces(const std::string& path);

// The supported extensions, for messages and help texts: ".ply, .ply.gz, .xyz, ...".
std::string supported_point_file_extensions();

// The origin recorded by the text, OBJ and LAS readers as the comment "origin: X Y Z"
// (absolute coordinates = origin + position), or nothing when positions are absolute. Tools
// that merge several files must add each file's origin (or the difference of origins) to its
// positions, or the parts will not line up.
std::optional<std::array<double, 3>> point_set_origin(const PointSet& points);

}  // namespace pointillist
