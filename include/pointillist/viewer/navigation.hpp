// Camera controls of the viewer, as in CloudCompare and MeshLab: a turntable orbit around a pivot
// that keeps the model's up axis up, panning, zooming towards the cursor, the six axis views and
// a reset. Pure camera arithmetic (no window): the viewer feeds it the mouse and keys.
#pragma once

#include <optional>

#include "pointillist/core/camera.hpp"
#include "pointillist/core/math.hpp"

namespace pointillist {

enum class AxisView { Front, Back, Left, Right, Top, Bottom };

// The camera is the pivot (its target), a distance and two angles about the model's up axis:
// eye = pivot + distance · (cos(el)·sin(az)·X' + sin(el)·up + cos(el)·cos(az)·Z'), with X', Z' the
// basis of orbit_camera (core/camera.hpp), so azimuth and elevation mean what `render --view`
// means. The camera's up vector is the direction of increasing elevation, so the top and bottom
// views (el = ±90°) are defined too.
class Navigator {
 public:
  // Degrees the orbit turns per pixel dragged, as a share of the window height: dragging across
  // the whole height turns half a turn.
  static constexpr float kOrbitDegreesPerHeight = 180.0f;
  // One wheel click in brings the camera this factor closer to the point under the cursor.
  static constexpr float kZoomPerClick = 0.8f;

  // `home` is the camera shown first and by reset(); `view_sphere` frames the axis views;
  // `model_up` is the axis kept up. Throws OptionError for a camera make_camera_frame refuses
  // or a zero up axis.
  Navigator(const Camera& home, const Sphere& view_sphere, Vec3f model_up);

  Camera camera() const;
  float azimuth_deg() const { return azimuth_deg_; }
  float elevation_deg() const { return elevation_deg_; }
  float distance() const { return distance_; }
  Vec3f pivot() const { return pivot_; }

  // Left drag by (dx, dy) pixels (x right, y down): the model follows the mouse, turning about
  // the up axis through the pivot for dx (dragging right turns the front of the model to the
  // right: the azimuth decreases) and tilting for dy (dragging down shows more of the top: the
  // elevation increases, up to ±90°).
  void orbit(float dx_px, float dy_px);
  // Right or middle drag: the point at the pivot's depth under the cursor follows the cursor.
  void pan(float dx_px, float dy_px);
  // Wheel: `clicks` > 0 zooms in. The point under the cursor at (x, y) stays under the cursor:
  // at `depth` (its depth along the view direction, from the depth buffer) when given, else at
  // the pivot's depth. The camera never comes closer than a millionth of the view radius.
  // Orthographic: the view height shrinks instead, about the point under the cursor.
  void zoom(float clicks, float x_px, float y_px, std::optional<float> depth = std::nullopt);
  // Makes the point seen at pixel (x, y) at `depth` the pivot; the eye stays where it is.
  void pick_pivot(float x_px, float y_px, float depth);
  void axis_view(AxisView view);
  void reset();
  // Switches between perspective and an orthographic camera that shows the pivot's plane at
  // the same scale (height 2·distance·tan(fov/2)).
  void toggle_ortho();
  bool ortho() const { return ortho_height_ > 0; }
  void resize(int width, int height);

 private:
  void set_from_camera(const Camera& c);
  Vec3f direction() const;  // unit vector from the pivot to the eye
  Vec3f point_under(float x_px, float y_px, float depth) const;
  Camera home_;
  Sphere sphere_;
  Vec3f up_, x_axis_, z_axis_;
  Vec3f pivot_{0, 0, 0};
  float distance_ = 1, azimuth_deg_ = 0, elevation_deg_ = 0;
  float fov_deg_ = 30;
  float ortho_height_ = 0;  // > 0: orthographic (Camera::ortho_height)
  int width_ = 1, height_ = 1;
};

}  // namespace pointillist
