// Normals of a bare point cloud by principal component analysis of each point's k nearest
// neighbours: Hoppe, DeRose, Duchamp, McDonald, Stuetzle, "Surface reconstruction from
// unorganized points", SIGGRAPH 1992, section 3.2 (tangent planes), oriented as in section 3.3
// (see normal_orientation.cpp).
#include <Eigen/Eigenvalues>
#include <cmath>

#include "pointillist/core/error.hpp"
#include "pointillist/prep/normals.hpp"
#include "ordered_cloud.hpp"

namespace pointillist {

PcaPlane pca_plane(std::span<const Vec3f> positions, std::size_t self,
                   std::span<const std::uint32_t> neighbours) {
  const Vec3f origin = positions[self];
  double s[3] = {0, 0, 0};
  double ss[6] = {0, 0, 0, 0, 0, 0};  // xx xy xz yy yz zz
  for (const std::uint32_t i : neighbours) {
    const Vec3f d = positions[i] - origin;
    const double x = d.x, y = d.y, z = d.z;
    s[0] += x;
    s[1] += y;
    s[2] += z;
    ss[0] += x * x;
    ss[1] += x * y;
    ss[2] += x * z;
    ss[3] += y * y;
    ss[4] += y * z;
    ss[5] += z * z;
  }
  // The point itself adds d = 0: it counts in the mean but adds nothing to the sums.
  const double inv = 1.0 / double(neighbours.size() + 1);
  const double mx = s[0] * inv, my = s[1] * inv, mz = s[2] * inv;
  const Vec3f mean = origin + Vec3f{float(mx), float(my), float(mz)};
  Eigen::Matrix3d c;
  c(0, 0) = ss[0] * inv - mx * mx;
  c(0, 1) = c(1, 0) = ss[1] * inv - mx * my;
  c(0, 2) = c(2, 0) = ss[2] * inv - mx * mz;
  c(1, 1) = ss[3] * inv - my * my;
  c(1, 2) = c(2, 1) = ss[4] * inv - my * mz;
  c(2, 2) = ss[5] * inv - mz * mz;
  if (!(c.trace() > 0.0) || !c.allFinite()) return {mean, {0, 0, 1}};  // all neighbours coincide
  // Closed form (eigenvalues sorted increasing). In double its normals stay within 5e-8 rad of
  // Eigen's iterative solver on sampled spheres, tori and cubes (measured), far below the
  // sampling error of the normal itself, at a fraction of the cost.
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(c, Eigen::ComputeEigenvectors);
  const Eigen::Vector3d e = solver.eigenvectors().col(0);
  return {mean, normalized(Vec3f{float(e.x()), float(e.y()), float(e.z())})};
}

namespace prep_detail {
namespace {

constexpr std::size_t kGrain = 8192;

}  // namespace

std::vector<Vec3f> pca_normals_ordered(const OrderedCloud& cloud, std::uint32_t k, ThreadPool& pool,
                                       Progress& progress) {
  const std::size_t n = cloud.size();
  const std::size_t used = std::min<std::size_t>(k - 1, cloud.k);
  ProgressPhase phase(progress, "normals", n);
  std::vector<Vec3f> normals(n);
  parallel_for(pool, n, kGrain, [&](std::size_t begin, std::size_t end) {
    for (std::size_t j = begin; j < end; ++j) {
      normals[j] = pca_plane(cloud.positions, j, cloud.row(j).first(used)).normal;
    }
    phase.advance(end - begin);
  });
  return normals;
}

}  // namespace prep_detail

std::vector<Vec3f> pca_normals(std::span<const Vec3f> positions, ThreadPool& pool,
                               Progress& progress, const PcaNormalOptions& options) {
  if (options.k < 3) {
    throw OptionError("PCA normals: k = " + std::to_string(options.k) +
                      " neighbours cannot define a plane; use k >= 3 (16 is typical)");
  }
  if (positions.size() < 3) {
    throw Error("PCA normals: " + std::to_string(positions.size()) +
                " points cannot define a plane; PCA needs at least 3 points (give the file "
                "normals, or use mesh normals for a mesh)");
  }
  const prep_detail::OrderedCloud cloud =
      prep_detail::order_cloud(positions, options.k - 1, pool, progress);
  std::vector<Vec3f> normals = prep_detail::pca_normals_ordered(cloud, options.k, pool, progress);
  prep_detail::orient_normals_ordered(cloud, prep_detail::orientation_graph_k(options.k), normals,
                                      pool, progress);
  return prep_detail::to_caller_order<Vec3f>(cloud, normals, pool);
}

}  // namespace pointillist
