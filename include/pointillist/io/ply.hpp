// PLY 1.0 ("Polygon File Format", Greg Turk 1994) reader and writer.
#pragma once

#include <string>

#include "pointillist/core/point_set.hpp"
#include "pointillist/core/progress.hpp"

namespace pointillist {

struct PlyReadOptions {
  // Read `red green blue` / `diffuse_*` into PointSet::colors when present. Off: ignore colors.
  bool read_colors = true;
};

// Reads a PLY file (ascii, binary_little_endian or binary_big_endian; `.gz` is decompressed
// transparently, detected by its magic bytes). Understood vertex properties: x y z, nx ny nz,
// red green blue [alpha] (uchar or float) or diffuse_red/green/blue, radius or scale. Faces
// (`vertex_indices` or `vertex_index`) are fan-triangulated into PointSet::triangles. Unknown
// elements and properties are skipped.
// Throws FormatError naming the file and the line (ascii) or byte offset (binary) for malformed
// headers, truncated data, wrong counts, non-numeric tokens, out-of-range face indices,
// NaN/inf coordinates and files without vertices; IoError when the file cannot be read.
PointSet read_ply(const std::string& path, Progress& progress = Progress::none(),
                  const PlyReadOptions& options = {});

enum class PlyEncoding { BinaryLittleEndian, BinaryBigEndian, Ascii };

struct PlyWriteOptions {
  PlyEncoding encoding = PlyEncoding::BinaryLittleEndian;
  bool write_faces = true;  // write PointSet::triangles as a face element when present
};

// Writes positions and whichever of normals (nx ny nz), colors (red green blue, uchar), radii
// (radius) and triangles are present. Written to a temporary file and renamed, so a failure never
// leaves a partial file. Throws IoError.
void write_ply(const std::string& path, const PointSet& points,
               const PlyWriteOptions& options = {});

}  // namespace pointillist
