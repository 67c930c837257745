#include "pointillist/core/camera.hpp"

#include <cmath>
#include <string>

#include "pointillist/core/error.hpp"

namespace pointillist {

Camera orbit_camera(const Sphere& view_sphere, const OrbitOptions& o) {
  if (!(std::abs(o.elevation_deg) <= 90.0f)) {
    throw OptionError("view elevation " + std::to_string(o.elevation_deg) +
                      "° is beyond a pole; use a value between -90 and 90, or give "
                      "--eye/--target/--up");
  }
  if (!(o.fov_deg > 0.0f && o.fov_deg < 180.0f)) {
    throw OptionError("field of view " + std::to_string(o.fov_deg) +
                      "° is out of range; use a value between 0 and 180 (exclusive)");
  }
  if (o.distance < 0.0f || !std::isfinite(o.distance)) {
    throw OptionError("view distance " + std::to_string(o.distance) +
                      " is invalid; give a positive multiple of the model radius (or 0 for auto)");
  }
  const float half_fov = deg_to_rad(o.fov_deg) * 0.5f;
  const float d = o.distance > 0.0f ? o.distance : 1.05f / std::sin(half_fov);
  const float az = deg_to_rad(o.azimuth_deg);
  const float el = deg_to_rad(o.elevation_deg);
  const float radius = view_sphere.radius > 0.0f ? view_sphere.radius : 1.0f;
  const float up_length = length(o.up);
  if (!(up_length > 0.0f) || !std::isfinite(up_length)) {
    throw OptionError("orbit up axis (" + std::to_string(o.up.x) + ", " + std::to_string(o.up.y) +
                      ", " + std::to_string(o.up.z) + ") is not a direction; give a non-zero vector "
                      "such as 0,0,1");
  }
  const Vec3f up = o.up / up_length;
  // X' = +X made perpendicular to up (+Z when up is along X), Z' = X' × up.
  Vec3f x_axis = Vec3f{1, 0, 0} - up * up.x;
  if (length(x_axis) < 1e-3f) x_axis = Vec3f{0, 0, 1} - up * up.z;
  x_axis = x_axis / length(x_axis);
  const Vec3f z_axis = cross(x_axis, up);
  const Vec3f dir = x_axis * (std::cos(el) * std::sin(az)) + up * std::sin(el) +
                    z_axis * (std::cos(el) * std::cos(az));
  Camera cam;
  cam.eye = view_sphere.center + dir * (d * radius);
  cam.target = view_sphere.center;
  // Near a pole the up axis is (nearly) the view direction: the camera's up is then the direction
  // of increasing elevation (at 90°, a plan view with -Z' up in the image for azimuth 0).
  cam.up = std::abs(o.elevation_deg) < 89.99f
               ? up
               : up * std::cos(el) - (x_axis * std::sin(az) + z_axis * std::cos(az)) * std::sin(el);
  cam.fov_deg = o.fov_deg;
  cam.width = o.width;
  cam.height = o.height;
  return cam;
}

CameraFrame make_camera_frame(const Camera& c) {
  if (c.width <= 0 || c.height <= 0) {
    throw OptionError("image size " + std::to_string(c.width) + "x" + std::to_string(c.height) +
                      " is invalid; both sides must be positive");
  }
  if (!(c.ortho_height >= 0.0f) || !std::isfinite(c.ortho_height)) {
    throw OptionError("orthographic view height " + std::to_string(c.ortho_height) +
                      " is invalid; give a positive height in world units (or 0 for perspective)");
  }
  if (c.ortho_height == 0.0f && !(c.fov_deg > 0.0f && c.fov_deg < 180.0f)) {
    throw OptionError("field of view " + std::to_string(c.fov_deg) +
                      "° is out of range; use a value between 0 and 180 (exclusive)");
  }
  const Vec3f view = c.target - c.eye;
  if (!(length(view) > 0.0f) || !is_finite(view)) {
    throw OptionError("camera eye and target coincide (or are not finite); give distinct points");
  }
  CameraFrame f;
  f.eye = c.eye;
  f.forward = normalized(view);
  const Vec3f right = cross(f.forward, c.up);
  if (!(length(right) > 1e-6f * length(c.up))) {
    throw OptionError("camera up vector is parallel to the viewing direction; choose another --up");
  }
  f.right = normalized(right);
  f.up = cross(f.right, f.forward);
  f.width = c.width;
  f.height = c.height;
  if (c.ortho_height > 0.0f) {
    // Parallel side planes at half the view's width and height from the eye's axis.
    f.ortho = true;
    f.focal_px = static_cast<float>(c.height) / c.ortho_height;
    const float half_h = 0.5f * c.ortho_height;
    const float half_w = 0.5f * static_cast<float>(c.width) / f.focal_px;
    const auto side = [&](Vec3f n, float half) { return Plane{n, half - dot(n, f.eye)}; };
    f.planes = {side(f.right, half_w), side(-f.right, half_w), side(f.up, half_h),
                side(-f.up, half_h)};
    return f;
  }
  const float tan_half_v = std::tan(deg_to_rad(c.fov_deg) * 0.5f);
  f.focal_px = (static_cast<float>(c.height) * 0.5f) / tan_half_v;
  const float tan_half_h = static_cast<float>(c.width) * 0.5f / f.focal_px;
  // Side planes through the eye; a point is inside when its lateral offset is within
  // depth * tan(half angle). Normals are the inward unit normals of those planes.
  const auto plane_through_eye = [&](Vec3f n) {
    n = normalized(n);
    return Plane{n, -dot(n, f.eye)};
  };
  f.planes[0] = plane_through_eye(f.right + f.forward * tan_half_h);   // left
  f.planes[1] = plane_through_eye(-f.right + f.forward * tan_half_h);  // right
  f.planes[2] = plane_through_eye(f.up + f.forward * tan_half_v);      // bottom
  f.planes[3] = plane_through_eye(-f.up + f.forward * tan_half_v);     // top
  return f;
}

}  // namespace pointillist
