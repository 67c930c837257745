// Interior node bounds for the QSplat hierarchy (Rusinkiewicz & Levoy, "QSplat: A
// Multiresolution Point Rendering System for Large Meshes", SIGGRAPH 2000, section 3.1).
#include "node_bounds.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>

namespace pointillist::lod_detail {
namespace {

// Smallest float >= x, so a bound computed in double stays a bound once stored as float.
float round_up(double x) {
  float f = static_cast<float>(x);
  if (static_cast<double>(f) < x) f = std::nextafter(f, std::numeric_limits<float>::infinity());
  return f;
}

// Radius of the smallest sphere around `c` that holds every child sphere, in double so that the
// rounded-up float result encloses the children exactly, not just within float error.
double enclosing_radius(Vec3f c, std::span<const SphereNode> children) {
  double r = 0;
  for (const SphereNode& ch : children) {
    const double dx = static_cast<double>(ch.center.x) - c.x;
    const double dy = static_cast<double>(ch.center.y) - c.y;
    const double dz = static_cast<double>(ch.center.z) - c.z;
    r = std::max(r, std::sqrt(dx * dx + dy * dy + dz * dz) + ch.radius);
  }
  return r;
}

// Area weights r², or equal weights when the radii are all zero (or their squares overflow).
bool use_area_weights(std::span<const SphereNode> children) {
  float sum = 0;
  for (const SphereNode& ch : children) sum += ch.radius * ch.radius;
  return sum > 0 && std::isfinite(sum);
}

// Candidate spheres (centre, radius R) internally tangent to the children in `subset` (2 to 4
// of them, centre in their affine hull), passed to `consider(centre, R)`. The smallest sphere enclosing a set of balls touches at
// most 4 of them and is this sphere for that subset, so trying every subset finds it.
// Positions are relative to the first child of the subset, in double; `p`, `r` are all children.
template <typename Consider>
void tangent_spheres(const Vec3d* p, const double* r, const int* subset, int m, Consider&& consider) {
  const Vec3d o = p[subset[0]];
  const double r0 = r[subset[0]];
  Vec3d q[3];
  double e[3], f[3];  // x·q_k = e_k + f_k·R for x = centre - o (difference of the tangency equations)
  for (int k = 1; k < m; ++k) {
    q[k - 1] = p[subset[k]] + o * -1.0;
    const double rk = r[subset[k]];
    e[k - 1] = 0.5 * (dot(q[k - 1], q[k - 1]) - rk * rk + r0 * r0);
    f[k - 1] = rk - r0;
  }
  Vec3d a, b;  // centre - o = a + b·R
  if (m == 2) {
    const double d = std::sqrt(dot(q[0], q[0]));
    if (!(d > 0)) return;
    const double radius = 0.5 * (d + r0 + r[subset[1]]);
    consider(o + q[0] * ((radius - r0) / d), radius);
    return;
  }
  if (m == 3) {
    const double g11 = dot(q[0], q[0]), g12 = dot(q[0], q[1]), g22 = dot(q[1], q[1]);
    const double det = g11 * g22 - g12 * g12;
    if (!(det > 1e-12 * g11 * g22)) return;
    const double ae = (g22 * e[0] - g12 * e[1]) / det, be = (g11 * e[1] - g12 * e[0]) / det;
    const double af = (g22 * f[0] - g12 * f[1]) / det, bf = (g11 * f[1] - g12 * f[0]) / det;
    a = q[0] * ae + q[1] * be;
    b = q[0] * af + q[1] * bf;
  } else {
    const Vec3d c12 = cross(q[1], q[2]), c20 = cross(q[2], q[0]), c01 = cross(q[0], q[1]);
    const double det = dot(q[0], c12);
    const double scale = std::sqrt(dot(q[0], q[0]) * dot(q[1], q[1]) * dot(q[2], q[2]));
    if (!(std::abs(det) > 1e-9 * scale)) return;
    a = (c12 * e[0] + c20 * e[1] + c01 * e[2]) * (1.0 / det);
    b = (c12 * f[0] + c20 * f[1] + c01 * f[2]) * (1.0 / det);
  }
  // |a + b·R|² = (R - r0)²; only roots with R >= every r_k describe internal tangency.
  double r_max = 0;
  for (int k = 0; k < m; ++k) r_max = std::max(r_max, r[subset[k]]);
  const auto root = [&](double radius) {
    if (radius >= r_max) consider(o + a + b * radius, radius);
  };
  const double qa = dot(b, b) - 1, qb = 2 * (dot(a, b) + r0), qc = dot(a, a) - r0 * r0;
  if (std::abs(qa) < 1e-12) {
    if (qb != 0) root(-qc / qb);
    return;
  }
  const double disc = qb * qb - 4 * qa * qc;
  if (!(disc >= 0)) return;
  const double sq = std::sqrt(disc);
  root((-qb + sq) / (2 * qa));
  root((-qb - sq) / (2 * qa));
}

// Position of `x` relative to `origin`, as a double vector.
Vec3d relative(Vec3f x, Vec3f origin) {
  const Vec3f d = x - origin;
  return {d.x, d.y, d.z};
}

void bound_sphere(std::span<const SphereNode> children, SphereNode& parent) {
  // The smallest sphere enclosing the children touches 1 to 4 of them. The common cases are
  // checked first: one child holding the others, then the sphere on the farthest-apart pair
  // (d + r_i + r_j maximal; half of that is a lower bound, so when this sphere holds everything
  // it is optimal). Otherwise the spheres tangent to every 3 or 4 children are tried from the
  // smallest up, and the first that holds everything is the optimum. Radii are always
  // recomputed for the float centre that is stored, so numerical trouble in a solve can only
  // cost tightness, never containment.
  const int k = static_cast<int>(children.size());
  const Vec3f origin = children[0].center;
  Vec3d p[4];
  double r[4];
  int largest = 0;
  for (int i = 0; i < k; ++i) {
    p[i] = relative(children[i].center, origin);
    r[i] = children[i].radius;
    if (r[i] > r[largest]) largest = i;
  }
  Vec3f best_center = children[largest].center;
  double best_radius = enclosing_radius(best_center, children);
  // True when `radius` (enclosing radius around float centre `c`) is `bound` up to rounding: of
  // the solve, and of the centre to float (a few ulps of its coordinates).
  const auto holds_all = [&](Vec3f c, double radius, double bound) {
    const float magnitude = std::max({std::abs(c.x), std::abs(c.y), std::abs(c.z)});
    return radius <= bound * (1 + 1e-6) + 4e-7 * magnitude;
  };
  // Tries centre `x` (relative to origin) and keeps it when it is the best so far; true when the
  // sphere there with radius `bound` holds every child, which makes it optimal when `bound` is a
  // lower bound on the optimum.
  const auto consider = [&](Vec3d x, double bound) {
    const Vec3f c = origin + Vec3f{static_cast<float>(x.x), static_cast<float>(x.y),
                                   static_cast<float>(x.z)};
    if (!is_finite(c)) return false;
    const double radius = enclosing_radius(c, children);
    if (radius < best_radius) {
      best_radius = radius;
      best_center = c;
    }
    return holds_all(c, radius, bound);
  };
  if (!holds_all(best_center, best_radius, r[largest])) {
    int pi = 0, pj = 1;
    double span = -1;
    for (int i = 0; i < k; ++i) {
      for (int j = i + 1; j < k; ++j) {
        const Vec3d d = p[j] + p[i] * -1.0;
        const double s = std::sqrt(dot(d, d)) + r[i] + r[j];
        if (s > span) {
          span = s;
          pi = i;
          pj = j;
        }
      }
    }
    const double lower_bound = 0.5 * span;
    bool optimal = false;
    const int pair[2] = {pi, pj};
    tangent_spheres(p, r, pair, 2, [&](Vec3d x, double radius) { optimal = consider(x, radius); });
    if (!optimal && k >= 3) {
      struct Candidate {
        Vec3d center;
        double radius;
      };
      Candidate candidates[10];
      int count = 0;
      const auto collect = [&](Vec3d x, double radius) {
        if (radius >= lower_bound * (1 - 1e-9) && count < 10) candidates[count++] = {x, radius};
      };
      for (int mask = 7; mask < (1 << k); ++mask) {
        int subset[4], m = 0;
        for (int i = 0; i < k; ++i) {
          if (mask & (1 << i)) subset[m++] = i;
        }
        if (m >= 3) tangent_spheres(p, r, subset, m, collect);
      }
      for (int i = 1; i < count; ++i) {  // insertion sort of at most 10
        for (int j = i; j > 0 && candidates[j].radius < candidates[j - 1].radius; --j) {
          std::swap(candidates[j], candidates[j - 1]);
        }
      }
      for (int i = 0; i < count && !optimal; ++i) {
        optimal = consider(candidates[i].center, candidates[i].radius);
      }
      if (!optimal) {
        Aabb box;
        for (const SphereNode& ch : children) {
          const Vec3f rv{ch.radius, ch.radius, ch.radius};
          box.extend(ch.center - rv);
          box.extend(ch.center + rv);
        }
        consider(relative(box.center(), origin), 0);
      }
    }
  }
  parent.center = best_center;
  parent.radius = round_up(best_radius);
}

void bound_normals(std::span<const SphereNode> children, bool area_weights, SphereNode& parent) {
  Vec3f sum{};
  float length_sum = 0;
  for (const SphereNode& ch : children) {
    const float w = area_weights ? ch.radius * ch.radius : 1.0f;
    sum += ch.normal * w;
    length_sum += w * length(ch.normal);
  }
  const float len = length(sum);
  // Opposite normals cancel: no meaningful mean direction, so no cone either.
  if (!(len > 1e-6f * length_sum)) {
    parent.normal = {0, 0, 1};
    parent.cone_sin = kNoConeBound;
    return;
  }
  const Vec3f n = sum / len;
  parent.normal = n;
  const Vec3d nd{n.x, n.y, n.z};
  // θ = max_i (α_i + θ_i) with α_i = angle(n, n_i), without trigonometric calls:
  // sin(α + θ) = sin α cos θ + cos α sin θ and cos(α + θ) = cos α cos θ - sin α sin θ, where
  // sin α = |n × n_i| / |n_i| stays accurate for small angles. While α + θ < 90° (cos > 0) the
  // sine grows with the angle, so the largest sine is the largest angle.
  double max_sin = 0;
  for (const SphereNode& ch : children) {
    const Vec3d m{ch.normal.x, ch.normal.y, ch.normal.z};
    const double child_len = std::sqrt(dot(m, m));
    if (!(ch.cone_sin < 1.0f) || !(child_len > 0)) {
      parent.cone_sin = kNoConeBound;
      return;
    }
    const Vec3d c = cross(nd, m);
    const double sin_a = std::sqrt(dot(c, c)) / child_len;
    const double cos_a = dot(nd, m) / child_len;
    const double sin_t = ch.cone_sin;
    const double cos_t = std::sqrt(1 - sin_t * sin_t);
    if (!(cos_a * cos_t - sin_a * sin_t > 0)) {
      parent.cone_sin = kNoConeBound;
      return;
    }
    max_sin = std::max(max_sin, sin_a * cos_t + cos_a * sin_t);
  }
  const float s = round_up(max_sin * (1 + 1e-12));
  parent.cone_sin = s < 1.0f ? s : kNoConeBound;
}

}  // namespace

void combine_children(std::span<const SphereNode> children, SphereNode& parent) {
  assert(!children.empty() && children.size() <= 4);
  const bool area_weights = use_area_weights(children);
  bound_sphere(children, parent);
  bound_normals(children, area_weights, parent);
  unsigned r = 0, g = 0, b = 0;
  for (const SphereNode& ch : children) {
    r += ch.color.r;
    g += ch.color.g;
    b += ch.color.b;
  }
  const auto k = static_cast<unsigned>(children.size());
  parent.color = {static_cast<std::uint8_t>((r + k / 2) / k),
                  static_cast<std::uint8_t>((g + k / 2) / k),
                  static_cast<std::uint8_t>((b + k / 2) / k)};
}

}  // namespace pointillist::lod_detail
