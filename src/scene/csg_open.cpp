// The open surfaces of the CSG test scenes: a rectangle (the wedge strips of spec T12) and the
// height field of the open crease (spec T15), y = 0.5·|x|·max(0, 1 − z) over x in [−1, 1],
// z in [0, 2]: two bilinear pieces (x < 0 and x > 0, z < 1) meeting along x = 0 at a dihedral
// that fades from 53° at z = 0 to none at z = 1, and the flat part y = 0 beyond.
#include <cmath>
#include <limits>

#include "csg_internal.hpp"

namespace pointillist::csg_detail {
namespace {

constexpr double kNoHit = std::numeric_limits<double>::infinity();

// Roots of a·t² + b·t + c = 0 (a linear equation when a is negligible), NaN where none.
void solve_quadratic(double a, double b, double c, double& t0, double& t1) {
  t0 = t1 = std::numeric_limits<double>::quiet_NaN();
  if (std::fabs(a) < 1e-12 * (std::fabs(b) + std::fabs(c) + 1e-300)) {
    if (b != 0) t0 = -c / b;
    return;
  }
  const double disc = b * b - 4 * a * c;
  if (disc < 0) return;
  const double q = -0.5 * (b + std::copysign(std::sqrt(disc), b));
  t0 = q / a;
  if (q != 0) t1 = c / q;
}

std::optional<OpenHit> ray_quad(const Primitive& p, Vec3f origin, Vec3f dir) {
  const Vec3f n = cross(p.edge_u, p.edge_v);
  const double denom = dot(n, dir);
  if (std::fabs(denom) < 1e-12) return std::nullopt;
  const double t = dot(n, p.center - origin) / denom;
  if (!(t > 0)) return std::nullopt;
  const Vec3f x = origin + dir * static_cast<float>(t);
  if (!open_face_contains(p, 0, x)) return std::nullopt;
  return OpenHit{t, 0};
}

std::optional<OpenHit> ray_crease(const Primitive& p, Vec3f origin, Vec3f dir) {
  const double o[3] = {double(origin.x) - p.center.x, double(origin.y) - p.center.y,
                       double(origin.z) - p.center.z};
  const double d[3] = {dir.x, dir.y, dir.z};
  double best = kNoHit;
  std::uint32_t face = 0;
  const auto consider = [&](double t, std::uint32_t f) {
    if (!(t > 0) || !(t < best)) return;
    const double x = o[0] + t * d[0], z = o[2] + t * d[2];
    const bool in = f == 2 ? std::fabs(x) <= 1 && z >= 1 && z <= 2
                           : (f == 0 ? x <= 0 : x >= 0) && std::fabs(x) <= 1 && z >= 0 && z <= 1;
    if (in) best = t, face = f;
  };
  // Piece s (−1: x ≤ 0, +1: x ≥ 0): y − 0.5·s·x·(1 − z) = 0 along the ray.
  for (const int s : {-1, 1}) {
    const double a = 0.5 * s * d[0] * d[2];
    const double b = d[1] - 0.5 * s * d[0] + 0.5 * s * (o[0] * d[2] + d[0] * o[2]);
    const double c = o[1] - 0.5 * s * o[0] + 0.5 * s * o[0] * o[2];
    double t0, t1;
    solve_quadratic(a, b, c, t0, t1);
    consider(t0, s < 0 ? 0 : 1);
    consider(t1, s < 0 ? 0 : 1);
  }
  if (d[1] != 0) consider(-o[1] / d[1], 2);
  if (best == kNoHit) return std::nullopt;
  return OpenHit{best, face};
}

}  // namespace

bool is_open(const Primitive& p) {
  return p.kind == PrimitiveKind::Quad || p.kind == PrimitiveKind::Crease;
}

std::uint32_t open_face_count(const Primitive& p) { return p.kind == PrimitiveKind::Crease ? 3 : 1; }

void sample_open(const Primitive& p, float spacing, SamplingMode mode, std::mt19937_64& rng,
                 std::vector<FaceSample>& out) {
  if (p.kind == PrimitiveKind::Quad) {
    const float w = length(p.edge_u), h = length(p.edge_v);
    const Vec3f u = p.edge_u / w, v = p.edge_v / h;
    sample_rectangle(w, h, spacing, mode, rng,
                     [&](float s, float t) { out.push_back({p.center + u * s + v * t, 0}); });
    return;
  }
  // The crease: the parameter square (x, z), as the spec's sample count assumes.
  sample_rectangle(2.0f, 2.0f, spacing, mode, rng, [&](float s, float z) {
    const float x = s - 1.0f;
    const float y = 0.5f * std::fabs(x) * std::max(0.0f, 1.0f - z);
    out.push_back({p.center + Vec3f{x, y, z}, z >= 1.0f ? 2u : (x < 0 ? 0u : 1u)});
  });
}

Vec3f open_face_normal(const Primitive& p, std::uint32_t face, Vec3f x) {
  if (p.kind == PrimitiveKind::Quad) return normalized(cross(p.edge_u, p.edge_v));
  if (face == 2) return {0, 1, 0};
  const Vec3f l = x - p.center;
  const float s = face == 0 ? -1.0f : 1.0f;
  // The gradient of y − 0.5·s·x·(1 − z).
  return normalized(Vec3f{-0.5f * s * (1.0f - l.z), 1.0f, 0.5f * s * l.x});
}

std::optional<OpenHit> ray_open(const Primitive& p, Vec3f origin, Vec3f dir) {
  return p.kind == PrimitiveKind::Quad ? ray_quad(p, origin, dir) : ray_crease(p, origin, dir);
}

void extend_open_bounds(const Primitive& p, Aabb& box) {
  if (p.kind == PrimitiveKind::Quad) {
    box.extend(p.center);
    box.extend(p.center + p.edge_u);
    box.extend(p.center + p.edge_v);
    box.extend(p.center + p.edge_u + p.edge_v);
    return;
  }
  box.extend(p.center + Vec3f{-1, 0, 0});
  box.extend(p.center + Vec3f{1, 0.5f, 2});
}

bool open_face_is_planar(const Primitive& p, std::uint32_t face) {
  return p.kind == PrimitiveKind::Quad || face == 2;
}

bool open_face_contains(const Primitive& p, std::uint32_t face, Vec3f x) {
  constexpr float eps = 1e-5f;
  const Vec3f l = x - p.center;
  if (p.kind == PrimitiveKind::Quad) {
    const float s = dot(l, p.edge_u) / dot(p.edge_u, p.edge_u);
    const float t = dot(l, p.edge_v) / dot(p.edge_v, p.edge_v);
    return s >= -eps && s <= 1 + eps && t >= -eps && t <= 1 + eps;
  }
  if (std::fabs(l.x) > 1 + eps) return false;
  if (face == 2) return l.z >= 1 - eps && l.z <= 2 + eps;
  return (face == 0 ? l.x <= eps : l.x >= -eps) && l.z >= -eps && l.z <= 1 + eps;
}

}  // namespace pointillist::csg_detail
