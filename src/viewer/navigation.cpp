#include "pointillist/viewer/navigation.hpp"

#include <algorithm>
#include <cmath>

#include "pointillist/core/error.hpp"

namespace pointillist {
namespace {

float rad_to_deg(float r) { return r * (180.0f / 3.14159265358979f); }

}  // namespace

Navigator::Navigator(const Camera& home, const Sphere& view_sphere, Vec3f model_up)
    : home_(home), sphere_(view_sphere) {
  make_camera_frame(home);  // throws for a camera that cannot be drawn
  const float n = length(model_up);
  if (!(n > 0.0f) || !is_finite(model_up)) {
    throw OptionError("the viewer's up axis is not a direction; give a non-zero --up such as 0,0,1");
  }
  up_ = model_up / n;
  // The basis of orbit_camera: X' = +X made perpendicular to up (+Z when up is along X).
  x_axis_ = Vec3f{1, 0, 0} - up_ * up_.x;
  if (length(x_axis_) < 1e-3f) x_axis_ = Vec3f{0, 0, 1} - up_ * up_.z;
  x_axis_ = x_axis_ / length(x_axis_);
  z_axis_ = cross(x_axis_, up_);
  if (!(sphere_.radius > 0.0f)) sphere_.radius = 1.0f;
  set_from_camera(home);
}

void Navigator::set_from_camera(const Camera& c) {
  pivot_ = c.target;
  distance_ = length(c.eye - c.target);
  const Vec3f d = (c.eye - c.target) / distance_;
  elevation_deg_ = rad_to_deg(std::asin(std::clamp(dot(d, up_), -1.0f, 1.0f)));
  azimuth_deg_ = rad_to_deg(std::atan2(dot(d, x_axis_), dot(d, z_axis_)));
  fov_deg_ = c.fov_deg;
  ortho_height_ = c.ortho_height;
  width_ = c.width;
  height_ = c.height;
}

Vec3f Navigator::direction() const {
  const float az = deg_to_rad(azimuth_deg_), el = deg_to_rad(elevation_deg_);
  return x_axis_ * (std::cos(el) * std::sin(az)) + up_ * std::sin(el) +
         z_axis_ * (std::cos(el) * std::cos(az));
}

Camera Navigator::camera() const {
  const float az = deg_to_rad(azimuth_deg_), el = deg_to_rad(elevation_deg_);
  Camera c;
  c.eye = pivot_ + direction() * distance_;
  c.target = pivot_;
  // d(direction)/d(el): perpendicular to the view, pointing up in the image, also at the poles.
  c.up = up_ * std::cos(el) - (x_axis_ * std::sin(az) + z_axis_ * std::cos(az)) * std::sin(el);
  c.fov_deg = fov_deg_;
  c.width = width_;
  c.height = height_;
  c.ortho_height = ortho_height_;
  return c;
}

void Navigator::toggle_ortho() {
  ortho_height_ = ortho_height_ > 0
                      ? 0.0f
                      : 2.0f * distance_ * std::tan(0.5f * deg_to_rad(fov_deg_));
}

void Navigator::orbit(float dx_px, float dy_px) {
  const float k = kOrbitDegreesPerHeight / static_cast<float>(height_);
  azimuth_deg_ = std::remainder(azimuth_deg_ - dx_px * k, 360.0f);
  elevation_deg_ = std::clamp(elevation_deg_ + dy_px * k, -90.0f, 90.0f);
}

void Navigator::pan(float dx_px, float dy_px) {
  const CameraFrame f = make_camera_frame(camera());
  const float world_per_px = (f.ortho ? 1.0f : distance_) / f.focal_px;
  pivot_ -= (f.right * dx_px - f.up * dy_px) * world_per_px;
}

Vec3f Navigator::point_under(float x_px, float y_px, float depth) const {
  const CameraFrame f = make_camera_frame(camera());
  const float sx = (x_px - 0.5f * static_cast<float>(width_)) / f.focal_px;
  const float sy = (0.5f * static_cast<float>(height_) - y_px) / f.focal_px;
  if (f.ortho) return f.eye + f.right * sx + f.up * sy + f.forward * depth;
  return f.eye + (f.forward + f.right * sx + f.up * sy) * depth;
}

void Navigator::zoom(float clicks, float x_px, float y_px, std::optional<float> depth) {
  const float z = depth && std::isfinite(*depth) && *depth > 0 ? *depth : distance_;
  const Vec3f p = point_under(x_px, y_px, z);
  float s = std::pow(kZoomPerClick, clicks);
  const float closest = sphere_.radius * 1e-6f;
  if (ortho_height_ > 0) {
    // Parallel rays: shrink the view about p's ray (p's lateral place stays under the cursor).
    if (ortho_height_ * s < closest) s = closest / ortho_height_;
    const Vec3f forward = -direction();
    const Vec3f lateral = (pivot_ - p) - forward * dot(pivot_ - p, forward);
    pivot_ = pivot_ - lateral + lateral * s;
    ortho_height_ *= s;
    return;
  }
  if (distance_ * s < closest) s = closest / distance_;
  // Scaling the camera about p keeps the ray through p, so p stays under the cursor.
  pivot_ = p + (pivot_ - p) * s;
  distance_ *= s;
}

void Navigator::pick_pivot(float x_px, float y_px, float depth) {
  if (!(depth > 0) || !std::isfinite(depth)) return;
  const Camera c = camera();
  Camera looking = c;
  looking.target = point_under(x_px, y_px, depth);
  if (!(length(looking.eye - looking.target) > 0)) return;
  set_from_camera(looking);
}

void Navigator::axis_view(AxisView view) {
  pivot_ = sphere_.center;
  distance_ = length(home_.eye - home_.target);
  struct Angles { float az, el; };
  constexpr Angles kAngles[] = {{0, 0}, {180, 0}, {-90, 0}, {90, 0}, {0, 90}, {0, -90}};
  azimuth_deg_ = kAngles[static_cast<int>(view)].az;
  elevation_deg_ = kAngles[static_cast<int>(view)].el;
}

void Navigator::reset() {
  const int w = width_, h = height_;
  set_from_camera(home_);
  resize(w, h);
}

void Navigator::resize(int width, int height) {
  if (width > 0 && height > 0) {
    width_ = width;
    height_ = height;
  }
}

}  // namespace pointillist
