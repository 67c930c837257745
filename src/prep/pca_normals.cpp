// Normals of a bare point cloud by principal component analysis of each point's k nearest
// neighbours: Hoppe, DeRose, Duchamp, McDonald, Stuetzle, "Surface reconstruction from
// unorganized points", SIGGRAPH 1992, section 3.2 (tangent planes), oriented as in section 3.3
// (see normal_orientation.cpp).
#include <algorithm>
#include <cmath>

#include "pointillist/core/error.hpp"
#include "pointillist/prep/normals.hpp"
#include "ordered_cloud.hpp"

namespace pointillist {
namespace {

// The unit eigenvector of the smallest eigenvalue λ1 of the symmetric 3x3 matrix
// {a00 a01 a02 a11 a12 a22} (positive semi-definite, not zero). λ1 is the smallest root of the
// characteristic cubic det(A - λI), whose roots are all real; Newton's method started left of
// the smallest root of such a polynomial (here at 0) increases to it without overshooting. It
// stops when a step no longer moves λ, or when rounding puts det(A - λI) at or below 0. Near a
// plane λ1 is almost 0 and the first step almost lands. The columns of the adjugate of
// A - λ1 I (cross products of its rows) then all lie along the eigenvector; the longest is
// taken, and multiplied by the adjugate once more: a step of inverse iteration (the adjugate is
// the inverse times the determinant), which shrinks what an inexact λ1 let in of the other
// eigenvectors by the same factor again.
// Measured against Eigen's iterative solver on the same matrices (covariances of 16 float points
// spread 1 : w : w/1000 in random orientations): within 7e-8 rad for w down to 1e-3, where
// Eigen's closed form (trigonometric roots, two kernels) is within 5e-8 for w = 0.1 but 2e-3 rad
// off at w = 1e-3; on every 50th point of a 5 M scan and of the dragon's vertices, within 6e-8
// (Eigen's closed form: 6e-5 on the dragon). Half the time of Eigen's closed form.
Vec3f smallest_eigenvector(const double (&c)[6]) {
  const double scale = std::max({std::abs(c[0]), std::abs(c[1]), std::abs(c[2]),
                                 std::abs(c[3]), std::abs(c[4]), std::abs(c[5])});
  const double s = 1.0 / scale;  // entries at most 1 in magnitude
  const double a00 = c[0] * s, a01 = c[1] * s, a02 = c[2] * s;
  const double a11 = c[3] * s, a12 = c[4] * s, a22 = c[5] * s;
  // det(A - λI) = -λ³ + t λ² - m λ + d.
  const double t = a00 + a11 + a22;
  const double m = a00 * a11 - a01 * a01 + a00 * a22 - a02 * a02 + a11 * a22 - a12 * a12;
  const double d = a00 * (a11 * a22 - a12 * a12) - a01 * (a01 * a22 - a12 * a02) +
                   a02 * (a01 * a12 - a11 * a02);
  double lambda = 0;
  for (int step = 0; step < 100; ++step) {
    const double p = ((t - lambda) * lambda - m) * lambda + d;
    const double slope = (2 * t - 3 * lambda) * lambda - m;
    if (!(p > 0) || !(slope < 0)) break;
    const double next = lambda - p / slope;
    if (!(next > lambda)) break;
    lambda = next;
  }
  const Vec3d rows[3] = {
      {a00 - lambda, a01, a02}, {a01, a11 - lambda, a12}, {a02, a12, a22 - lambda}};
  const Vec3d adjugate[3] = {cross(rows[1], rows[2]), cross(rows[2], rows[0]),
                             cross(rows[0], rows[1])};
  int longest = 0;
  for (int i = 1; i < 3; ++i) {
    if (dot(adjugate[i], adjugate[i]) > dot(adjugate[longest], adjugate[longest])) longest = i;
  }
  Vec3d n;
  // m is about λ2·λ3: below 1e-10 t², the points lie on a line (or are thinner across it than
  // their rounding), and the adjugate would be mostly rounding. Any direction across the line
  // (the longest row of A - λ1 I) will do: across the axis it leans on least.
  if (!(m > 1e-10 * t * t) || !(dot(adjugate[longest], adjugate[longest]) > 0)) {
    const Vec3d* line = &rows[0];
    for (const Vec3d& r : rows) {
      if (dot(r, r) > dot(*line, *line)) line = &r;
    }
    const Vec3d& l = *line;
    if (!(dot(l, l) > 0)) return {0, 0, 1};
    const double ax = std::abs(l.x), ay = std::abs(l.y), az = std::abs(l.z);
    const Vec3d axis = ax <= ay && ax <= az ? Vec3d{1, 0, 0}
                       : ay <= az           ? Vec3d{0, 1, 0}
                                            : Vec3d{0, 0, 1};
    n = cross(l, axis);
  } else {
    const Vec3d& b = adjugate[longest];  // the adjugate is symmetric: rows or columns alike
    n = {dot(adjugate[0], b), dot(adjugate[1], b), dot(adjugate[2], b)};
  }
  const double k = 1.0 / std::sqrt(dot(n, n));
  return normalized(Vec3f{float(n.x * k), float(n.y * k), float(n.z * k)});
}

}  // namespace

PcaPlane pca_plane(std::span<const Vec3f> positions, std::size_t self,
                   std::span<const std::uint32_t> neighbours) {
  const Vec3f origin = positions[self];
  double s[3] = {0, 0, 0};
  double ss[6] = {0, 0, 0, 0, 0, 0};  // xx xy xz yy yz zz
  for (const std::uint32_t i : neighbours) {
    // In double: exact (a float difference is not, where the two straddle a power of 2 or
    // zero, and that rounding tilted the normals of thin strips by 4e-6 rad at 1 : 0.01).
    const double x = double(positions[i].x) - origin.x;
    const double y = double(positions[i].y) - origin.y;
    const double z = double(positions[i].z) - origin.z;
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
  double c[6] = {ss[0] * inv - mx * mx, ss[1] * inv - mx * my, ss[2] * inv - mx * mz,
                 ss[3] * inv - my * my, ss[4] * inv - my * mz, ss[5] * inv - mz * mz};
  const double trace = c[0] + c[3] + c[5];
  if (!(trace > 0.0) || !std::isfinite(trace + c[1] + c[2] + c[4])) {
    return {mean, {0, 0, 1}};  // all neighbours coincide
  }
  return {mean, smallest_eigenvector(c)};
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
