// Measured surface error of a set of splats (discs: centre, unit normal, radius) against a
// reference surface, the geometric metrics of specs/occlusion-simplification-hybrid.md §2.7,
// for `pointillist compare-surface`:
//   forward   each splat centre to the reference surface (its exact closest point);
//   backward  area-uniform samples of the reference, each to the nearest disc: with h = (s−c)·n
//             and t = |(s−c) − h·n|, the distance is |h| when t ≤ r, else √(h² + (t−r)²);
//             the nearest disc is found exactly (a bounding-volume hierarchy over the discs);
//   holes     samples that no disc covers (|h| ≤ hole_tolerance·diagonal and t ≤ r);
//   normals   the unsigned angle between a splat's normal and the reference normal at its
//             centre's closest point.
// All distances in world units (the caller scales by `diagonal` to report ×10⁻³ diagonal).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "pointillist/core/math.hpp"
#include "pointillist/core/thread_pool.hpp"
#include "pointillist/scene/analytic.hpp"

namespace pointillist {

// The surface a simplified point set is measured against. Built once, then queried from many
// threads (all queries are const). Movable, not copyable.
class SurfaceReference {
 public:
  // An analytic scene (sphere, torus, cube of generate --scene): exact distances
  // (closest_point). Keeps a copy of the scene. Throws Error when the scene has no shapes.
  static SurfaceReference analytic(const AnalyticScene& scene);
  // A triangle mesh: exact point-triangle distances through a bounding-volume hierarchy (median
  // splits on the longest axis, leaves of ≤ 4 triangles). Keeps copies. Throws Error when there
  // are no triangles, a position is not finite or a triangle names a vertex past the end.
  static SurfaceReference mesh(std::span<const Vec3f> positions,
                               std::span<const std::array<std::uint32_t, 3>> triangles,
                               ThreadPool& pool);
  // A point cloud without a mesh: each original point's local plane (through the mean of its k
  // nearest neighbours, itself included, normal along their covariance's least eigenvector); a
  // query's distance is the distance to the plane of its nearest original point (ties: lower
  // index). Throws OptionError when k < 3, Error with fewer than 3 points or a non-finite one.
  static SurfaceReference points(std::span<const Vec3f> positions, ThreadPool& pool,
                                 std::uint32_t k = 16);

  SurfaceReference(SurfaceReference&&) noexcept;
  SurfaceReference& operator=(SurfaceReference&&) noexcept;
  ~SurfaceReference();

  struct Closest {
    Vec3f point;   // nearest point of the reference surface (world)
    Vec3f normal;  // unit surface normal there, sign arbitrary
    float distance = 0;  // world units
  };
  Closest closest(Vec3f p) const;

  // `count` samples spread uniformly by area over the reference. Mesh: triangles chosen by area,
  // uniform barycentric coordinates; analytic: sample_scene(scene, count, seed); points: the
  // original points themselves, every ceil(n/count)-th when there are more than count (seed
  // unused). The same arguments give the same samples.
  std::vector<Vec3f> samples(std::size_t count, std::uint64_t seed) const;

  // Bounding-box diagonal of the reference (mesh, points: of their positions; analytic:
  // scene_bounds), world units.
  double diagonal() const;

  class Impl;  // one per kind of reference (surface_error.cpp)

 private:
  explicit SurfaceReference(std::unique_ptr<const Impl> impl);
  std::unique_ptr<const Impl> impl_;
};

struct SurfaceErrorOptions {
  // Reference samples of the backward distance and hole fraction (the spec: 2 M). Fewer run
  // faster; the hole fraction's sampling error is about √(f(1−f)/samples).
  std::size_t backward_samples = 2'000'000;
  // Seed of the reference samples (mesh and analytic references).
  std::uint64_t seed = 1;
  // × diagonal: the largest plane distance |h| at which a disc still covers a sample. Raise it
  // for noisy references, whose samples scatter off the discs' planes.
  double hole_tolerance = 0.01;
};

struct DistanceStats {
  double max = 0, mean = 0, rms = 0;  // world units
};

struct SurfaceError {
  DistanceStats forward;     // each splat centre to the reference surface
  DistanceStats backward;    // each reference sample to the nearest disc
  double hausdorff = 0;      // max(forward.max, backward.max)
  double hole_fraction = 0;  // share of reference samples that no disc covers
  // Unsigned angle between splat normal and reference normal at the centre's closest point,
  // degrees: mean and 95th percentile (nearest rank).
  double normal_mean_deg = 0, normal_p95_deg = 0;
  double diagonal = 0;  // reference.diagonal()
  std::size_t splats = 0, samples = 0;
};

// Forward and backward distances, holes and normal error of the discs (centers[i], normals[i],
// radii[i]) against `reference`. Normals need not be unit (they are normalised). Parallel over
// splats and samples; per-block sums are reduced in block order in double, so the result does
// not depend on the thread count. Throws Error when the spans differ in length or are empty, or
// a splat has a non-finite centre or normal, a zero normal or a radius that is not finite and
// >= 0; OptionError when options.backward_samples is 0.
SurfaceError surface_error(const SurfaceReference& reference, std::span<const Vec3f> centers,
                           std::span<const Vec3f> normals, std::span<const float> radii,
                           ThreadPool& pool, const SurfaceErrorOptions& options = {});

}  // namespace pointillist
