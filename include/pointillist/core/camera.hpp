// Pinhole camera (ARCHITECTURE.md, "Coordinate and camera conventions"): right-handed world,
// +Y up, the camera looks down its -Z axis, image rows go top to bottom, perspective with a
// vertical field of view.
#pragma once

#include <array>

#include "pointillist/core/math.hpp"

namespace pointillist {

struct Camera {
  Vec3f eye{0, 0, 1};
  Vec3f target{0, 0, 0};
  Vec3f up{0, 1, 0};
  float fov_deg = 30.0f;  // vertical field of view (perspective)
  int width = 1024;       // image size in pixels
  int height = 768;
  // > 0: an orthographic camera showing this height of the world (world units) from top to
  // bottom of the image, along parallel rays; fov_deg is then unused. 0: perspective.
  float ortho_height = 0.0f;
};

// An orbit around a model's view sphere (centre c, radius R = largest distance from c to a
// sample): eye = c + D·R·(cos(el)·sin(az), sin(el), cos(el)·cos(az)), looking at c, up +Y.
struct OrbitOptions {
  float azimuth_deg = 0.0f;
  float elevation_deg = 0.0f;
  float distance = 0.0f;  // D in units of R; 0 = 1.05 / sin(fov/2), the whole model in view
  float fov_deg = 30.0f;
  int width = 1024;
  int height = 768;
  // The model's up axis: elevation is measured from the plane perpendicular to it and the camera
  // keeps it pointing up in the image. +Y by default (the world convention); scans that use +Z
  // up (most LAS files) pass {0, 0, 1}. Azimuth 0 looks along −Z' where X' is +X made
  // perpendicular to `up` (+Z for up along ±X) and Z' = X' × up: (+Z for +Y up, −Y for +Z up).
  Vec3f up = {0.0f, 1.0f, 0.0f};
};

// Elevations of ±90° are plan views from above (below): the camera's up is then the direction of
// increasing elevation (−Z' for azimuth 0). Throws OptionError when the elevation is beyond ±90°,
// `up` is zero or not finite, or the size/fov/distance is out of range.
Camera orbit_camera(const Sphere& view_sphere, const OrbitOptions& options);

// A plane n·p + d = 0 with unit normal n; signed distance n·p + d, positive inside.
struct Plane {
  Vec3f normal;
  float d = 0;
  float distance(Vec3f p) const { return dot(normal, p) + d; }
};

// Everything the renderer derives from a Camera: an orthonormal eye basis, the focal length in
// pixels, and the four side planes of the view frustum (no near/far planes: depth is tested
// separately).
struct CameraFrame {
  Vec3f eye;
  Vec3f right;    // +x on screen
  Vec3f up;       // +y on screen (rows go down, so pixel y decreases along it)
  Vec3f forward;  // viewing direction (= -Z of the camera); depth = dot(p - eye, forward)
  // Perspective: f = (H/2) / tan(fov/2), a point at eye-space (x, y, z) is at pixel
  // (W/2 + f·x/z, H/2 − f·y/z). Orthographic: f = H / ortho_height (pixels per world unit), and
  // the pixel is (W/2 + f·x, H/2 − f·y).
  float focal_px = 1;
  bool ortho = false;
  int width = 1, height = 1;
  std::array<Plane, 4> planes;  // left, right, bottom, top; normals point into the frustum

  // Depth (eye-space distance along the view direction; positive in front).
  float depth(Vec3f p) const { return dot(p - eye, forward); }
  // What eye-space x and y are multiplied by, with focal_px, to give pixels at depth z: 1/z in
  // perspective, 1 orthographic.
  float projection(float z) const { return ortho ? 1.0f : 1.0f / z; }
  // Eye-space coordinates of a world direction: x right, y up, z toward the viewer.
  Vec3f eye_direction(Vec3f world_dir) const {
    return {dot(world_dir, right), dot(world_dir, up), -dot(world_dir, forward)};
  }
  // Unit vector from p towards the eye (the viewing rays' reverse).
  Vec3f to_eye(Vec3f p) const { return ortho ? -forward : normalized(eye - p); }
};

// Unit direction (world) of the ray through the centre of pixel (x, y): from the eye in
// perspective; along the view direction, from pixel_ray_origin, orthographic.
inline Vec3f pixel_ray(const CameraFrame& f, int x, int y) {
  if (f.ortho) return f.forward;
  const float sx = (static_cast<float>(x) + 0.5f - static_cast<float>(f.width) * 0.5f) / f.focal_px;
  const float sy = (static_cast<float>(f.height) * 0.5f - (static_cast<float>(y) + 0.5f)) / f.focal_px;
  return normalized(f.forward + f.right * sx + f.up * sy);
}
// Where the ray of pixel (x, y) starts: the eye in perspective, the pixel's place on the plane
// through the eye orthographic.
inline Vec3f pixel_ray_origin(const CameraFrame& f, int x, int y) {
  if (!f.ortho) return f.eye;
  const float sx = (static_cast<float>(x) + 0.5f - static_cast<float>(f.width) * 0.5f) / f.focal_px;
  const float sy = (static_cast<float>(f.height) * 0.5f - (static_cast<float>(y) + 0.5f)) / f.focal_px;
  return f.eye + f.right * sx + f.up * sy;
}

// Throws OptionError when eye == target, up is parallel to the view direction, fov is not in
// (0, 180) (perspective), ortho_height is negative or not finite, or the size is not positive.
CameraFrame make_camera_frame(const Camera& camera);

}  // namespace pointillist
