// The preparation stage: give every sample a normal and a splat radius.
#pragma once

#include <cstdint>

#include "pointillist/core/point_set.hpp"
#include "pointillist/core/progress.hpp"
#include "pointillist/core/thread_pool.hpp"

namespace pointillist {

enum class NormalSource {
  Auto,  // keep the file's normals; else mesh normals for a mesh; else PCA
  Keep,  // the file's normals (error if there are none)
  Mesh,  // area-weighted vertex normals of the faces (error without faces)
  Pca,   // PCA of the k nearest neighbours, oriented by MST propagation
};

struct PrepareOptions {
  NormalSource normals = NormalSource::Auto;
  std::uint32_t k = 16;         // neighbours for PCA normals
  float radius_scale = 1.0f;    // multiplies every computed radius (and radii read from the file)
  float coverage = 1.0f;        // point clouds: radius = mean 5-NN distance × coverage × scale
};

// Fills points.normals and points.radii (keeping the file's radii when present, scaled).
// Mesh vertices used by no face are removed (as QSplat does), and so are faces' references
// remapped. Throws Error with an explanation when the requested source is impossible.
void prepare_splats(PointSet& points, ThreadPool& pool, Progress& progress,
                    const PrepareOptions& options = {});

}  // namespace pointillist
