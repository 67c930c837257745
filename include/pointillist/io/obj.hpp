// Wavefront OBJ meshes (the geometry part: vertices, vertex normals, polygonal faces).
#pragma once

#include <string>

#include "pointillist/core/point_set.hpp"
#include "pointillist/core/progress.hpp"

namespace pointillist {

struct ObjReadOptions {
  // Read per-vertex colors (`v x y z r g b`, as MeshLab and photogrammetry tools write them)
  // into PointSet::colors. Off: ignore them.
  bool read_colors = true;
};

// Reads an OBJ file (`.gz` is decompressed transparently) into a PointSet with one point per
// `v` line and the faces in PointSet::triangles.
//
// `v x y z [w]` (w ignored) or `v x y z r g b`: colors are 0..1 floats (0..255 when a value
// exceeds 1); they are kept only when every vertex has them. `vn` lines are normals; `f` lines
// take corners `v`, `v/vt`, `v//vn` or `v/vt/vn` with 1-based indices, or negative ones counting
// back from the last vertex (normal) defined so far; polygons are fan-triangulated (v0, vk,
// vk+1) and faces with fewer than 3 corners are skipped. A positive index may refer to a vertex
// defined further down the file.
//
// Normals: each vertex gets the normals its face corners reference (`//vn`), averaged when they
// differ, then normalized. A vertex no corner gives a normal takes the area-weighted normal of
// its faces, and (0, 0, 1) when it has none. Without `vn` references, normals stay empty.
//
// Ignored: texture coordinates (vt), groups and objects (g, o), smoothing (s), materials
// (usemtl, mtllib), points and lines (p, l), free-form geometry, comments (#).
//
// Large coordinates: as read_xyz (an "origin: X Y Z" comment when the first vertex has a
// coordinate of magnitude 65536 or more).
//
// Progress: one phase "read", total = the file's size in bytes.
// Throws FormatError naming the file and the line for bad numbers, a `v` line with other than
// 3, 4 or 6 values, non-finite coordinates, index 0, indices out of range, and files without
// vertices; IoError when the file cannot be read.
PointSet read_obj(const std::string& path, Progress& progress = Progress::none(),
                  const ObjReadOptions& options = {});

}  // namespace pointillist
