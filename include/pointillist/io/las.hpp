// ASPRS LAS 1.0 to 1.4 lidar point clouds (uncompressed; LAZ is refused with advice).
#pragma once

#include <string>

#include "pointillist/core/point_set.hpp"
#include "pointillist/core/progress.hpp"

namespace pointillist {

class ThreadPool;

struct LasReadOptions {
  // Read RGB (point formats 2, 3, 5, 7, 8, 10) into PointSet::colors. Off: ignore colors.
  bool read_colors = true;
  // Optional pool: records are decoded in parallel chunks. Null: the calling thread does all.
  // The result is the same either way.
  ThreadPool* pool = nullptr;
  // Subtract an origin from coordinates too large for float precision (see read_las). Off:
  // positions are the absolute coordinates rounded to float (georeferenced files then lose
  // precision: a UTM northing is kept to 0.5 m).
  bool shift_origin = true;
};

// Reads an uncompressed LAS file (versions 1.0 to 1.4, point data record formats 0 to 10;
// `.gz` is decompressed transparently). Positions are X * scale + offset from the public
// header, computed in double. Records longer than their format needs (extra bytes) are read;
// waveform packets, GPS time, intensity and classification are ignored. The point count is
// the 64-bit one of a 1.4 header when it is set, else the legacy 32-bit one.
//
// Origin: per axis, when the data's coordinates reach 2^23 times that axis's scale factor (a
// float could no longer hold every step of the file's grid), the minimum coordinate rounded
// down to a power of ten no larger than the data's extent is subtracted. The shift goes into
// PointSet::comments as "origin: X Y Z" (absolute = origin + position). Small coordinates (a
// local scan in metres with millimetre steps, below 8 km) are not shifted, so tiles of one
// scan keep one frame.
//
// Colors: the 16-bit values are scaled to 8 bits (v >> 8), except when no value in the file
// exceeds 255, when they are taken as 8-bit values already (as many writers store them). When
// every color is black the file has none in substance and colors stay empty.
// Comments: the version and point format, the system identifier and generating software, and
// the origin.
//
// Progress: one phase "read", total = the file's size in bytes.
// Throws FormatError naming the file and the byte offset for a missing "LASF" signature, an
// unsupported version or point format, a header or record length too small for its format,
// LAZ compression (with how to decompress), zero points, bad scale factors and files that end
// before the last record; IoError when the file cannot be read.
PointSet read_las(const std::string& path, Progress& progress = Progress::none(),
                  const LasReadOptions& options = {});

}  // namespace pointillist
