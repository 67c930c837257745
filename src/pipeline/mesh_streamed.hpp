// A mesh larger than memory prepared for the chunked conversion (private to pipeline;
// chunked_convert.cpp): its vertices with the normals and radii its faces give, found by
// streaming the faces past a file of per-vertex sums held a page at a time.
#pragma once

#include <cstdint>
#include <string>

#include "pointillist/core/progress.hpp"
#include "pointillist/prep/prepare.hpp"

namespace pointillist::chunking {

struct StreamedMeshOptions {
  // Memory for the vertices' pages (positions and sums, 28 bytes a vertex); at least 4 pages
  // are held whatever it says.
  std::uint64_t cache_bytes = std::uint64_t{256} << 20;
  // Vertices a page holds (tests make it small so that pages are written out and read back).
  std::uint64_t page_vertices = std::uint64_t{1} << 14;
};

// Writes to `output` (a binary PLY) what prepare_mesh_vertices makes of the mesh `input`, in
// memory bounded by `options.cache_bytes` and the streams' windows: the vertices used by some
// face, in file order, with the file's normals (a PLY's, or an OBJ's `vn` sums as read_obj
// makes them; bit for bit, but for corners that name a normal defined after them, which read_obj
// adds last) or the faces' area-weighted normals (normalized, bit for bit those of
// mesh_vertex_normals), or none for Pca, and the file's radii or the faces' enclosing-circle
// radii (mesh_radii with scale 1). `records` names scratch files (it, and with a suffix for an
// OBJ's normals), removed when done. Returns false,
// doing nothing, when the input has no face stream (no faces, or not PLY or OBJ). Throws as
// prepare_mesh_vertices and the readers do, IoError when the disk is full.
bool prepare_mesh_streamed(const std::string& input, const std::string& output,
                           const std::string& records, const PrepareOptions& prepare,
                           Progress& progress, const StreamedMeshOptions& options = {});

}  // namespace pointillist::chunking
