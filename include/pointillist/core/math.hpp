// Small value types for geometry: vectors, boxes, spheres, colors.
// Plain aggregates with inline operators so hot loops compile to straight-line code.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace pointillist {

struct Vec3f {
  float x = 0, y = 0, z = 0;

  constexpr float& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
  constexpr float operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
};

constexpr Vec3f operator+(Vec3f a, Vec3f b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
constexpr Vec3f operator-(Vec3f a, Vec3f b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
constexpr Vec3f operator-(Vec3f a) { return {-a.x, -a.y, -a.z}; }
constexpr Vec3f operator*(Vec3f a, float s) { return {a.x * s, a.y * s, a.z * s}; }
constexpr Vec3f operator*(float s, Vec3f a) { return {a.x * s, a.y * s, a.z * s}; }
constexpr Vec3f operator/(Vec3f a, float s) { return {a.x / s, a.y / s, a.z / s}; }
constexpr Vec3f& operator+=(Vec3f& a, Vec3f b) { return a = a + b; }
constexpr Vec3f& operator-=(Vec3f& a, Vec3f b) { return a = a - b; }
constexpr Vec3f& operator*=(Vec3f& a, float s) { return a = a * s; }
constexpr bool operator==(Vec3f a, Vec3f b) { return a.x == b.x && a.y == b.y && a.z == b.z; }

constexpr float dot(Vec3f a, Vec3f b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
constexpr Vec3f cross(Vec3f a, Vec3f b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
constexpr float length_squared(Vec3f a) { return dot(a, a); }
inline float length(Vec3f a) { return std::sqrt(dot(a, a)); }
inline float distance(Vec3f a, Vec3f b) { return length(a - b); }
constexpr Vec3f min(Vec3f a, Vec3f b) {
  return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)};
}
constexpr Vec3f max(Vec3f a, Vec3f b) {
  return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)};
}

// Unit vector along `a`; returns `fallback` when `a` is (nearly) zero so callers never divide by 0.
inline Vec3f normalized(Vec3f a, Vec3f fallback = {0, 0, 1}) {
  const float len = length(a);
  return len > 1e-30f ? a / len : fallback;
}

// Two unit vectors (u, v) completing a unit normal n to a right-handed frame, u = n × helper
// normalised (helper +X, or +Y when n is near ±X), v = n × u: deterministic in n.
struct TangentFrame {
  Vec3f u, v;
};
inline TangentFrame tangent_frame(Vec3f n) {
  const Vec3f u = normalized(cross(n, std::fabs(n.x) < 0.9f ? Vec3f{1, 0, 0} : Vec3f{0, 1, 0}));
  return {u, cross(n, u)};
}

inline bool is_finite(Vec3f a) {
  return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z);
}

// Double-precision vector for the geometry that needs it (bounding-sphere and eigenvector
// solves, exact distances): the same operators as Vec3f, each evaluated in the same order.
struct Vec3d {
  double x = 0, y = 0, z = 0;
};
constexpr Vec3d to_double(Vec3f v) { return {v.x, v.y, v.z}; }
constexpr Vec3d operator+(Vec3d a, Vec3d b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
constexpr Vec3d operator-(Vec3d a, Vec3d b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
constexpr Vec3d operator*(Vec3d a, double s) { return {a.x * s, a.y * s, a.z * s}; }
constexpr double dot(Vec3d a, Vec3d b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
constexpr Vec3d cross(Vec3d a, Vec3d b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

// Axis-aligned bounding box. A default box is empty (lo > hi) and grows with `extend`.
struct Aabb {
  Vec3f lo{std::numeric_limits<float>::max(), std::numeric_limits<float>::max(),
           std::numeric_limits<float>::max()};
  Vec3f hi{-std::numeric_limits<float>::max(), -std::numeric_limits<float>::max(),
           -std::numeric_limits<float>::max()};

  constexpr bool empty() const { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }
  constexpr void extend(Vec3f p) {
    lo = min(lo, p);
    hi = max(hi, p);
  }
  constexpr void extend(const Aabb& b) {
    lo = min(lo, b.lo);
    hi = max(hi, b.hi);
  }
  constexpr Vec3f center() const { return (lo + hi) * 0.5f; }
  constexpr Vec3f extent() const { return hi - lo; }
  // Index (0, 1, 2) of the longest side; ties go to the lower axis.
  constexpr int longest_axis() const {
    const Vec3f e = extent();
    return (e.x >= e.y && e.x >= e.z) ? 0 : (e.y >= e.z ? 1 : 2);
  }
  // Squared distance from p to the box (0 inside).
  constexpr float distance_squared(Vec3f p) const {
    const float dx = std::max(std::max(lo.x - p.x, p.x - hi.x), 0.0f);
    const float dy = std::max(std::max(lo.y - p.y, p.y - hi.y), 0.0f);
    const float dz = std::max(std::max(lo.z - p.z, p.z - hi.z), 0.0f);
    return dx * dx + dy * dy + dz * dz;
  }
};

struct Sphere {
  Vec3f center;
  float radius = 0;
};

// 8-bit sRGB-ish color as stored in files and images.
struct Rgb8 {
  std::uint8_t r = 0, g = 0, b = 0;
};
constexpr bool operator==(Rgb8 a, Rgb8 b) { return a.r == b.r && a.g == b.g && a.b == b.b; }

constexpr float kPi = 3.14159265358979323846f;
constexpr float deg_to_rad(float deg) { return deg * (kPi / 180.0f); }

}  // namespace pointillist
