#include "pointillist/scene/csg.hpp"

#include "csg_internal.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <utility>

#include "pointillist/core/error.hpp"

namespace pointillist {
namespace {

using csg_detail::FaceSample;
using csg_detail::sample_rectangle;

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr double kTwoPi = 6.28318530717958647692;

Vec3f axis_vector(int axis, float sign = 1.0f) {
  Vec3f v{0, 0, 0};
  v[axis] = sign;
  return v;
}

std::uint32_t face_count(const Primitive& p) {
  switch (p.kind) {
    case PrimitiveKind::Box: return 6;
    case PrimitiveKind::Sphere: return 1;
    case PrimitiveKind::Cylinder: return 3;
    case PrimitiveKind::Quad:
    case PrimitiveKind::Crease: return csg_detail::open_face_count(p);
  }
  return 0;
}

// Closed inside test with a small tolerance, so that a face lying on another primitive's face
// (the step's inner faces) counts as inside it.
bool inside(const Primitive& p, Vec3f x) {
  constexpr float eps = 1e-5f;
  const Vec3f d = x - p.center;
  switch (p.kind) {
    case PrimitiveKind::Box:
      return std::fabs(d.x) <= p.half.x + eps && std::fabs(d.y) <= p.half.y + eps &&
             std::fabs(d.z) <= p.half.z + eps;
    case PrimitiveKind::Sphere: return length(d) <= p.radius + eps;
    case PrimitiveKind::Cylinder: {
      const float axial = d[p.axis];
      const Vec3f radial = d - axis_vector(p.axis, axial);
      return std::fabs(axial) <= p.half_length + eps && length(radial) <= p.radius + eps;
    }
    case PrimitiveKind::Quad:
    case PrimitiveKind::Crease: return false;  // open: no inside
  }
  return false;
}

// Outward normal of face `face` of `p` at x (on that face).
Vec3f face_normal(const Primitive& p, std::uint32_t face, Vec3f x) {
  switch (p.kind) {
    case PrimitiveKind::Box: return axis_vector(static_cast<int>(face / 2), face % 2 ? 1.0f : -1.0f);
    case PrimitiveKind::Sphere: return normalized(x - p.center);
    case PrimitiveKind::Cylinder: {
      if (face == 1) return axis_vector(p.axis, -1.0f);
      if (face == 2) return axis_vector(p.axis, 1.0f);
      const Vec3f d = x - p.center;
      return normalized(d - axis_vector(p.axis, d[p.axis]));
    }
    case PrimitiveKind::Quad:
    case PrimitiveKind::Crease: return csg_detail::open_face_normal(p, face, x);
  }
  return {0, 0, 1};
}

void sample_primitive(const Primitive& p, float spacing, SamplingMode mode, std::mt19937_64& rng,
                      std::vector<FaceSample>& out) {
  switch (p.kind) {
    case PrimitiveKind::Box:
      for (std::uint32_t face = 0; face < 6; ++face) {
        const int a = static_cast<int>(face / 2), u = (a + 1) % 3, v = (a + 2) % 3;
        Vec3f base = p.center;
        base[a] += face % 2 ? p.half[a] : -p.half[a];
        base[u] -= p.half[u];
        base[v] -= p.half[v];
        const float h = p.face_spacing[a] > 0 ? p.face_spacing[a] : spacing;
        sample_rectangle(2 * p.half[u], 2 * p.half[v], h, mode, rng, [&](float s, float t) {
          Vec3f x = base;
          x[u] += s;
          x[v] += t;
          out.push_back({x, face});
        });
      }
      break;
    case PrimitiveKind::Sphere: {
      const int n = std::max(1, static_cast<int>(std::lround(4 * kPi * p.radius * p.radius /
                                                             (spacing * spacing))));
      std::uniform_real_distribution<float> unit(0.0f, 1.0f), jitter(-0.1f, 0.1f);
      const double golden = kTwoPi * (1.0 - 1.0 / 1.6180339887498949);
      for (int k = 0; k < n; ++k) {
        Vec3f d;
        if (mode == SamplingMode::Jittered) {
          const double z = 1.0 - (2.0 * k + 1.0) / n, rho = std::sqrt(std::max(0.0, 1 - z * z));
          const double phi = golden * k;
          d = {static_cast<float>(rho * std::cos(phi)), static_cast<float>(z),
               static_cast<float>(rho * std::sin(phi))};
          const auto [t1, t2] = tangent_frame(d);
          d = normalized(d * p.radius + (t1 * jitter(rng) + t2 * jitter(rng)) * spacing);
        } else {
          const float z = 2 * unit(rng) - 1, phi = static_cast<float>(kTwoPi) * unit(rng);
          const float rho = std::sqrt(std::max(0.0f, 1 - z * z));
          d = {rho * std::cos(phi), z, rho * std::sin(phi)};
        }
        out.push_back({p.center + d * p.radius, 0});
      }
      break;
    }
    case PrimitiveKind::Cylinder: {
      const int a = p.axis, u = (a + 1) % 3, v = (a + 2) % 3;
      const float circumference = static_cast<float>(kTwoPi) * p.radius;
      sample_rectangle(circumference, 2 * p.half_length, spacing, mode, rng, [&](float s, float t) {
        const float angle = s / p.radius;
        Vec3f x = p.center;
        x[u] += p.radius * std::cos(angle);
        x[v] += p.radius * std::sin(angle);
        x[a] += t - p.half_length;
        out.push_back({x, 0});
      });
      for (std::uint32_t cap = 1; cap <= 2; ++cap) {
        sample_rectangle(2 * p.radius, 2 * p.radius, spacing, mode, rng, [&](float s, float t) {
          const float du = s - p.radius, dv = t - p.radius;
          if (du * du + dv * dv > p.radius * p.radius) return;
          Vec3f x = p.center;
          x[u] += du;
          x[v] += dv;
          x[a] += cap == 2 ? p.half_length : -p.half_length;
          out.push_back({x, cap});
        });
      }
      break;
    }
    case PrimitiveKind::Quad:
    case PrimitiveKind::Crease: csg_detail::sample_open(p, spacing, mode, rng, out); break;
  }
}

// Whether a sample of primitive k lies on the result's boundary, and whether its normal flips.
bool on_boundary(const CsgScene& scene, std::size_t k, Vec3f x, bool& flip) {
  flip = false;
  const auto& prims = scene.primitives;
  switch (scene.op) {
    case CsgOp::Separate: return true;
    case CsgOp::Union:
      for (std::size_t m = 0; m < prims.size(); ++m) {
        if (m != k && inside(prims[m], x)) return false;
      }
      return true;
    case CsgOp::Intersection:
      for (std::size_t m = 0; m < prims.size(); ++m) {
        if (m != k && !inside(prims[m], x)) return false;
      }
      return true;
    case CsgOp::Difference:
      for (std::size_t m = 1; m < prims.size(); ++m) {
        if (m != k && inside(prims[m], x)) return false;
      }
      if (k == 0) return true;
      flip = true;
      return inside(prims[0], x);
  }
  return false;
}

// The interval [t0, t1] of the ray inside primitive p, with the faces where it enters and
// leaves; false when the ray misses.
struct Interval {
  double t0, t1;
  std::uint32_t face0, face1;
};
bool ray_interval(const Primitive& p, Vec3f origin, Vec3f dir, Interval& iv) {
  const double o[3] = {origin.x - p.center.x, origin.y - p.center.y, origin.z - p.center.z};
  const double d[3] = {dir.x, dir.y, dir.z};
  iv = {-std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(), 0, 0};
  const auto slab = [&](int a, double half, std::uint32_t face_lo, std::uint32_t face_hi) {
    if (std::fabs(d[a]) < 1e-300) return std::fabs(o[a]) <= half;
    double lo = (-half - o[a]) / d[a], hi = (half - o[a]) / d[a];
    std::uint32_t f_lo = face_lo, f_hi = face_hi;
    if (lo > hi) std::swap(lo, hi), std::swap(f_lo, f_hi);
    if (lo > iv.t0) iv.t0 = lo, iv.face0 = f_lo;
    if (hi < iv.t1) iv.t1 = hi, iv.face1 = f_hi;
    return true;
  };
  switch (p.kind) {
    case PrimitiveKind::Box:
      for (int a = 0; a < 3; ++a) {
        if (!slab(a, p.half[a], 2 * a, 2 * a + 1)) return false;
      }
      break;
    case PrimitiveKind::Sphere: {
      const double b = o[0] * d[0] + o[1] * d[1] + o[2] * d[2];
      const double c = o[0] * o[0] + o[1] * o[1] + o[2] * o[2] - double(p.radius) * p.radius;
      const double disc = b * b - c;
      if (disc < 0) return false;
      iv.t0 = -b - std::sqrt(disc);
      iv.t1 = -b + std::sqrt(disc);
      break;
    }
    case PrimitiveKind::Cylinder: {
      const int a = p.axis, u = (a + 1) % 3, v = (a + 2) % 3;
      const double qa = d[u] * d[u] + d[v] * d[v];
      const double qb = o[u] * d[u] + o[v] * d[v];
      const double qc = o[u] * o[u] + o[v] * o[v] - double(p.radius) * p.radius;
      if (qa < 1e-300) {
        if (qc > 0) return false;
      } else {
        const double disc = qb * qb - qa * qc;
        if (disc < 0) return false;
        iv.t0 = (-qb - std::sqrt(disc)) / qa;
        iv.t1 = (-qb + std::sqrt(disc)) / qa;
      }
      if (!slab(a, p.half_length, 1, 2)) return false;
      break;
    }
    case PrimitiveKind::Quad:
    case PrimitiveKind::Crease: return false;  // open: no interval (ray_open)
  }
  return iv.t0 < iv.t1;
}

bool member(const CsgScene& scene, const std::vector<Interval>& iv,
            const std::vector<std::uint8_t>& hit, double t) {
  const auto in = [&](std::size_t k) { return hit[k] && iv[k].t0 < t && t < iv[k].t1; };
  const std::size_t n = scene.primitives.size();
  switch (scene.op) {
    case CsgOp::Union:
    case CsgOp::Separate:
      for (std::size_t k = 0; k < n; ++k) if (in(k)) return true;
      return false;
    case CsgOp::Intersection:
      for (std::size_t k = 0; k < n; ++k) if (!in(k)) return false;
      return n > 0;
    case CsgOp::Difference:
      if (n == 0 || !in(0)) return false;
      for (std::size_t k = 1; k < n; ++k) if (in(k)) return false;
      return true;
  }
  return false;
}

}  // namespace

std::uint32_t CsgScene::label_count() const { return first_label(primitives.size()); }

std::uint32_t CsgScene::first_label(std::size_t primitive) const {
  std::uint32_t n = 0;
  for (std::size_t k = 0; k < primitive && k < primitives.size(); ++k) n += face_count(primitives[k]);
  return n;
}

namespace {
// Spec T14's scanner noise (CsgScene::normal_noise_degrees, position_noise), from a stream of its
// own so the noise-free samples stay those of the scene without it.
void add_noise(const CsgScene& scene, std::uint64_t seed, PointSet& points) {
  if (scene.normal_noise_degrees <= 0 && scene.position_noise <= 0) return;
  std::mt19937_64 rng(seed ^ 0x6a09e667f3bcc909ull);
  std::normal_distribution<float> tilt(0.0f, std::max(scene.normal_noise_degrees, 0.0f) * kPi / 180);
  std::normal_distribution<float> offset(0.0f, std::max(scene.position_noise, 0.0f) * scene.spacing);
  std::uniform_real_distribution<float> turn(0.0f, static_cast<float>(kTwoPi));
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vec3f n = points.normals[i];
    const auto [t1, t2] = tangent_frame(n);
    const float phi = turn(rng), angle = scene.normal_noise_degrees > 0 ? tilt(rng) : 0.0f;
    const Vec3f toward = t1 * std::cos(phi) + t2 * std::sin(phi);
    points.normals[i] = normalized(n * std::cos(angle) + toward * std::sin(angle));
    if (scene.position_noise > 0) points.positions[i] = points.positions[i] + n * offset(rng);
  }
}
}  // namespace

CsgSamples sample_csg(const CsgScene& scene, SamplingMode mode, std::uint64_t seed) {
  CsgSamples out;
  std::mt19937_64 rng(seed);
  std::vector<FaceSample> faces;
  for (std::size_t k = 0; k < scene.primitives.size(); ++k) {
    const Primitive& p = scene.primitives[k];
    faces.clear();
    sample_primitive(p, scene.spacing, mode, rng, faces);
    const std::uint32_t first = scene.first_label(k);
    for (const FaceSample& f : faces) {
      bool flip = false;
      if (!on_boundary(scene, k, f.x, flip)) continue;
      const Vec3f n = face_normal(p, f.face, f.x);
      out.points.positions.push_back(f.x);
      out.points.normals.push_back(flip ? -n : n);
      out.labels.push_back(first + f.face);
    }
  }
  add_noise(scene, seed, out.points);
  return out;
}

namespace {
// Primitive and local face of a label.
std::pair<std::size_t, std::uint32_t> face_of(const CsgScene& scene, std::uint32_t label) {
  for (std::size_t k = 0; k < scene.primitives.size(); ++k) {
    const std::uint32_t first = scene.first_label(k), count = face_count(scene.primitives[k]);
    if (label >= first && label < first + count) return {k, label - first};
  }
  throw Error("face label " + std::to_string(label) + " is not a face of scene " + scene.name);
}
}  // namespace

bool csg_face_is_planar(const CsgScene& scene, std::uint32_t label) {
  const auto [k, face] = face_of(scene, label);
  const Primitive& p = scene.primitives[k];
  if (csg_detail::is_open(p)) return csg_detail::open_face_is_planar(p, face);
  return p.kind == PrimitiveKind::Box || (p.kind == PrimitiveKind::Cylinder && face > 0);
}

bool csg_face_contains(const CsgScene& scene, std::uint32_t label, Vec3f x) {
  const auto [k, face] = face_of(scene, label);
  const Primitive& p = scene.primitives[k];
  if (csg_detail::is_open(p)) return csg_detail::open_face_contains(p, face, x);
  constexpr float eps = 1e-6f;
  const Vec3f d = x - p.center;
  if (p.kind == PrimitiveKind::Box) {
    const int a = static_cast<int>(face / 2);
    for (int u = 0; u < 3; ++u) {
      if (u != a && std::fabs(d[u]) > p.half[u] + eps) return false;
    }
  } else if (p.kind == PrimitiveKind::Cylinder && face > 0) {
    const Vec3f radial = d - axis_vector(p.axis, d[p.axis]);
    if (length(radial) > p.radius + eps) return false;
  }
  bool flip = false;
  return on_boundary(scene, k, x, flip);
}

std::optional<CsgHit> ray_cast_csg(const CsgScene& scene, Vec3f origin, Vec3f dir) {
  const std::size_t n = scene.primitives.size();
  std::vector<Interval> iv(n);
  std::vector<std::uint8_t> hit(n);
  struct Event {
    double t;
    std::size_t prim;
    std::uint32_t face;
  };
  std::vector<Event> events;
  for (std::size_t k = 0; k < n; ++k) {
    // An open surface: its first crossing, in Separate scenes only. It is one-sided, seen only
    // from the side its normal faces, as the renderer culls back-facing splats.
    if (csg_detail::is_open(scene.primitives[k])) {
      const Primitive& p = scene.primitives[k];
      if (const auto h = csg_detail::ray_open(p, origin, dir)) {
        const Vec3f x = origin + dir * static_cast<float>(h->t);
        if (dot(csg_detail::open_face_normal(p, h->face, x), dir) < 0) {
          events.push_back({h->t, k, h->face});
        }
      }
      continue;
    }
    hit[k] = ray_interval(scene.primitives[k], origin, dir, iv[k]);
    if (!hit[k]) continue;
    events.push_back({iv[k].t0, k, iv[k].face0});
    events.push_back({iv[k].t1, k, iv[k].face1});
  }
  std::stable_sort(events.begin(), events.end(),
                   [](const Event& a, const Event& b) { return a.t < b.t; });
  for (std::size_t e = 0; e < events.size(); ++e) {
    const double t = events[e].t;
    if (!(t > 0)) continue;
    if (e > 0 && events[e - 1].t == t) continue;  // the first event at this t stands for all
    std::size_t next = e;
    while (next < events.size() && events[next].t == t) ++next;
    const double before = e > 0 ? std::max(0.5 * (events[e - 1].t + t), 0.0) : t - 1.0;
    const double after = next < events.size() ? 0.5 * (t + events[next].t) : t + 1.0;
    const bool changes = scene.op == CsgOp::Separate
                             ? true
                             : member(scene, iv, hit, before) != member(scene, iv, hit, after);
    if (!changes) continue;
    const Event& ev = events[e];
    const Vec3f x = origin + dir * static_cast<float>(t);
    Vec3f normal = face_normal(scene.primitives[ev.prim], ev.face, x);
    if (scene.op == CsgOp::Difference && ev.prim > 0) normal = -normal;
    return CsgHit{static_cast<float>(t), normal, scene.first_label(ev.prim) + ev.face};
  }
  return std::nullopt;
}

CsgImage ray_cast_csg_image(const CsgScene& scene, const Camera& camera) {
  const CameraFrame f = make_camera_frame(camera);
  CsgImage img;
  img.width = f.width;
  img.height = f.height;
  const std::size_t n = static_cast<std::size_t>(f.width) * f.height;
  img.label.assign(n, kNoLabel);
  img.depth.assign(n, kInf);
  img.normal.assign(n, Vec3f{});
  for (int y = 0; y < f.height; ++y) {
    for (int x = 0; x < f.width; ++x) {
      const Vec3f dir = pixel_ray(f, x, y);
      if (auto hit = ray_cast_csg(scene, pixel_ray_origin(f, x, y), dir)) {
        const std::size_t i = static_cast<std::size_t>(y) * f.width + x;
        img.label[i] = hit->label;
        img.depth[i] = hit->t * dot(dir, f.forward);
        img.normal[i] = hit->normal;
      }
    }
  }
  return img;
}

Aabb csg_bounds(const CsgScene& scene) {
  Aabb box;
  for (const Primitive& p : scene.primitives) {
    if (csg_detail::is_open(p)) {
      csg_detail::extend_open_bounds(p, box);
      continue;
    }
    Vec3f half = p.half;
    if (p.kind == PrimitiveKind::Sphere) half = {p.radius, p.radius, p.radius};
    if (p.kind == PrimitiveKind::Cylinder) {
      half = {p.radius, p.radius, p.radius};
      half[p.axis] = p.half_length;
    }
    box.extend(p.center - half);
    box.extend(p.center + half);
  }
  return box;
}

std::vector<std::uint32_t> csg_surface_groups(const CsgScene& scene, const CsgSamples& samples) {
  const std::uint32_t labels = scene.label_count();
  constexpr std::uint32_t kUnset = 0xffffffffu;
  // A planar face's plane (normal, offset) from its first sample, rounded to 0.01.
  std::vector<std::array<long, 4>> plane(labels);
  std::vector<bool> seen(labels, false);
  for (std::size_t i = 0; i < samples.labels.size() && i < samples.points.positions.size(); ++i) {
    const std::uint32_t l = samples.labels[i];
    if (l >= labels || seen[l]) continue;
    seen[l] = true;
    const Vec3f n = samples.points.normals[i];
    const float h = dot(n, samples.points.positions[i]);
    plane[l] = {std::lround(n.x * 100), std::lround(n.y * 100), std::lround(n.z * 100),
                std::lround(h * 100)};
  }
  std::vector<std::uint32_t> group(labels, kUnset);
  std::uint32_t next = 0;
  for (std::uint32_t l = 0; l < labels; ++l) {
    if (group[l] != kUnset) continue;
    group[l] = next;
    if (seen[l] && csg_face_is_planar(scene, l)) {
      for (std::uint32_t k = l + 1; k < labels; ++k) {
        if (seen[k] && group[k] == kUnset && csg_face_is_planar(scene, k) && plane[k] == plane[l]) {
          group[k] = next;
        }
      }
    }
    ++next;
  }
  return group;
}

}  // namespace pointillist
