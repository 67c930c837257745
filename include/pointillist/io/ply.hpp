// PLY 1.0 ("Polygon File Format", Greg Turk 1994) reader and writer.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "pointillist/core/point_set.hpp"
#include "pointillist/core/progress.hpp"

namespace pointillist {

class ThreadPool;
class AtomicFile;

struct PlyReadOptions {
  // Read `red green blue` / `diffuse_*` into PointSet::colors when present. Off: ignore colors.
  bool read_colors = true;
  // Optional pool (2+ threads): large ascii bodies are parsed in parallel pieces, and a .gz file
  // is inflated on one thread while another parses. Binary bodies decode at memory speed on one
  // thread. Null: everything runs on the calling thread. The result is the same either way.
  ThreadPool* pool = nullptr;
};

// Reads a PLY file (ascii, binary_little_endian or binary_big_endian; `.gz` is decompressed
// transparently, detected by its magic bytes). Understood vertex properties: x y z (any scalar
// type, stored as float), nx ny nz (normalized; dropped when all are zero; a zero or non-finite
// normal among valid ones becomes (0, 0, 1)), red green blue (alpha ignored) or
// diffuse_red/green/blue, radius or scale. Colors: float/double are 0..1, ushort is 0..65535,
// other integer types are clamped to 0..255. Faces (`vertex_indices` or `vertex_index`) are
// fan-triangulated into PointSet::triangles; polygons with fewer than 3 vertices are skipped.
// `comment` lines go to PointSet::comments. Unknown elements and properties are skipped. Ascii
// bodies hold one element per line (blank lines are ignored).
// Progress: one phase "read", total = the file's size in bytes.
// Throws FormatError naming the file and the line (ascii) or byte offset (binary) for malformed
// headers, truncated data, wrong counts, non-numeric tokens, out-of-range face indices,
// NaN/inf coordinates or radii and files without vertices (for .gz files the byte offset is
// into the decompressed data); IoError when the file cannot be read.
PointSet read_ply(const std::string& path, Progress& progress = Progress::none(),
                  const PlyReadOptions& options = {});

enum class PlyEncoding { BinaryLittleEndian, BinaryBigEndian, Ascii };

struct PlyWriteOptions {
  PlyEncoding encoding = PlyEncoding::BinaryLittleEndian;
  bool write_faces = true;  // write PointSet::triangles as a face element when present
};

// Writes positions and whichever of normals (nx ny nz), colors (red green blue, uchar), radii
// (radius) and triangles (list uchar int vertex_indices) are present, all as float but colors,
// plus PointSet::comments as comment lines. Ascii floats use the shortest text that reads back
// as the same float. Written to `path + ".tmp-XXXXXX"` in the same folder and renamed, so a
// failure never leaves a partial file (the temporary is removed).
// Throws IoError naming the file; Error when an attribute array's length differs from the
// position count or a triangle indexes past the last position (nothing is written then).
void write_ply(const std::string& path, const PointSet& points,
               const PlyWriteOptions& options = {});

// A binary little-endian PLY of `count` points written batch by batch, in constant memory: the
// header (properties, comments, origin and up of `layout`, whose point count does not matter)
// first, then each batch's vertices, which must have the layout's properties. The file appears
// only when commit() finds all `count` points written (atomically, as write_ply). Throws Error
// for a batch that does not fit, IoError when writing fails.
class PlyPointWriter {
 public:
  PlyPointWriter(const std::string& path, const PointSet& layout, std::uint64_t count);
  ~PlyPointWriter();
  PlyPointWriter(const PlyPointWriter&) = delete;
  PlyPointWriter& operator=(const PlyPointWriter&) = delete;
  void write(const PointSet& batch);
  void commit();

 private:
  std::unique_ptr<AtomicFile> file_;
  std::string path_;
  std::uint64_t count_, written_ = 0;
  bool normals_, colors_, radii_;
};

}  // namespace pointillist
