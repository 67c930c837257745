// Splat normals: from mesh faces, or by PCA over k nearest neighbours with a consistent
// orientation (Hoppe, DeRose, Duchamp, McDonald, Stuetzle, "Surface reconstruction from
// unorganized points", SIGGRAPH 1992).
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "pointillist/core/point_set.hpp"
#include "pointillist/core/progress.hpp"
#include "pointillist/core/thread_pool.hpp"

namespace pointillist {

// Area-weighted vertex normals of a triangle mesh: the sum of the unnormalized face normals
// cross(b - a, c - a) of the incident triangles, normalized, so the normals follow the winding
// (counter-clockwise seen from outside gives outward normals). Vertices in no triangle, or only in
// triangles of zero area, get (0, 0, 1). Preconditions: every index < positions.size().
// Parallel; the result is the same bits for any thread count. Memory: 24 bytes per face.
std::vector<Vec3f> mesh_vertex_normals(std::span<const Vec3f> positions,
                                       std::span<const std::array<std::uint32_t, 3>> triangles,
                                       ThreadPool& pool);

// The least-squares plane of positions[self] and its neighbours (indices into positions, self not
// among them): their mean, and the unit eigenvector of the smallest eigenvalue of their covariance
// ((0, 0, 1) when they all coincide). Coordinates are taken relative to positions[self] and
// summed in double, so scans far from the origin lose no precision. What pca_normals computes per
// point (its normal, before orientation); the surface-error metric's local planes of a cloud.
struct PcaPlane {
  Vec3f mean;
  Vec3f normal;
};
PcaPlane pca_plane(std::span<const Vec3f> positions, std::size_t self,
                   std::span<const std::uint32_t> neighbours);

struct PcaNormalOptions {
  // Points in each covariance, the point itself included (so k - 1 neighbours); the orientation
  // graph takes the nearest min(k - 1, 10) of them. More smooths noise but blurs sharp edges;
  // fewer follows thin features.
  std::uint32_t k = 16;
};

// Normals of a bare point cloud: the eigenvector of the smallest eigenvalue of the covariance of
// each point and its k - 1 nearest neighbours, then oriented consistently by propagation along
// spanning trees of smooth edges of the symmetrized min(k - 1, 10)-neighbour graph (edge weight
// 1 - |n_i·n_j|; a child is flipped when n_child·n_parent < 0): minimum spanning trees inside
// pieces of 16,384 points in Morton order, grown in parallel, then the pieces' components joined
// strongest evidence first (summed n_u·n_v over the edges between them). Each joined surface
// then faces away from the centroid of the whole cloud where most of its points say so: right
// for closed surfaces and for scans seen from outside.
// Unit length; points whose neighbours all coincide get (0, 0, 1) before orientation.
// Throws OptionError when k < 3, Error when there are fewer than 3 points or a position is not
// finite. Progress phases "neighbours", "normals", "orientation". Deterministic for any thread
// count. Memory: about 4·k + 60 bytes per point at the peak (the neighbour graph dominates;
// 1.25 GB for 10M points at k = 16). Time: every step is parallel.
std::vector<Vec3f> pca_normals(std::span<const Vec3f> positions, ThreadPool& pool,
                               Progress& progress = Progress::none(),
                               const PcaNormalOptions& options = {});

}  // namespace pointillist
