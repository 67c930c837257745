// QSplat model files `.qs`, version 1.1 (Rusinkiewicz & Levoy, "QSplat: A Multiresolution Point
// Rendering System for Large Meshes", SIGGRAPH 2000; file layout and the QSplat 1.0
// preprocessor as restated in ../shared/specs/qsplat-qs-format.md, cited below as "spec §n").
//
// A .qs file is a chain of fragments (comment text or a complete bounding-sphere tree); nodes are
// 4-byte records (6 with colour) holding a sphere quantized against the parent's, a quantized
// normal, a 2-bit normal-cone width and an optional RGB 565 colour, in breadth-first groups.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "pointillist/core/math.hpp"
#include "pointillist/core/point_set.hpp"
#include "pointillist/lod/sphere_tree.hpp"

namespace pointillist {

// Bits of a fragment header's options word (spec §2.1).
constexpr std::uint32_t kQsOptionColor = 1;    // records carry RGB 565 (6 bytes instead of 4)
constexpr std::uint32_t kQsOptionComment = 2;  // a comment fragment, not a tree

// One fragment as found in the file.
struct QsFragment {
  std::uint64_t offset = 0;   // byte offset of the fragment in the file
  std::uint32_t length = 0;   // fragment length in bytes (header, tree and padding)
  bool is_comment = false;
  std::uint32_t options = 0;  // the header's options word
  // Tree fragments only:
  std::uint32_t leaf_count = 0;        // from the header (checked against the decoded tree)
  Sphere root;                         // the header's float32 root sphere
  std::uint32_t root_child_count = 0;  // 2..4
  std::uint32_t padding = 0;           // bytes after the last group (0..3)
};

// Raw counts of the records as stored, before the enclosure fix (except the last two fields).
// "Records" are the stored nodes below the fragment roots; the roots (header spheres) are not
// records. Sums over all tree fragments.
struct QsStats {
  std::uint64_t leaf_count = 0;    // records without children
  std::uint64_t record_count = 0;  // all records
  // records_per_level[i]: records i + 1 levels below their fragment's root.
  std::vector<std::uint64_t> records_per_level;
  // Records by number of children: [0] leaves, [2], [3], [4]; [1] is always 0.
  std::array<std::uint64_t, 5> child_count_histogram{};
  std::array<std::uint64_t, 4> cone_code_histogram{};  // records by 2-bit cone code K
  // Records whose decoded sphere is not inside their decoded parent's (the root's for level 1):
  // |c - c_parent| + r > r_parent·(1 + 1e-5), evaluated in double. The format allows this (spec
  // §4.3). The tolerance leaves out spheres that touch the parent from inside and stick out only
  // by float rounding (187 in the 5,205-point dragon; any tolerance from 1e-6 to 1e-3 counts
  // the same 1,428 records there).
  std::uint64_t records_outside_parent = 0;
  // Records with sphere code 8191, which QSplat 1.0 writes when a child sticks out of its
  // decoded parent into a cube its table lacks (spec §4.3); decoded, as QSplat 1.0's viewer
  // does, to the parent's centre with radius 0. Two leaves of the twice-subdivided dragon.
  std::uint64_t out_of_table_records = 0;
  // The enclosure fix (read_qs): interior nodes (roots included) whose radius was enlarged to
  // enclose their children, and whose normal cone was widened to cover their children's cones.
  std::uint64_t spheres_enlarged = 0;
  std::uint64_t cones_widened = 0;
};

// A decoded .qs file.
struct QsModel {
  // The whole hierarchy, breadth-first, ready for render(): node 0 is the root (the header
  // sphere; with several tree fragments, a node added above their roots), records follow in
  // file order. Centres and radii are the decoded spheres, enlarged bottom-up so every node
  // encloses its children's spheres (the renderer's culling relies on it); normals are the
  // decoded 14-bit normals (roots: normalized mean of their children's); cone_sin is the decoded
  // bound ((K + 1)/4)² for K < 3 and 2 (no bound) for K = 3, widened bottom-up to cover the
  // children's cones around the decoded normals; leaves have cone_sin 0; colors are the 565
  // colors expanded by bit replication (roots: truncated means of their children's).
  // bounds / view_sphere: box around the leaf centres and the largest distance from its centre.
  SphereTree tree;
  std::vector<QsFragment> fragments;  // in file order
  std::string comments;               // text of all comment fragments, zero padding removed
  QsStats stats;
  std::uint64_t file_size = 0;

  // Multi-line "key: value" summary for `info`: fragments, comments, records, and what the
  // enclosure fix changed.
  std::string metadata() const;
};

// Reads, validates and decodes a whole .qs file (every fragment). Validation covers magic,
// version, fragment lengths, options, the root header, every group's position (each group must
// begin where the previous one ended, where its parent's pointer says), record counts against
// the fragment end, sphere codes (0..7620, and 8191: see QsStats::out_of_table_records),
// child-count/grandchild bits and the header's leaf count. Normal codes 16224..16383 decode to
// (0, 0, 1), as in QSplat 1.0.
// Throws FormatError "<path>: byte <offset>: <what was expected, what was found>" for any
// malformed, truncated or corrupt input (never reads out of bounds, never loops), and IoError
// when the file cannot be read.
QsModel read_qs(const std::string& path);

// True when the file starts with the .qs magic "QSplat" (dispatch on content, not extension).
bool is_qs_file(const std::string& path);

struct QsWriteOptions {
  // Store per-node colours (6-byte records) when the input has colors. Off: 4-byte records.
  bool write_colors = true;
  // Write PointSet::comments as a comment fragment before the tree, as QSplat 1.0 does.
  bool write_comments = true;
  // Normals are dithered by ±1/52 per component before quantizing (breaks up banding, spec
  // §5.2) with glibc's rand() sequence for this seed; QSplat 1.0 never seeds it, i.e. seed 1,
  // which is needed for byte-identical files. 0 is treated as 1 (as glibc does).
  std::uint32_t dither_seed = 1;
  bool dither_normals = true;  // off: every normal goes to its nearest grid cell
};

// What write_qs did.
struct QsWriteReport {
  std::uint64_t input_points = 0;
  std::uint64_t leaf_count = 0;      // points kept (the rest used by no face or of radius 0)
  std::uint64_t record_count = 0;    // node records below the root
  std::uint64_t file_size = 0;       // bytes
  std::uint32_t depth = 0;           // levels below the root
};

// Writes `mesh` as a .qs 1.1 file the way QSplat 1.0's `qsplat_make` does (spec §8), so the
// bytes equal the original's for the same input (read with read_ply: float positions, faces in
// file order, diffuse colours, comments):
//  - a mesh (triangles present): per-vertex area-weighted normals and splat radii from the faces
//    (spec §8.2; normals and radii in the PointSet are ignored, as the original does), dropping
//    vertices used by no face or of radius 0;
//  - a point set without faces: its own normals (unit) and radii, which must be present (e.g.
//    from prepare_splats); points of radius 0 are dropped.
// Then the midpoint-split hierarchy (§8.3-8.4), quantized breadth-first against the decoded
// parents (§4.3-4.4, §5.2, §6, §7), one tree fragment after an optional comment fragment. Like
// the original, a child that sticks out of its decoded parent into a cube the sphere table lacks
// gets sphere code 8191 (see QsStats::out_of_table_records); read_qs accepts it.
// Written to a temporary file in the same folder and renamed, so a failure never leaves a
// partial file. Throws Error when fewer than 2 points remain, an attribute array's length is
// wrong, a triangle index is out of range, a coordinate, normal or radius is not finite, or the
// fragment would exceed 2^31 - 1 bytes (about 300 million points); IoError naming the file.
QsWriteReport write_qs(const std::string& path, const PointSet& mesh,
                       const QsWriteOptions& options = {});

}  // namespace pointillist
