// Point clouds as text: XYZ, PTS, CSV and TXT files with one point per line.
#pragma once

#include <string>

#include "pointillist/core/point_set.hpp"
#include "pointillist/core/progress.hpp"

namespace pointillist {

class ThreadPool;

struct XyzReadOptions {
  // Read colors into PointSet::colors when the file has them. Off: ignore color columns.
  bool read_colors = true;
  // Optional pool (2+ threads): files of a few MB and more are parsed in parallel pieces.
  // Null: everything runs on the calling thread. The result is the same either way.
  ThreadPool* pool = nullptr;
  // What each column holds, overriding the detection below: names separated by commas or
  // blanks, from x y z nx ny nz r g b (also red green blue) and skip (or _), e.g.
  // "x,y,z,skip,r,g,b" or "x y z nx ny nz". x, y and z are required; normals and colors need
  // all three. Columns after the last named one are ignored. Empty: detect.
  std::string columns = {};
};

// Reads a text point cloud (`.gz` is decompressed transparently, detected by its magic bytes).
//
// Lines: values separated by blanks (spaces, tabs), commas or semicolons, detected from the
// first point line (';' if it has one, else ',' if it has one, else blanks). Blank lines and
// lines starting with '#' or '//' are skipped. Before the first point line the file may have a
// header line of column names (e.g. "x y z r g b", "//X,Y,Z,R,G,B" as CloudCompare writes it)
// and a line holding a single integer (the point count of a PTS file; it is not checked).
//
// Columns: `options.columns` when given; else the header's names when they include x, y and z;
// else by the count on the first point line: 3 x y z; 4 x y z + one ignored (intensity);
// 6 x y z + normals or colors; 7 x y z intensity r g b (PTS); 9 x y z + normals and colors;
// 10 x y z intensity + normals and colors; any other count: x y z, the rest ignored. Whether a
// group of three is normals or colors is decided over the whole file (a negative value, or all
// rows of unit length, means normals); when both groups look alike they are taken as
// nx ny nz r g b. Without explicit columns or a header, every point line must have as many
// values as the first.
//
// Colors: 0..1 floats when no value exceeds 1 and some value has a decimal point or exponent;
// 0..65535 when a value exceeds 255; else 0..255 integers (clamped). Normals are normalized; a
// zero one becomes (0, 0, 1), and all-zero normals are dropped.
//
// Large coordinates: when the first point has a coordinate of magnitude 65536 or more, that
// axis is shifted by the coordinate rounded down to a multiple of 1000, and the shift is
// recorded as the comment "origin: X Y Z" (absolute = origin + position), so float positions
// keep their precision. PointSet::comments also says which columns were read.
//
// Progress: one phase "read", total = the file's size in bytes.
// Throws FormatError naming the file and the line for non-numeric or non-finite coordinates,
// lines with too few (or, without explicit columns, too many) values, and files without point
// lines; OptionError for a bad `columns` string; IoError when the file cannot be read.
PointSet read_xyz(const std::string& path, Progress& progress = Progress::none(),
                  const XyzReadOptions& options = {});

}  // namespace pointillist
