// Settings shared by the splat renderer and the reference triangle rasterizer.
#pragma once

#include "pointillist/core/math.hpp"

namespace pointillist {

enum class SplatShape {
  Square,   // axis-aligned square of side = projected diameter
  Circle,   // disc of the projected diameter (default)
  Ellipse,  // disc seen at an angle: major axis = projected diameter, minor/major = max(|n·v|, 0.1)
};

// The name the command line and the reports use: "square", "circle", "ellipse".
constexpr const char* name(SplatShape s) {
  return s == SplatShape::Square ? "square" : s == SplatShape::Circle ? "circle" : "ellipse";
}

// Shading model (per splat, or per pixel for the triangle reference), with every vector in eye
// space, n the unit normal, v the unit vector to the eye, l = normalized light_dir_eye and
// h = normalize(l + v):
//   color = base·(ambient + diffuse·max(n·l, 0)) + specular·max(n·h, 0)^shininess   (n·l > 0)
//   color = base·ambient                                                             (n·l ≤ 0)
// clamped to [0, 1] and written as round(255·color). `base` is base_color, or the model's 8-bit
// color divided by 255 when it has colors (the 8-bit values are treated as linear, no sRGB
// decoding). The specular power is read from a 1024-interval table with linear interpolation
// (exact at n·h = 0 and 1; elsewhere off by at most 1.2e-4 at shininess 32, 2e-3 at 128). Splats
// are shaded once, with n the node normal and v the direction from the node centre to the eye.
struct RenderSettings {
  // Stop refining when a node's projected diameter 2·r·f/z is at most this many pixels. Larger
  // values draw fewer, bigger splats (faster, coarser).
  float threshold_px = 1.0f;
  SplatShape shape = SplatShape::Circle;
  Rgb8 background{0, 0, 0};
  // Light direction in eye space (toward the light; x right, y up, z toward the viewer); the
  // default is a headlight at the eye. Need not be unit length, must not be zero.
  Vec3f light_dir_eye{0, 0, 1};
  bool frustum_culling = true;   // turn off only to check that culling changes nothing
  bool backface_culling = true;  // normal-cone culling of whole subtrees
  // Surface color when the model has no colors (linear 0..1).
  Vec3f base_color{0.8f, 0.8f, 0.8f};
  float ambient = 0.08f;
  float diffuse = 0.85f;
  float specular = 0.25f;   // Blinn-Phong, white
  float shininess = 32.0f;  // Blinn-Phong exponent, >= 0
  // Two-sided lighting: nothing is culled for facing away (no backface culling of subtrees or
  // splats), and a surface seen from behind is lit as if its normal faced the eye (partial scans
  // seen from behind, clouds with unoriented normals).
  bool two_sided = false;
  // Normal colours instead of shading: every surface shows its eye-space normal n (x right, y up,
  // z toward the viewer; after the two-sided flip) as (R, G, B) = round(255·(n + 1)/2) per
  // component, the blended normal in quality mode, the splat's normal in fast mode. Decoding
  // 2·c/255 − 1 and normalising recovers n to within 0.4° (8-bit rounding). For looking at
  // normals and for the normal error of `compare --normals`. Not with eye-dome lighting.
  bool normal_colors = false;
  // Eye-dome lighting after rasterization (eye_dome.hpp): 0 = off; 1 is Potree's default.
  float edl_strength = 0.0f;

  // Whether subtrees and splats facing away are skipped.
  bool culls_backfaces() const { return backface_culling && !two_sided; }
};

}  // namespace pointillist
