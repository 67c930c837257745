// Splat normals: from mesh faces, or by PCA over k nearest neighbours with a consistent
// orientation (Hoppe, DeRose, Duchamp, McDonald, Stuetzle, "Surface reconstruction from
// unorganized points", SIGGRAPH 1992).
#pragma once

#include <span>
#include <vector>

#include "pointillist/core/point_set.hpp"
#include "pointillist/core/progress.hpp"
#include "pointillist/core/thread_pool.hpp"

namespace pointillist {

// Area-weighted vertex normals of a triangle mesh (sum of the unnormalized face normals of the
// incident triangles, normalized). Vertices without faces get (0, 0, 1)... see .cpp.
std::vector<Vec3f> mesh_vertex_normals(std::span<const Vec3f> positions,
                                       std::span<const std::array<std::uint32_t, 3>> triangles,
                                       ThreadPool& pool);

struct PcaNormalOptions {
  std::uint32_t k = 16;  // neighbours for the covariance; more smooths noise, blurs edges
};

// Normals of a bare point cloud: the smallest-eigenvalue eigenvector of the covariance of the k
// nearest neighbours, then oriented consistently by propagation along a minimum spanning tree of
// the k-neighbour graph (edge weight 1 - |n_i·n_j|), seeded in each connected component by the
// point farthest from the centroid, whose normal is made to face away from the centroid.
std::vector<Vec3f> pca_normals(std::span<const Vec3f> positions, ThreadPool& pool,
                               Progress& progress = Progress::none(),
                               const PcaNormalOptions& options = {});

}  // namespace pointillist
