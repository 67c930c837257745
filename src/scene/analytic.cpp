#include "pointillist/scene/analytic.hpp"

#include <cmath>
#include <limits>
#include <random>

namespace pointillist {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

Vec3f to_local(const AnalyticShape& s, Vec3f p) {
  const Vec3f d = p - s.center;
  return {dot(d, s.axis_x), dot(d, s.axis_y), dot(d, s.axis_z)};
}
Vec3f dir_to_local(const AnalyticShape& s, Vec3f d) {
  return {dot(d, s.axis_x), dot(d, s.axis_y), dot(d, s.axis_z)};
}
Vec3f to_world_dir(const AnalyticShape& s, Vec3f d) {
  return s.axis_x * d.x + s.axis_y * d.y + s.axis_z * d.z;
}

// Rotation of the standard frame by `angle_deg` about a unit axis (Rodrigues).
void set_rotation(AnalyticShape& s, Vec3f axis, float angle_deg) {
  axis = normalized(axis);
  const float a = deg_to_rad(angle_deg);
  const auto rot = [&](Vec3f v) {
    return v * std::cos(a) + cross(axis, v) * std::sin(a) + axis * (dot(axis, v) * (1 - std::cos(a)));
  };
  s.axis_x = rot({1, 0, 0});
  s.axis_y = rot({0, 1, 0});
  s.axis_z = rot({0, 0, 1});
}

double shape_area(const AnalyticShape& s) {
  const double pi = 3.14159265358979323846;
  switch (s.kind) {
    case ShapeKind::Sphere: return 4.0 * pi * s.a * s.a;
    case ShapeKind::Torus: return 4.0 * pi * pi * s.a * s.b;
    case ShapeKind::Cube: return 24.0 * double(s.a) * s.a;
  }
  return 0;
}

// Signed distance in local coordinates, in double for accurate ray marching near the surface.
double local_sdf(const AnalyticShape& s, double x, double y, double z) {
  switch (s.kind) {
    case ShapeKind::Sphere: return std::sqrt(x * x + y * y + z * z) - s.a;
    case ShapeKind::Torus: {
      const double q = std::sqrt(x * x + z * z) - s.a;
      return std::sqrt(q * q + y * y) - s.b;
    }
    case ShapeKind::Cube: {
      const double qx = std::abs(x) - s.a, qy = std::abs(y) - s.a, qz = std::abs(z) - s.a;
      const double ox = std::max(qx, 0.0), oy = std::max(qy, 0.0), oz = std::max(qz, 0.0);
      return std::sqrt(ox * ox + oy * oy + oz * oz) + std::min(std::max(qx, std::max(qy, qz)), 0.0);
    }
  }
  return 0;
}

Vec3f local_normal(const AnalyticShape& s, Vec3f p) {
  switch (s.kind) {
    case ShapeKind::Sphere: return normalized(p);
    case ShapeKind::Torus: {
      const float rho = std::sqrt(p.x * p.x + p.z * p.z);
      const Vec3f ring = rho > 0 ? Vec3f{p.x / rho * s.a, 0, p.z / rho * s.a} : Vec3f{s.a, 0, 0};
      return normalized(p - ring);
    }
    case ShapeKind::Cube: {
      const float ax = std::abs(p.x), ay = std::abs(p.y), az = std::abs(p.z);
      if (ax >= ay && ax >= az) return {p.x >= 0 ? 1.f : -1.f, 0, 0};
      if (ay >= az) return {0, p.y >= 0 ? 1.f : -1.f, 0};
      return {0, 0, p.z >= 0 ? 1.f : -1.f};
    }
  }
  return {0, 0, 1};
}

// Exact ray/sphere intersection in local coordinates; returns the smallest t > 0 or +inf.
double intersect_sphere(double r, const double o[3], const double d[3]) {
  const double b = o[0] * d[0] + o[1] * d[1] + o[2] * d[2];
  const double c = o[0] * o[0] + o[1] * o[1] + o[2] * o[2] - r * r;
  const double disc = b * b - c;
  if (disc < 0) return kInf;
  const double sq = std::sqrt(disc);
  const double t0 = -b - sq, t1 = -b + sq;
  if (t0 > 1e-9) return t0;
  if (t1 > 1e-9) return t1;
  return kInf;
}

// Slab test for the cube.
double intersect_cube(double h, const double o[3], const double d[3]) {
  double tmin = -1e300, tmax = 1e300;
  for (int i = 0; i < 3; ++i) {
    if (std::abs(d[i]) < 1e-300) {
      if (std::abs(o[i]) > h) return kInf;
      continue;
    }
    double t0 = (-h - o[i]) / d[i], t1 = (h - o[i]) / d[i];
    if (t0 > t1) std::swap(t0, t1);
    tmin = std::max(tmin, t0);
    tmax = std::min(tmax, t1);
  }
  if (tmin > tmax) return kInf;
  if (tmin > 1e-9) return tmin;
  if (tmax > 1e-9) return tmax;
  return kInf;
}

// Torus: sphere tracing on the exact SDF from the entry of its bounding sphere, then bisection.
double intersect_torus(const AnalyticShape& s, const double o[3], const double d[3]) {
  const double bound = s.a + s.b;
  double t = intersect_sphere(bound, o, d);
  const double inside = o[0] * o[0] + o[1] * o[1] + o[2] * o[2] <= bound * bound;
  if (inside) t = 0;
  if (!std::isfinite(t)) return kInf;
  const double tmax = t + 2 * bound + 1e-6;
  const double eps = 1e-7 * bound;
  for (int i = 0; i < 512 && t < tmax; ++i) {
    const double dist = local_sdf(s, o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]);
    if (dist < eps) return t;
    t += dist;
  }
  return kInf;
}

struct LocalClosest {
  double point[3];
  double normal[3];
  double distance;
};

// Closest surface point of one shape in its local frame (coordinates in double).
LocalClosest local_closest(const AnalyticShape& s, const double p[3]) {
  LocalClosest c{};
  const double a = s.a;
  switch (s.kind) {
    case ShapeKind::Sphere: {
      const double len = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
      for (int i = 0; i < 3; ++i) c.normal[i] = len > 0 ? p[i] / len : (i == 0 ? 1.0 : 0.0);
      for (int i = 0; i < 3; ++i) c.point[i] = c.normal[i] * a;
      c.distance = std::abs(len - a);
      break;
    }
    case ShapeKind::Torus: {
      // The torus is the set at distance b from the tube's centre circle, and the distance to
      // that circle is 1-Lipschitz, so the nearest surface point lies on the line from the
      // nearest circle point through p, inside the tube as well as outside.
      const double rho = std::sqrt(p[0] * p[0] + p[2] * p[2]);
      const double radial[3] = {rho > 0 ? p[0] / rho : 1.0, 0.0, rho > 0 ? p[2] / rho : 0.0};
      const double ring[3] = {radial[0] * a, 0.0, radial[2] * a};
      const double d[3] = {p[0] - ring[0], p[1], p[2] - ring[2]};
      const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
      for (int i = 0; i < 3; ++i) c.normal[i] = len > 0 ? d[i] / len : radial[i];
      for (int i = 0; i < 3; ++i) c.point[i] = ring[i] + c.normal[i] * s.b;
      c.distance = std::abs(len - s.b);
      break;
    }
    case ShapeKind::Cube: {
      bool outside = false;
      for (int i = 0; i < 3; ++i) {
        c.point[i] = std::clamp(p[i], -a, a);
        outside = outside || std::abs(p[i]) > a;
      }
      if (outside) {
        const double d[3] = {p[0] - c.point[0], p[1] - c.point[1], p[2] - c.point[2]};
        c.distance = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        for (int i = 0; i < 3; ++i) c.normal[i] = d[i] / c.distance;
        break;
      }
      int axis = 0;
      for (int i = 1; i < 3; ++i) {
        if (std::abs(p[i]) > std::abs(p[axis])) axis = i;
      }
      const double sign = p[axis] >= 0 ? 1.0 : -1.0;
      c.point[axis] = sign * a;
      c.normal[axis] = sign;
      c.distance = a - std::abs(p[axis]);
      break;
    }
  }
  return c;
}

}  // namespace

AnalyticScene demo_scene() {
  AnalyticScene scene;
  AnalyticShape sphere{ShapeKind::Sphere, {-2.3f, 0.0f, 0.0f}, 0.9f, 0.0f};
  AnalyticShape torus{ShapeKind::Torus, {0.0f, 0.0f, 0.0f}, 0.75f, 0.28f};
  set_rotation(torus, {1, 0, 0}, 60.0f);
  AnalyticShape cube{ShapeKind::Cube, {2.3f, 0.0f, 0.0f}, 0.65f, 0.0f};
  set_rotation(cube, normalized(Vec3f{0.3f, 1.0f, 0.2f}), 35.0f);
  scene.shapes = {sphere, torus, cube};
  return scene;
}

AnalyticScene statue_scene() {
  AnalyticShape pedestal{ShapeKind::Cube, {0.0f, 0.35f, 0.0f}, 0.35f, 0.0f};
  AnalyticShape head{ShapeKind::Sphere, {0.0f, 1.1f, 0.0f}, 0.4f, 0.0f};
  AnalyticShape ring{ShapeKind::Torus, {0.0f, 1.1f, 0.0f}, 0.55f, 0.1f};
  set_rotation(ring, {1, 0, 0}, 60.0f);
  return {{pedestal, head, ring}};
}

AnalyticScene sphere_scene(float radius) {
  return {{AnalyticShape{ShapeKind::Sphere, {0, 0, 0}, radius, 0}}};
}
AnalyticScene torus_scene(float major, float minor) {
  return {{AnalyticShape{ShapeKind::Torus, {0, 0, 0}, major, minor}}};
}
AnalyticScene cube_scene(float half_side) {
  return {{AnalyticShape{ShapeKind::Cube, {0, 0, 0}, half_side, 0}}};
}

double surface_area(const AnalyticScene& scene) {
  double total = 0;
  for (const auto& s : scene.shapes) total += shape_area(s);
  return total;
}

SurfaceSamples sample_scene(const AnalyticScene& scene, std::size_t count, std::uint64_t seed) {
  SurfaceSamples out;
  out.points.positions.reserve(count);
  out.true_normals.reserve(count);
  out.shape_ids.reserve(count);
  out.edge_distance.reserve(count);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  std::vector<double> cumulative;
  double total = 0;
  for (const auto& s : scene.shapes) cumulative.push_back(total += shape_area(s));
  const double two_pi = 2.0 * 3.14159265358979323846;
  for (std::size_t i = 0; i < count && total > 0; ++i) {
    const double pick = uni(rng) * total;
    std::uint32_t id = 0;
    while (id + 1 < cumulative.size() && pick >= cumulative[id]) ++id;
    const AnalyticShape& s = scene.shapes[id];
    Vec3f p, n;
    float edge = kInf;
    switch (s.kind) {
      case ShapeKind::Sphere: {
        const double z = 2 * uni(rng) - 1, phi = two_pi * uni(rng);
        const double r = std::sqrt(std::max(0.0, 1 - z * z));
        n = {float(r * std::cos(phi)), float(r * std::sin(phi)), float(z)};
        p = n * s.a;
        break;
      }
      case ShapeKind::Torus: {
        // Area element ∝ (a + b cos θ): rejection-sample θ.
        double theta;
        for (;;) {
          theta = two_pi * uni(rng);
          if (uni(rng) * (s.a + s.b) <= s.a + s.b * std::cos(theta)) break;
        }
        const double phi = two_pi * uni(rng);
        n = {float(std::cos(theta) * std::cos(phi)), float(std::sin(theta)),
             float(std::cos(theta) * std::sin(phi))};
        const double ring = s.a + s.b * std::cos(theta);
        p = {float(ring * std::cos(phi)), float(s.b * std::sin(theta)), float(ring * std::sin(phi))};
        break;
      }
      case ShapeKind::Cube: {
        const int face = std::min(5, int(uni(rng) * 6));
        const int axis = face / 2;
        const float sign = (face % 2) ? -1.0f : 1.0f;
        const float u = float((2 * uni(rng) - 1) * s.a), v = float((2 * uni(rng) - 1) * s.a);
        p = {0, 0, 0};
        n = {0, 0, 0};
        p[axis] = sign * s.a;
        n[axis] = sign;
        p[(axis + 1) % 3] = u;
        p[(axis + 2) % 3] = v;
        edge = std::min(s.a - std::abs(u), s.a - std::abs(v));
        break;
      }
    }
    out.points.positions.push_back(s.center + to_world_dir(s, p));
    out.true_normals.push_back(to_world_dir(s, n));
    out.shape_ids.push_back(id);
    out.edge_distance.push_back(edge);
  }
  return out;
}

std::optional<RayHit> ray_cast(const AnalyticScene& scene, Vec3f origin, Vec3f dir) {
  std::optional<RayHit> best;
  for (std::uint32_t id = 0; id < scene.shapes.size(); ++id) {
    const AnalyticShape& s = scene.shapes[id];
    const Vec3f lo = to_local(s, origin), ld = dir_to_local(s, dir);
    const double o[3] = {lo.x, lo.y, lo.z}, d[3] = {ld.x, ld.y, ld.z};
    double t = kInf;
    switch (s.kind) {
      case ShapeKind::Sphere: t = intersect_sphere(s.a, o, d); break;
      case ShapeKind::Cube: t = intersect_cube(s.a, o, d); break;
      case ShapeKind::Torus: t = intersect_torus(s, o, d); break;
    }
    if (std::isfinite(t) && (!best || t < best->t)) {
      const Vec3f hit_local{float(o[0] + t * d[0]), float(o[1] + t * d[1]), float(o[2] + t * d[2])};
      best = RayHit{float(t), to_world_dir(s, local_normal(s, hit_local)), id};
    }
  }
  return best;
}

RayCastImage ray_cast_image(const AnalyticScene& scene, const Camera& camera) {
  const CameraFrame f = make_camera_frame(camera);
  RayCastImage img;
  img.width = f.width;
  img.height = f.height;
  const std::size_t n = std::size_t(f.width) * f.height;
  img.covered.assign(n, 0);
  img.depth.assign(n, kInf);
  img.normal.assign(n, Vec3f{});
  for (int y = 0; y < f.height; ++y) {
    for (int x = 0; x < f.width; ++x) {
      const Vec3f dir = pixel_ray(f, x, y);
      if (auto hit = ray_cast(scene, pixel_ray_origin(f, x, y), dir)) {
        const std::size_t i = std::size_t(y) * f.width + x;
        img.covered[i] = 1;
        img.depth[i] = hit->t * dot(dir, f.forward);
        img.normal[i] = hit->normal;
      }
    }
  }
  return img;
}

Aabb scene_bounds(const AnalyticScene& scene) {
  Aabb box;
  for (const auto& s : scene.shapes) {
    float r = s.a;
    if (s.kind == ShapeKind::Torus) r = s.a + s.b;
    if (s.kind == ShapeKind::Cube) r = s.a * std::sqrt(3.0f);
    box.extend(s.center - Vec3f{r, r, r});
    box.extend(s.center + Vec3f{r, r, r});
  }
  return box;
}

AnalyticClosest closest_point(const AnalyticScene& scene, Vec3f p) {
  AnalyticClosest best{{}, {0, 0, 1}, kInf};
  double best_distance = kInf;
  for (const AnalyticShape& s : scene.shapes) {
    const Vec3f axes[3] = {s.axis_x, s.axis_y, s.axis_z};
    const double d[3] = {double(p.x) - s.center.x, double(p.y) - s.center.y,
                         double(p.z) - s.center.z};
    double local[3];
    for (int i = 0; i < 3; ++i) local[i] = d[0] * axes[i].x + d[1] * axes[i].y + d[2] * axes[i].z;
    const LocalClosest c = local_closest(s, local);
    if (!(c.distance < best_distance)) continue;
    best_distance = c.distance;
    double point[3] = {s.center.x, s.center.y, s.center.z}, normal[3] = {0, 0, 0};
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) {
        point[j] += c.point[i] * axes[i][j];
        normal[j] += c.normal[i] * axes[i][j];
      }
    }
    best.point = {float(point[0]), float(point[1]), float(point[2])};
    best.normal = normalized(Vec3f{float(normal[0]), float(normal[1]), float(normal[2])});
    best.distance = float(c.distance);
  }
  return best;
}

}  // namespace pointillist
