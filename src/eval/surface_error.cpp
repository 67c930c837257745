// Surface error of a splat set against a reference surface (specs/occlusion-simplification-
// hybrid.md §2.7 "Metrics"). Point-cloud references use local PCA planes: Hoppe, DeRose,
// Duchamp, McDonald, Stuetzle, "Surface reconstruction from unorganized points", SIGGRAPH 1992,
// section 3.2.
#include "pointillist/eval/surface_error.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>

#include "pointillist/core/error.hpp"
#include "pointillist/prep/normals.hpp"
#include "pointillist/spatial/knn.hpp"
#include "triangle_bvh.hpp"

namespace pointillist {

class SurfaceReference::Impl {
 public:
  explicit Impl(double diagonal) : diagonal_(diagonal) {}
  virtual ~Impl() = default;
  virtual Closest closest(Vec3f p) const = 0;
  virtual std::vector<Vec3f> samples(std::size_t count, std::uint64_t seed) const = 0;
  double diagonal() const { return diagonal_; }

 private:
  double diagonal_;
};

namespace {

using eval_detail::BoxTree;
constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr std::size_t kGrain = 4096;

std::string vec_text(Vec3f v) {
  return "(" + std::to_string(v.x) + ", " + std::to_string(v.y) + ", " + std::to_string(v.z) + ")";
}

double diagonal_of(std::span<const Vec3f> positions) {
  Aabb box;
  for (const Vec3f p : positions) box.extend(p);
  const double dx = double(box.hi.x) - box.lo.x, dy = double(box.hi.y) - box.lo.y,
               dz = double(box.hi.z) - box.lo.z;
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

void check_finite(std::span<const Vec3f> positions, const std::string& what) {
  for (std::size_t i = 0; i < positions.size(); ++i) {
    if (!is_finite(positions[i])) {
      throw Error(what + " " + std::to_string(i) + " of " + std::to_string(positions.size()) +
                  " is not finite: " + vec_text(positions[i]));
    }
  }
}

class AnalyticReference final : public SurfaceReference::Impl {
 public:
  explicit AnalyticReference(const AnalyticScene& scene)
      : Impl(double(length(scene_bounds(scene).extent()))), scene_(scene) {}
  SurfaceReference::Closest closest(Vec3f p) const override {
    const AnalyticClosest c = closest_point(scene_, p);
    return {c.point, c.normal, c.distance};
  }
  std::vector<Vec3f> samples(std::size_t count, std::uint64_t seed) const override {
    return std::move(sample_scene(scene_, count, seed).points.positions);
  }

 private:
  AnalyticScene scene_;
};

class MeshReference final : public SurfaceReference::Impl {
 public:
  MeshReference(std::span<const Vec3f> positions,
                std::span<const std::array<std::uint32_t, 3>> triangles, ThreadPool& pool)
      : Impl(diagonal_of(positions)),
        bvh_(positions, triangles),
        positions_(positions.begin(), positions.end()),
        triangles_(triangles.begin(), triangles.end()),
        cumulative_area_(triangles.size()) {
    std::vector<double> area(triangles.size());
    parallel_for(pool, triangles.size(), 1 << 16, [&](std::size_t begin, std::size_t end) {
      for (std::size_t t = begin; t < end; ++t) {
        const auto& [a, b, c] = triangles[t];
        const Vec3f ab = positions[b] - positions[a], ac = positions[c] - positions[a];
        area[t] = 0.5 * double(length(cross(ab, ac)));
      }
    });
    double total = 0;
    for (std::size_t t = 0; t < area.size(); ++t) cumulative_area_[t] = total += area[t];
  }
  SurfaceReference::Closest closest(Vec3f p) const override {
    const auto hit = bvh_.closest(p);
    return {hit.point, hit.normal, hit.distance};
  }
  std::vector<Vec3f> samples(std::size_t count, std::uint64_t seed) const override {
    std::vector<Vec3f> out;
    const double total = cumulative_area_.back();
    if (!(total > 0)) return out;
    out.reserve(count);
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> uni(0.0, 1.0);
    for (std::size_t i = 0; i < count; ++i) {
      const double pick = uni(rng) * total;
      const std::size_t t = std::min<std::size_t>(
          std::upper_bound(cumulative_area_.begin(), cumulative_area_.end(), pick) -
              cumulative_area_.begin(),
          triangles_.size() - 1);
      float u = float(uni(rng)), v = float(uni(rng));
      if (u + v > 1) {  // fold the square's far half onto the triangle
        u = 1 - u;
        v = 1 - v;
      }
      const auto& [a, b, c] = triangles_[t];
      const Vec3f origin = positions_[a];
      out.push_back(origin + (positions_[b] - origin) * u + (positions_[c] - origin) * v);
    }
    return out;
  }

 private:
  eval_detail::TriangleBvh bvh_;
  std::vector<Vec3f> positions_;
  std::vector<std::array<std::uint32_t, 3>> triangles_;
  std::vector<double> cumulative_area_;
};

class PointsReference final : public SurfaceReference::Impl {
 public:
  PointsReference(std::span<const Vec3f> positions, ThreadPool& pool, std::uint32_t k)
      : Impl(diagonal_of(positions)), original_(positions.begin(), positions.end()) {
    const std::size_t n = positions.size();
    const auto used = std::uint32_t(std::min<std::size_t>(k - 1, n - 1));
    const std::vector<std::uint32_t> rows = k_nearest_neighbours(positions, pool, {.k = used});
    std::vector<Aabb> boxes(n);
    for (std::size_t i = 0; i < n; ++i) boxes[i].extend(positions[i]);
    tree_ = BoxTree(boxes);
    const auto order = tree_.order();
    points_.resize(n);
    plane_points_.resize(n);
    plane_normals_.resize(n);
    parallel_for(pool, n, kGrain, [&](std::size_t begin, std::size_t end) {
      for (std::size_t s = begin; s < end; ++s) {
        const std::size_t i = order[s];
        points_[s] = positions[i];
        const auto [mean, normal] =
            pca_plane(positions, i, std::span(rows).subspan(i * used, used));
        plane_points_[s] = mean;
        plane_normals_[s] = normal;
      }
    });
  }
  SurfaceReference::Closest closest(Vec3f p) const override {
    const auto order = tree_.order();
    float best = kInf;
    std::uint32_t best_slot = 0, best_index = std::numeric_limits<std::uint32_t>::max();
    tree_.search(p, kInf, [&](std::uint32_t slot, float bound) {
      const float d2 = length_squared(p - points_[slot]);
      if (d2 < best || (d2 == best && order[slot] < best_index)) {
        best = d2;
        best_slot = slot;
        best_index = order[slot];
        return d2;
      }
      return bound;
    });
    const Vec3f n = plane_normals_[best_slot];
    const float h = dot(p - plane_points_[best_slot], n);
    return {p - n * h, n, std::abs(h)};
  }
  std::vector<Vec3f> samples(std::size_t count, std::uint64_t) const override {
    const std::size_t n = original_.size();
    const std::size_t stride = n > count ? (n + count - 1) / count : 1;
    std::vector<Vec3f> out;
    out.reserve(n / stride + 1);
    for (std::size_t i = 0; i < n; i += stride) out.push_back(original_[i]);
    return out;
  }

 private:
  std::vector<Vec3f> original_;
  BoxTree tree_;
  // In the tree's leaf order: the points, and the plane (a point on it and its unit normal).
  std::vector<Vec3f> points_, plane_points_, plane_normals_;
};

// The splats as discs in a bounding-volume hierarchy, for the exact nearest disc of a sample.
class DiscSet {
 public:
  DiscSet(std::span<const Vec3f> centers, std::span<const Vec3f> normals,
          std::span<const float> radii) {
    std::vector<Aabb> boxes(centers.size());
    for (std::size_t i = 0; i < centers.size(); ++i) {
      const Vec3f c = centers[i], n = normalized(normals[i]);
      // The disc's own box, widened so that float rounding cannot push a disc out of its box.
      const float margin =
          1e-4f * radii[i] + 1e-6f * std::max({std::abs(c.x), std::abs(c.y), std::abs(c.z)});
      Vec3f half;
      for (int a = 0; a < 3; ++a) {
        half[a] = radii[i] * std::sqrt(std::max(0.0f, 1 - n[a] * n[a])) + margin;
      }
      boxes[i].extend(c - half);
      boxes[i].extend(c + half);
    }
    tree_ = BoxTree(boxes);
    const auto order = tree_.order();
    discs_.resize(order.size());
    for (std::size_t s = 0; s < order.size(); ++s) {
      discs_[s] = {centers[order[s]], normalized(normals[order[s]]), radii[order[s]]};
    }
  }

  struct Nearest {
    float distance_squared = kInf;
    bool covered = false;
  };
  // The nearest disc's squared distance from s, and whether some disc covers s (its foot inside
  // the radius, plane distance ≤ cover_distance). Until a covering disc is found the search
  // reaches past the nearest disc out to cover_distance: a cover's box is no farther than that.
  Nearest nearest(Vec3f s, float cover_distance) const {
    Nearest out;
    const float cover2 = cover_distance * cover_distance;
    tree_.search(s, kInf, [&](std::uint32_t slot, float) {
      const Disc& d = discs_[slot];
      const Vec3f v = s - d.center;
      const float h = dot(v, d.normal);
      const float t2 = length_squared(v - d.normal * h);
      float d2 = h * h;
      if (t2 <= d.radius * d.radius) {
        out.covered = out.covered || d2 <= cover2;
      } else {
        const float e = std::sqrt(t2) - d.radius;
        d2 += e * e;
      }
      out.distance_squared = std::min(out.distance_squared, d2);
      return out.covered ? out.distance_squared : std::max(out.distance_squared, cover2);
    });
    return out;
  }

 private:
  struct Disc {
    Vec3f center, normal;
    float radius;
  };
  BoxTree tree_;
  std::vector<Disc> discs_;  // in the tree's leaf order
};

void check_splats(std::span<const Vec3f> centers, std::span<const Vec3f> normals,
                  std::span<const float> radii) {
  if (centers.size() != normals.size() || centers.size() != radii.size()) {
    throw Error("surface error: " + std::to_string(centers.size()) + " centres, " +
                std::to_string(normals.size()) + " normals and " + std::to_string(radii.size()) +
                " radii; every splat needs one of each");
  }
  if (centers.empty()) throw Error("surface error: no splats to measure");
  check_finite(centers, "surface error: splat centre");
  check_finite(normals, "surface error: splat normal");
  for (std::size_t i = 0; i < normals.size(); ++i) {
    if (!(length_squared(normals[i]) > 0)) {
      throw Error("surface error: splat normal " + std::to_string(i) + " of " +
                  std::to_string(normals.size()) + " is zero (a disc needs a direction)");
    }
  }
  for (std::size_t i = 0; i < radii.size(); ++i) {
    if (!(radii[i] >= 0) || !std::isfinite(radii[i])) {
      throw Error("surface error: splat " + std::to_string(i) + " of " +
                  std::to_string(radii.size()) + " has radius " + std::to_string(radii[i]) +
                  " (expected a finite radius >= 0)");
    }
  }
}

// acos(|n·m|) of the normalised vectors, as atan2(|n×m|, |n·m|) in double: acos loses
// precision near 0°, where most splats are (float normals give up to 0.02° there).
double unsigned_angle_deg(Vec3f n, Vec3f m) {
  const double a[3] = {n.x, n.y, n.z}, b[3] = {m.x, m.y, m.z};
  const double cx = a[1] * b[2] - a[2] * b[1], cy = a[2] * b[0] - a[0] * b[2],
               cz = a[0] * b[1] - a[1] * b[0];
  const double sine = std::sqrt(cx * cx + cy * cy + cz * cz);
  const double cosine = std::abs(a[0] * b[0] + a[1] * b[1] + a[2] * b[2]);
  return std::atan2(sine, cosine) * (180.0 / 3.14159265358979323846);
}

// One block's sums of distances (and their squares, maximum) and angles.
struct Partial {
  double sum = 0, sum_squared = 0, max = 0, angle_sum = 0;
  std::size_t uncovered = 0;
};

Partial sum_blocks(const std::vector<Partial>& partials) {
  Partial total;
  for (const Partial& p : partials) {  // block order: the same sums for any thread count
    total.sum += p.sum;
    total.sum_squared += p.sum_squared;
    total.max = std::max(total.max, p.max);
    total.angle_sum += p.angle_sum;
    total.uncovered += p.uncovered;
  }
  return total;
}

DistanceStats stats_of(const Partial& total, std::size_t count) {
  return {total.max, total.sum / double(count), std::sqrt(total.sum_squared / double(count))};
}

}  // namespace

SurfaceReference::SurfaceReference(std::unique_ptr<const Impl> impl) : impl_(std::move(impl)) {}
SurfaceReference::SurfaceReference(SurfaceReference&&) noexcept = default;
SurfaceReference& SurfaceReference::operator=(SurfaceReference&&) noexcept = default;
SurfaceReference::~SurfaceReference() = default;

SurfaceReference SurfaceReference::analytic(const AnalyticScene& scene) {
  if (scene.shapes.empty()) throw Error("surface reference: the analytic scene has no shapes");
  return SurfaceReference(std::make_unique<AnalyticReference>(scene));
}

SurfaceReference SurfaceReference::mesh(std::span<const Vec3f> positions,
                                        std::span<const std::array<std::uint32_t, 3>> triangles,
                                        ThreadPool& pool) {
  if (triangles.empty()) throw Error("surface reference: the mesh has no triangles");
  check_finite(positions, "surface reference: mesh vertex");
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    for (const std::uint32_t v : triangles[t]) {
      if (v >= positions.size()) {
        throw Error("surface reference: triangle " + std::to_string(t) + " of " +
                    std::to_string(triangles.size()) + " refers to vertex " + std::to_string(v) +
                    " of " + std::to_string(positions.size()));
      }
    }
  }
  return SurfaceReference(std::make_unique<MeshReference>(positions, triangles, pool));
}

SurfaceReference SurfaceReference::points(std::span<const Vec3f> positions, ThreadPool& pool,
                                          std::uint32_t k) {
  if (k < 3) {
    throw OptionError("surface reference: k = " + std::to_string(k) +
                      " neighbours cannot define a plane; use k >= 3 (16 is typical)");
  }
  if (positions.size() < 3) {
    throw Error("surface reference: " + std::to_string(positions.size()) +
                " points cannot define a plane; the point reference needs at least 3");
  }
  check_finite(positions, "surface reference: point");
  return SurfaceReference(std::make_unique<PointsReference>(positions, pool, k));
}

SurfaceReference::Closest SurfaceReference::closest(Vec3f p) const { return impl_->closest(p); }

std::vector<Vec3f> SurfaceReference::samples(std::size_t count, std::uint64_t seed) const {
  return impl_->samples(count, seed);
}

double SurfaceReference::diagonal() const { return impl_->diagonal(); }

SurfaceError surface_error(const SurfaceReference& reference, std::span<const Vec3f> centers,
                           std::span<const Vec3f> normals, std::span<const float> radii,
                           ThreadPool& pool, const SurfaceErrorOptions& options) {
  check_splats(centers, normals, radii);
  if (options.backward_samples == 0) {
    throw OptionError("surface error: backward_samples = 0; the backward distance and hole "
                      "fraction need reference samples (the spec uses 2,000,000)");
  }
  SurfaceError out;
  out.diagonal = reference.diagonal();
  out.splats = centers.size();

  // Forward: each centre to the reference, and the normal angle at its closest point.
  const std::size_t n = centers.size();
  std::vector<double> angles(n);
  std::vector<Partial> forward((n + kGrain - 1) / kGrain);
  parallel_for(pool, n, kGrain, [&](std::size_t begin, std::size_t end) {
    Partial& part = forward[begin / kGrain];
    for (std::size_t i = begin; i < end; ++i) {
      const SurfaceReference::Closest c = reference.closest(centers[i]);
      const double d = c.distance;
      part.sum += d;
      part.sum_squared += d * d;
      part.max = std::max(part.max, d);
      angles[i] = unsigned_angle_deg(normals[i], c.normal);
      part.angle_sum += angles[i];
    }
  });
  const Partial forward_total = sum_blocks(forward);
  out.forward = stats_of(forward_total, n);
  out.normal_mean_deg = forward_total.angle_sum / double(n);
  const std::size_t rank = (95 * n + 99) / 100;  // nearest rank: ceil(0.95 n), 1-based
  std::nth_element(angles.begin(), angles.begin() + (rank - 1), angles.end());
  out.normal_p95_deg = angles[rank - 1];

  // Backward: each reference sample to the nearest disc, and whether any disc covers it.
  const DiscSet discs(centers, normals, radii);
  const std::vector<Vec3f> samples = reference.samples(options.backward_samples, options.seed);
  const std::size_t m = samples.size();
  out.samples = m;
  if (m > 0) {
    const auto cover_distance = float(options.hole_tolerance * out.diagonal);
    std::vector<Partial> backward((m + kGrain - 1) / kGrain);
    parallel_for(pool, m, kGrain, [&](std::size_t begin, std::size_t end) {
      Partial& part = backward[begin / kGrain];
      for (std::size_t i = begin; i < end; ++i) {
        const DiscSet::Nearest near = discs.nearest(samples[i], cover_distance);
        const double d = std::sqrt(double(near.distance_squared));
        part.sum += d;
        part.sum_squared += d * d;
        part.max = std::max(part.max, d);
        part.uncovered += near.covered ? 0 : 1;
      }
    });
    const Partial backward_total = sum_blocks(backward);
    out.backward = stats_of(backward_total, m);
    out.hole_fraction = double(backward_total.uncovered) / double(m);
  }
  out.hausdorff = std::max(out.forward.max, out.backward.max);
  return out;
}

}  // namespace pointillist
