// Point-set simplification: the driver, the random subset, the voxel grid (both variants) and
// what the clustering methods share.
#include "pointillist/prep/simplify.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <random>

#include "pointillist/core/error.hpp"
#include "pointillist/core/morton.hpp"
#include "pointillist/prep/radii.hpp"
#include "simplify_internal.hpp"

namespace pointillist {
namespace sd = simplify_detail;

namespace {

constexpr std::array<std::pair<SimplifyMethod, std::string_view>, 6> kNames = {{
    {SimplifyMethod::Random, "random"},
    {SimplifyMethod::VoxelCentroid, "voxel"},
    {SimplifyMethod::VoxelNearest, "voxel-nearest"},
    {SimplifyMethod::Hierarchical, "hierarchical"},
    {SimplifyMethod::Incremental, "incremental"},
    {SimplifyMethod::Quadric, "quadric"},
}};

// The points with keep[i] set, with their attributes; no radii and no faces (a subset is a
// cloud whose spacing is not the input's).
PointSet subset(const PointSet& in, std::span<const std::uint8_t> keep) {
  PointSet out = in;
  out.radii.clear();
  out.triangles.clear();
  keep_points(out, keep);
  return out;
}

// ---- random ----

PointSet random_subset(const PointSet& in, std::size_t target, std::uint64_t seed) {
  std::vector<std::uint32_t> index(in.size());
  std::iota(index.begin(), index.end(), 0u);
  std::mt19937_64 rng(seed);
  for (std::size_t i = 0; i < target; ++i) {  // partial Fisher-Yates: the first `target` picked
    std::uniform_int_distribution<std::size_t> pick(i, index.size() - 1);
    std::swap(index[i], index[pick(rng)]);
  }
  std::vector<std::uint8_t> keep(in.size(), 0);
  for (std::size_t i = 0; i < target; ++i) keep[index[i]] = 1;
  return subset(in, keep);
}

// ---- voxel grid ----

// Cells of side `size` over the box from `lo`, 21 bits an axis (a smaller size is raised to
// what 21 bits can hold).
struct VoxelGrid {
  Vec3f lo;
  float inv = 1;
  std::uint64_t key(Vec3f p) const {
    std::uint64_t k = 0;
    for (int a = 0; a < 3; ++a) {
      const float c = std::floor((p[a] - lo[a]) * inv);
      const auto cell = static_cast<std::uint64_t>(std::clamp(c, 0.0f, 2097151.0f));
      k |= cell << (21 * a);
    }
    return k;
  }
};

VoxelGrid voxel_grid(const Aabb& box, float size) {
  const Vec3f e = box.extent();
  const float longest = std::max({e.x, e.y, e.z});
  return {box.lo, 1.0f / std::max(size, longest / 2'000'000.0f)};
}

// Occupied cells at this size.
std::size_t count_cells(std::span<const Vec3f> p, const VoxelGrid& g, ThreadPool& pool) {
  std::vector<std::uint64_t> keys(p.size());
  parallel_for(pool, p.size(), 1 << 16, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) keys[i] = g.key(p[i]);
  });
  parallel_sort(keys, pool, std::less<>());
  return static_cast<std::size_t>(std::unique(keys.begin(), keys.end()) - keys.begin());
}

// The cell side whose occupied-cell count is nearest `target`. On a surface the count goes
// about as size^-2, so a secant step in log-log scale (slope -2 to begin with) lands within
// 0.5 % in three or four counting passes; a step that leaves the bracket of sizes known to give
// too many and too few cells is replaced by the bracket's geometric mean (at most 40 passes).
float voxel_size_for(std::span<const Vec3f> p, const Aabb& box, std::size_t target,
                     ThreadPool& pool, int& passes) {
  const Vec3f e = box.extent();
  const double area = 2.0 * (double(e.x) * e.y + double(e.y) * e.z + double(e.z) * e.x);
  const double longest = std::max({double(e.x), double(e.y), double(e.z), 1e-30});
  const double smallest = longest / 2'000'000.0, largest = longest * 2.0;
  const auto count = [&](double s) {
    ++passes;
    return double(count_cells(p, voxel_grid(box, float(s)), pool));
  };
  const double want = double(target);
  double s = std::clamp(area > 0 ? std::sqrt(area / (2.0 * want)) : longest, smallest, largest);
  double c = count(s);
  double lo = smallest, hi = largest;  // count(lo) >= target > count(hi), as far as known
  double best = s, best_c = c, slope = -2.0, prev_s = 0, prev_c = 0;
  while (std::abs(best_c - want) > 0.005 * want && passes < 40 && hi > lo * 1.000001) {
    (c >= want ? lo : hi) = std::max(lo, std::min(hi, s));
    if (prev_s > 0 && c != prev_c && s != prev_s) {
      const double measured = (std::log(c) - std::log(prev_c)) / (std::log(s) - std::log(prev_s));
      if (measured < -0.25) slope = std::clamp(measured, -4.0, -0.5);
    }
    double next = s * std::exp((std::log(want) - std::log(std::max(c, 1.0))) / slope);
    if (!(next > lo && next < hi)) next = std::sqrt(lo * hi);
    prev_s = s, prev_c = c;
    s = next;
    c = count(s);
    if (std::abs(c - want) < std::abs(best_c - want)) best = s, best_c = c;
  }
  return float(best);
}

sd::Clusters voxel_clusters(std::span<const Vec3f> p, const VoxelGrid& g, ThreadPool& pool) {
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed(p.size());
  parallel_for(pool, p.size(), 1 << 16, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) keyed[i] = {g.key(p[i]), static_cast<std::uint32_t>(i)};
  });
  parallel_sort(keyed, pool, std::less<>());
  sd::Clusters c;
  c.of.resize(p.size());
  for (std::size_t j = 0; j < keyed.size(); ++j) {
    if (j > 0 && keyed[j].first != keyed[j - 1].first) ++c.count;
    c.of[keyed[j].second] = c.count;
  }
  c.count += p.empty() ? 0 : 1;
  return c;
}

// Of each cluster, the member nearest its centroid (the lowest index among equals).
PointSet nearest_members(const PointSet& in, const sd::Clusters& c) {
  const PointSet means = sd::cluster_means(in, c);
  std::vector<std::uint32_t> best(c.count, UINT32_MAX);
  std::vector<float> best_d(c.count, INFINITY);
  for (std::size_t i = 0; i < in.size(); ++i) {
    const std::uint32_t k = c.of[i];
    const float d = length_squared(in.positions[i] - means.positions[k]);
    if (d < best_d[k]) {
      best_d[k] = d;
      best[k] = static_cast<std::uint32_t>(i);
    }
  }
  std::vector<std::uint8_t> keep(in.size(), 0);
  for (std::uint32_t i : best) keep[i] = 1;
  return subset(in, keep);
}

// Widens each cluster's disc to the farthest of its members, measured in the disc's plane, and
// half the member's own radius past it: an uneven cluster (a merged small one, a long one on a
// ridge) covers its own patch. (On 5 % of the dragon the incremental clusters left 0.006 % of
// the surface uncovered without it.)
void widen_to_members(const PointSet& in, const sd::Clusters& members, PointSet& out) {
  for (std::size_t i = 0; i < in.size(); ++i) {
    const std::uint32_t c = members.of[i];
    const Vec3f d = in.positions[i] - out.positions[c];
    const Vec3f n = out.normals[c];
    // Past the member by half its own disc, when it has one (what it stood for).
    const float own = in.has_radii() ? 0.5f * in.radii[i] : 0.0f;
    out.radii[c] = std::max(out.radii[c], length(d - n * dot(d, n)) + own);
  }
}

}  // namespace

std::string_view simplify_method_name(SimplifyMethod method) {
  for (const auto& [m, name] : kNames) {
    if (m == method) return name;
  }
  return "?";
}

SimplifyMethod parse_simplify_method(std::string_view name) {
  for (const auto& [m, n] : kNames) {
    if (n == name) return m;
  }
  throw OptionError("unknown simplification method '" + std::string(name) +
                    "'; use random, voxel, voxel-nearest, hierarchical, incremental or quadric");
}

namespace simplify_detail {

Rgb8 mean_color(const std::array<double, 3>& sum, double count) {
  const auto channel = [&](double v) {
    return static_cast<std::uint8_t>(std::clamp(std::lround(v / count), 0L, 255L));
  };
  return {channel(sum[0]), channel(sum[1]), channel(sum[2])};
}

void Moments::add(Vec3f p) {
  const Vec3f d = p - origin;
  const double x = d.x, y = d.y, z = d.z;
  n += 1;
  s[0] += x, s[1] += y, s[2] += z;
  ss[0] += x * x, ss[1] += x * y, ss[2] += x * z, ss[3] += y * y, ss[4] += y * z, ss[5] += z * z;
}

void Moments::add(const Moments& o) {
  n += o.n;
  for (int i = 0; i < 3; ++i) s[i] += o.s[i];
  for (int i = 0; i < 6; ++i) ss[i] += o.ss[i];
}

double Spread::variation() const {
  const double sum = lambda[0] + lambda[1] + lambda[2];
  return sum > 0 ? lambda[0] / sum : 0.0;
}

Spread spread_of(const Moments& m) {
  Spread out;
  if (m.n <= 0) return out;
  const double inv = 1.0 / m.n;
  const double mx = m.s[0] * inv, my = m.s[1] * inv, mz = m.s[2] * inv;
  out.centroid = m.centroid();
  Eigen::Matrix3d c;
  c(0, 0) = m.ss[0] * inv - mx * mx;
  c(0, 1) = c(1, 0) = m.ss[1] * inv - mx * my;
  c(0, 2) = c(2, 0) = m.ss[2] * inv - mx * mz;
  c(1, 1) = m.ss[3] * inv - my * my;
  c(1, 2) = c(2, 1) = m.ss[4] * inv - my * mz;
  c(2, 2) = m.ss[5] * inv - mz * mz;
  if (!(c.trace() > 0.0) || !c.allFinite()) return out;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(c, Eigen::ComputeEigenvectors);
  for (int i = 0; i < 3; ++i) out.lambda[i] = std::max(0.0, solver.eigenvalues()(i));
  const auto vec = [&](int col) {
    const Eigen::Vector3d e = solver.eigenvectors().col(col);
    return normalized(Vec3f{float(e.x()), float(e.y()), float(e.z())});
  };
  out.normal = vec(0);
  out.major = vec(2);
  return out;
}

Vec3f fitted_normal(const Moments& m, Vec3f mean_normal) {
  if (m.n < 3) return mean_normal;
  const Spread s = spread_of(m);
  if (!(s.lambda[1] > 4 * s.lambda[0])) return mean_normal;
  return dot(s.normal, mean_normal) < 0 ? -s.normal : s.normal;
}

PointSet cluster_means(const PointSet& in, const Clusters& clusters, bool fit_plane) {
  const std::size_t k = clusters.count;
  std::vector<Moments> m(k);
  std::vector<Vec3f> normal_sum(k, Vec3f{}), first_normal(k, Vec3f{});
  std::vector<std::array<double, 3>> color_sum(k, {0, 0, 0});
  std::vector<std::uint8_t> seen(k, 0);
  for (std::size_t i = 0; i < in.size(); ++i) {
    const std::uint32_t c = clusters.of[i];
    if (!seen[c]) {
      seen[c] = 1;
      m[c].origin = in.positions[i];
      first_normal[c] = in.normals[i];
    }
    m[c].add(in.positions[i]);
    normal_sum[c] += in.normals[i];
    if (in.has_colors()) {
      color_sum[c][0] += in.colors[i].r, color_sum[c][1] += in.colors[i].g;
      color_sum[c][2] += in.colors[i].b;
    }
  }
  PointSet out;
  out.comments = in.comments;
  out.origin = in.origin;
  out.up = in.up;
  out.positions.resize(k);
  out.normals.resize(k);
  if (in.has_colors()) out.colors.resize(k);
  for (std::size_t c = 0; c < k; ++c) {
    out.positions[c] = m[c].centroid();
    const float len = length(normal_sum[c]);
    out.normals[c] = len > 1e-6f ? normal_sum[c] / len : first_normal[c];
    if (fit_plane) out.normals[c] = fitted_normal(m[c], out.normals[c]);
    if (in.has_colors()) out.colors[c] = mean_color(color_sum[c], m[c].n);
  }
  return out;
}

}  // namespace simplify_detail

PointSet simplify_points(const PointSet& points, const SimplifyOptions& options, ThreadPool& pool,
                         Progress& progress, SimplifyReport* report, std::string_view input_name) {
  const std::string name(input_name);
  if (options.target == 0) throw OptionError("simplify: the target point count must be at least 1");
  if (points.size() == 0) throw Error(name + " has no points to simplify");
  if (!points.has_normals()) {
    throw Error(name + " has no normals: prepare it first (normals by PCA or from its faces)");
  }
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vec3f p = points.positions[i];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
      throw Error(name + ": point " + std::to_string(i) +
                  " has a coordinate that is not a finite number; remove it and try again");
    }
  }
  if (options.voxel_size < 0 || !std::isfinite(options.voxel_size)) {
    throw OptionError("simplify: the voxel size must be a positive length (or 0 for automatic)");
  }
  if ((options.method == SimplifyMethod::Incremental || options.method == SimplifyMethod::Quadric) &&
      options.neighbours < 2) {
    throw OptionError("simplify: --neighbours must be at least 2");
  }
  SimplifyReport local;
  SimplifyReport& r = report ? *report : local;
  r = SimplifyReport{};
  r.input = points.size();
  ProgressPhase phase(progress, "simplify", points.size());
  const bool voxel = options.method == SimplifyMethod::VoxelCentroid ||
                     options.method == SimplifyMethod::VoxelNearest;
  PointSet out;
  sd::Clusters members;  // which output point each input point went into (cluster methods)
  const bool whole = options.target >= points.size() && !(voxel && options.voxel_size > 0);
  if (whole) {  // nothing to take away: the input as it is, its radii kept if it has them
    out = points;
    out.triangles.clear();
  } else if (options.method == SimplifyMethod::Random) {
    out = random_subset(points, options.target, options.seed);
  } else if (voxel) {
    const Aabb box = bounding_box(points.positions);
    r.voxel_size = options.voxel_size > 0
                       ? options.voxel_size
                       : voxel_size_for(points.positions, box, options.target, pool, r.passes);
    sd::Clusters c = voxel_clusters(points.positions, voxel_grid(box, r.voxel_size), pool);
    if (options.method == SimplifyMethod::VoxelCentroid) {
      out = sd::cluster_means(points, c);
      members = std::move(c);
    } else {
      out = nearest_members(points, c);
    }
  } else {  // a clustering, each cluster drawn as its least-squares disc
    if (options.method == SimplifyMethod::Hierarchical) {
      members = sd::hierarchical_clusters(points, options.target, phase);
    } else if (options.method == SimplifyMethod::Incremental) {
      members = sd::incremental_clusters(points, options.target, options.neighbours, pool, phase,
                                         &r.passes);
    } else {
      members = sd::quadric_clusters(points, options, pool, phase);
    }
    out = sd::cluster_means(points, members, true);
  }
  // Radii: the cloud rule, with the coverage of evenly spread points (a random subset keeps
  // the default); a cluster's disc is at least as wide as its members reach in its plane.
  CloudRadiusOptions radius;
  radius.coverage = options.method == SimplifyMethod::Random || whole ? kDefaultCloudCoverage
                                                                      : kSimplifiedCoverage;
  if (!(whole && out.has_radii())) {
    out.radii = cloud_radii(out.positions, pool, Progress::none(), radius);
  }
  if (members.count == out.size()) widen_to_members(points, members, out);
  r.output = out.size();
  return out;
}

}  // namespace pointillist
