// PointSet: surface samples as a structure of arrays. An absent attribute is an empty array;
// a present one has exactly one entry per position.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "pointillist/core/math.hpp"

namespace pointillist {

struct PointSet {
  std::vector<Vec3f> positions;
  std::vector<Vec3f> normals;                     // unit length when present
  std::vector<Rgb8> colors;
  std::vector<float> radii;                       // splat radius, world units
  std::vector<std::array<std::uint32_t, 3>> triangles;  // mesh faces (fan-triangulated), may be empty
  std::vector<std::string> comments;              // header comments of the source file, for metadata
  // Where positions are relative to: absolute (georeferenced) = origin + position. Readers of
  // files with large coordinates (LAS, text, OBJ) move them next to the origin so that float
  // positions stay precise.
  std::array<double, 3> origin{};
  // The scan's up axis (unit): +Y by convention, +Z for LAS scans.
  Vec3f up{0, 1, 0};

  std::size_t size() const { return positions.size(); }
  bool has_normals() const { return !normals.empty(); }
  bool has_colors() const { return !colors.empty(); }
  bool has_radii() const { return !radii.empty(); }
  bool is_mesh() const { return !triangles.empty(); }
};

// Keeps the points i with keep[i] != 0 (keep.size() == points.size()), in order, with their
// normals, colors and radii; triangles are renumbered and those using a removed point dropped.
// Returns the number kept.
std::size_t keep_points(PointSet& points, std::span<const std::uint8_t> keep);

// Box around all positions (empty box for an empty set).
Aabb bounding_box(const std::vector<Vec3f>& positions);

// The view sphere used by orbit cameras (ARCHITECTURE.md): centre of the bounding box and the
// largest distance from it to a sample.
Sphere view_sphere(const std::vector<Vec3f>& positions);

}  // namespace pointillist
