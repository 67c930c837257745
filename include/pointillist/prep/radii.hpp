// Splat radii.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "pointillist/core/point_set.hpp"
#include "pointillist/core/progress.hpp"
#include "pointillist/core/thread_pool.hpp"

namespace pointillist {

// QSplat's rule for meshes, as its preprocessor applies it: each radius is the largest, over the
// triangles incident to the vertex, of the radius of the triangle's smallest enclosing circle
// (half the longest edge for a right or obtuse triangle, the circumradius otherwise), times
// `scale` (world units). Spheres of two vertices joined by an edge therefore at least touch, and
// unlike "half the longest incident edge" (which leaves a gap at the centre of every acute
// triangle: 0.577 vs 0.5 edge lengths for an equilateral one) the splats cover every triangle. Vertices
// in no triangle get 0. Preconditions: every index < positions.size(). Parallel; the result does
// not depend on the thread count.
std::vector<float> mesh_radii(std::span<const Vec3f> positions,
                              std::span<const std::array<std::uint32_t, 3>> triangles, float scale,
                              ThreadPool& pool);

// The radius mesh_radii gives a triangle's corners: of the smallest circle enclosing (a, b, c),
// in double, rounded to float. For callers that walk the faces themselves (a mesh streamed
// from disk).
float enclosing_circle_radius(Vec3f a, Vec3f b, Vec3f c);

// Default coverage factor of cloud radii, chosen by measurement. On spheres, tori and the demo
// scene sampled uniformly at random (Poisson) with 2k to 200k samples, discs of radius
// mean-5-NN-distance × c (centred on the samples, in their tangent planes) leave part of the
// surface uncovered unless c >= 1.1 (99% covered), 1.4 (99.9%), 1.6 (99.99%), and up to 2.1 for
// every one of 2M-20M random probe points (1.7-2.0 at 2k-20k samples; the worst gap grows slowly
// with the sample count). 2.5 keeps a margin of about 20% (tests/prep/cloud_radii_test.cpp checks
// it). Such discs also cover circle splats seen from any side: a circle is never smaller than the
// projected disc.
inline constexpr float kDefaultCloudCoverage = 2.5f;

// Default cap on a cloud radius relative to its neighbours' (see CloudRadiusOptions).
// 4 leaves randomly (Poisson) sampled surfaces covered as measured above (the coverage tests
// run with the cap on); 3 already caps some points of a random sample when few neighbours are used.
inline constexpr float kDefaultOutlierRatio = 4.0f;
// The outlier cap compares a point with this many nearest neighbours: enough to reach past a
// small cluster of stray points to the surface they float beside.
inline constexpr std::uint32_t kOutlierNeighbours = 15;

struct CloudRadiusOptions {
  std::uint32_t neighbours = 5;  // the mean distance to this many nearest neighbours is measured
  // Radius = mean distance × coverage × scale. The default closes the holes between the discs of
  // a uniformly (randomly) sampled surface (see kDefaultCloudCoverage); raise it for sparse or
  // uneven scans, lower it for samples on a regular grid (0.75 covers a square grid).
  float coverage = kDefaultCloudCoverage;
  float scale = 1.0f;  // the user's --radius-scale
  // Isolated points (stray returns, a leaf far from the rest) would get discs as large as the
  // gap to the main cloud. Each point's mean distance is capped at outlier_ratio × the median
  // of the mean distances of its kOutlierNeighbours nearest neighbours (so a small cluster of
  // strays is compared with the surface around it) before the coverage factor is applied. A point in a
  // uniformly sparse region is not affected (its neighbours are as sparse); only a point much
  // sparser than its own neighbours is. 0 = no cap.
  float outlier_ratio = kDefaultOutlierRatio;
};

// Radius of each point of a cloud (world units): the mean distance to its `neighbours` nearest
// other points (capped at outlier_ratio × the median of the same for its kOutlierNeighbours
// nearest) × coverage × scale. Points whose neighbours all coincide with them get 0.
// Throws OptionError when neighbours == 0, Error when a position is not finite. Progress phases
// "neighbours", "radii". Deterministic for any thread count.
std::vector<float> cloud_radii(std::span<const Vec3f> positions, ThreadPool& pool,
                               Progress& progress = Progress::none(),
                               const CloudRadiusOptions& options = {});

}  // namespace pointillist
