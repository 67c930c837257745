// The preparation stage: give every sample a normal and a splat radius.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "pointillist/core/point_set.hpp"
#include "pointillist/core/progress.hpp"
#include "pointillist/core/thread_pool.hpp"
#include "pointillist/prep/radii.hpp"

namespace pointillist {

enum class NormalSource {
  Auto,  // keep the file's normals; else mesh normals for a mesh; else PCA
  Keep,  // the file's normals, normalized (error if there are none)
  Mesh,  // area-weighted vertex normals of the faces (error without faces)
  Pca,   // PCA of the k nearest neighbours, oriented by MST propagation (pca_normals)
};

struct PrepareOptions {
  NormalSource normals = NormalSource::Auto;
  std::uint32_t k = 16;  // points per PCA neighbourhood, itself included; >= 3 (PcaNormalOptions)
  // Multiplies every computed radius and the radii read from the file; > 0. Raise it to close
  // holes in sparse scans, lower it for crisper (but possibly holey) renderings.
  float radius_scale = 1.0f;
  // Point clouds without radii: radius = mean 5-NN distance × coverage × radius_scale; > 0.
  // See kDefaultCloudCoverage for how the default was chosen.
  float coverage = kDefaultCloudCoverage;
  // Cap on an isolated point's radius relative to its neighbours' (CloudRadiusOptions); 0 = off.
  float outlier_ratio = kDefaultOutlierRatio;
  // First drop a point cloud's outliers (remove_outliers, outliers.hpp): points whose neighbours
  // are on average more than outlier_ratio times as far as theirs are (> 1; lower drops more).
  // Off by default: it removes data. Not for meshes.
  bool drop_outliers = false;
  float outlier_ratio_drop = 3.0f;
  // The point PCA normals are oriented away from (normal_orientation.cpp). Unset: the centroid
  // of the points. A part of a larger cloud (a chunk) passes the whole cloud's centroid, so its
  // normals are oriented as they would be in the whole.
  std::optional<Vec3f> orientation_centre;
  // When set and the normals are found by PCA: each point's connected component of the
  // orientation graph (components are oriented each on its own), in the points' order.
  std::vector<std::uint32_t>* orientation_components = nullptr;
  // When set and a neighbour search ran (PCA normals or radii of a cloud): the points' Morton
  // order it made (morton_order of the prepared points), for build_sphere_tree to reuse
  // (SphereTreeOptions::morton_order); else left as it is.
  std::vector<std::uint32_t>* morton_order = nullptr;
  // Names the input in error messages (e.g. the file path).
  std::string input_name = "the input";
};

// Fills points.normals (unit length) and points.radii (world units), after dropping a cloud's
// outliers when drop_outliers is set:
//  - normals as chosen by options.normals (NormalSource);
//  - radii: the file's radii × radius_scale when present, else mesh_radii for a mesh, else
//    cloud_radii.
// For a mesh, vertices used by no face are removed first (as QSplat does) together with their
// normals, colors and radii, and the faces are renumbered; a point set with no faces at all is a
// point cloud and keeps every point. Comments are kept.
// Throws OptionError for bad options (outlier removal asked for a mesh among them), and Error (saying what to do) when the input has no points,
// a non-finite coordinate, an attribute array of the wrong length or a face index out of range,
// or when the requested normal source is impossible: Keep without normals in the input, Mesh
// without faces, Pca (or Auto needing PCA) with fewer than 3 points.
// Progress phases: "normals" (or "neighbours", "normals", "orientation" for PCA), "radii".
// Deterministic for any thread count.
void prepare_splats(PointSet& points, ThreadPool& pool, Progress& progress,
                    const PrepareOptions& options = {});

// The part of prepare_splats that needs a mesh's faces, for a mesh converted in chunks (whose
// chunks hold points only): checks the mesh and drops its unused vertices as prepare_splats
// does, fills normals (the file's with Keep or Auto when it has them, the faces' with Mesh or
// Auto; left empty with Pca, which the chunks compute) and radii (the file's when present, else
// mesh_radii with scale 1: the chunks apply radius_scale), then drops the faces. The result,
// prepared again by prepare_splats with the same options, has the normals and radii the mesh
// would get in one piece (the normals up to a second normalization). Throws as prepare_splats
// (OptionError for drop_outliers on a mesh).
void prepare_mesh_vertices(PointSet& mesh, ThreadPool& pool, Progress& progress,
                           const PrepareOptions& options = {});

}  // namespace pointillist
