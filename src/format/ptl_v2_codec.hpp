// Node records of .ptl version 2 (docs/ptl-format.md, "Version 2"): QSplat's quantization
// (Rusinkiewicz & Levoy, SIGGRAPH 2000; tables in qs_tables.hpp) with encoders that keep every
// decoded sphere and normal cone conservative. Private to the format module.
#pragma once

#include <cstdint>
#include <span>

#include "ptl_v2_layout.hpp"
#include "qs_tables.hpp"
#include "pointillist/core/math.hpp"

namespace pointillist::ptl2 {

// Sphere code for `target` against the decoded `parent`: among the codes whose decoded sphere
// (qs_detail::decode_sphere, float32) encloses `target` and lies inside `parent` (both checked
// in double on the decoded floats), one of the smallest radius, then nearest the target's
// centre. When no code qualifies (only if `target` is not inside `parent`), the parent's own
// sphere (code 7620). `*exact` says whether the returned code passed both checks.
std::uint32_t encode_enclosing_sphere(const Sphere& parent, const Sphere& target, bool* exact);

// A leaf's sphere code and radius trim (see trimmed_leaf_radius), and the radius it is drawn at.
struct LeafCode {
  std::uint32_t code = 0;
  std::uint32_t trim = 0;
  float radius = 0;
  bool exact = false;  // the decoded sphere holds the target and lies inside the parent
};
// For a leaf: among the codes of encode_enclosing_sphere's search (decoded sphere holds `target`,
// lies inside `parent`), the one whose largest trim that still holds `target` gives the smallest
// drawn radius; ties to the lower code. Falls back to the parent's sphere as that function does.
LeafCode encode_enclosing_leaf(const Sphere& parent, const Sphere& target, LeafTrim mode);

// True when `outer` holds `inner`: |c_o - c_i| + r_i <= r_o, in double.
bool encloses(const Sphere& outer, const Sphere& inner);

// Normal code of a unit normal: QSplat's cube-face cell (qs_detail::encode_normal), or the
// neighbouring cell whose decoded normal is nearer. The decoded normal is within
// kPtlV2NormalErrorRad (ptl_v2.hpp) of `n`.
std::uint32_t encode_normal_nearest(Vec3f n);

// Half-angle (radians) that cone code k promises: asin(((k + 1)/4)²) for k < 3; +inf for 3.
double cone_half_angle(std::uint32_t k);
// Smallest cone code whose half-angle is >= `theta` (radians) plus a 1e-6 margin; 3 when none.
std::uint32_t encode_cone_at_least(double theta);
// RGB 565 with each channel rounded to the nearest representable value (bit-replicated decode):
// errors at most 4 levels in red and blue, 2 in green.
std::uint16_t encode_rgb565_nearest(Rgb8 c);

// Cosine of the angle between two vectors, in double, clamped to [-1, 1]; 1 for a zero vector.
double cosine_between(Vec3f a, Vec3f b);
// Angle between two vectors (radians, double; 0 for a zero vector): acos(cosine_between).
double angle_between(Vec3f a, Vec3f b);

}  // namespace pointillist::ptl2
