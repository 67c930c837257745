// The per-splat rules of the features module, one function each, on discs given by value (the
// tests build the dissertation's configurations by hand; compute_features applies them to every
// splat of a model). Equation numbers refer to specs/sharp-features.md.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "pointillist/core/math.hpp"
#include "pointillist/features/features.hpp"

namespace pointillist {

// The surface's second-order shape at a splat: the derivative of the unit normal along the
// surface (the shape operator, symmetric) in the tangent frame of tangent_frame(n), so that the
// normal curvature along a tangent direction w = a·u + b·v is (xx a² + 2 xy a b + yy b²) / |w|²
// and the surface lies −½ wᵀ S w along n from the tangent plane at offset w. Positive on a
// convex surface with outward normals (a sphere of radius R: xx = yy = 1/R), 0 on a plane.
struct Shape {
  float xx = 0, xy = 0, yy = 0;
};

// A circular splat as drawn: centre, unit normal, drawn radius, and (optional) the shape of
// its surface there, which corrects a partner's plane at curved creases (classify_partners).
struct Disc {
  Vec3f c;
  Vec3f n;
  float r = 0;
  Shape shape{};
  // How far its continuous neighbours' centres lie from the surface `shape` describes (root
  // mean square, model units): a scan's noise, 0 on exact samples (fit_residual).
  float noise = 0;
};

// The surface's offset from its tangent plane along the normal at tangent offset w, in the
// frame f that the shape refers to (tangent_frame of the normal): ½ wᵀ S w (toward −n).
inline float sag(const Shape& k, const TangentFrame& f, Vec3f w) {
  const float a = dot(w, f.u), b = dot(w, f.v);
  return 0.5f * (k.xx * a * a + 2.0f * k.xy * a * b + k.yy * b * b);
}

// The shape operator at a splat (centre c, unit normal n) fitted by least squares to its
// continuous neighbours: normal differences against centre differences, projected into the
// tangent plane. Isotropic (the mean over the neighbours) where the neighbours do not span the
// plane; zero without neighbours.
Shape fit_shape(Vec3f c, Vec3f n, std::span<const Vec3f> neighbour_centres,
                std::span<const Vec3f> neighbour_normals);

// The root-mean-square distance of `neighbour_centres` from the surface through c with normal n
// and shape `shape` (the second-order surface of fit_shape): noise of a scan's positions and
// normals, since exact samples of a smooth surface lie on it to second order.
float fit_residual(Vec3f c, Vec3f n, const Shape& shape, std::span<const Vec3f> neighbour_centres);

enum class Crossing {
  Cross,     // the two discs meet (closed intervals: touching chords count)
  Apart,     // they lie side by side (a false-positive sharp edge)
  Parallel,  // the planes are (anti)parallel, |n_a × n_b|² < 1e-6: no line, never partners
};

// Whether two neighbouring splats whose normals agree (n_i·n_j >= w_s) lie on one smooth
// surface: each centre within reach of the other's plane. On a smooth surface the chord d
// between two centres makes about half the normals' angle with each tangent plane, on
// opposite sides (n_i·d ≈ −n_j·d ≈ −½ dᵀ S d), so a chord steeper than the normals' largest
// angle (sine sqrt(1 − w_s²)), or two offsets of one sign that add up to that much, mean two
// surfaces side by side (the nearly parallel parts of two crossed cylinders). Offsets up to
// kStackedOffset of the smaller radius are allowed whatever the chord (noise, quantized
// centres).
inline constexpr float kStackedOffset = 0.5f;
inline bool on_planes_of_each_other(Vec3f ci, Vec3f ni, float ri, Vec3f cj, Vec3f nj, float rj,
                                    float w_s) {
  const Vec3f d = cj - ci;
  const float r = kStackedOffset * std::min(ri, rj);
  // Squared: allowed² = max(sin² θ_s · |d|², r²), θ_s taken at most 90° (a chord can make at most
  // that with a plane).
  const float sin2 = w_s > 0 ? 1.0f - w_s * w_s : 1.0f;
  const float allowed2 = std::max(sin2 * dot(d, d), r * r);
  const float oi = dot(ni, d), oj = dot(nj, d), sum = oi + oj;
  return oi * oi <= allowed2 && oj * oj <= allowed2 && sum * sum <= allowed2;
}

// The exact disc–disc test (eqs. 4.3–4.12): the line where the two planes meet, its chord
// through each disc on one shared parameterisation, and whether the chords overlap.
Crossing disc_crossing(const Disc& a, const Disc& b);

// The side test (spec §1.4 [P]): true when the surface of `s` ends at the plane of `partner`,
// i.e. s and its continuous neighbours (centres `continuous`) do not lie on both sides of the
// partner's plane by more than 0.1·s.r; false when the surface passes through it.
bool surface_ends_at(const Disc& s, std::span<const Vec3f> continuous, const Disc& partner);

// Linsen's gap test (dissertation §4.1, eqs. 4.1–4.2): true when `s` is on the boundary of its
// surface: fewer than two continuous neighbours, or an angular gap between their projections
// into s's plane larger than alpha_deg.
bool linsen_boundary(const Disc& s, std::span<const Vec3f> continuous, float alpha_deg);

// Of `through`, crossing discs whose plane the surface of `s` passes through (the side test
// says so for each alone), those that form a reflex vertex of s's face with another: two
// planes whose lines in s's plane cross at 30° or more, and where no point of s's surface (its
// centre and `continuous`) lies beyond both by more than 0.1·s.r, each plane's far side being
// the one eq. 4.14 clips. At the inner corner of an L-shaped face the face continues past each
// of the two planes, but not past both. Also a single plane that s's centre is within s.r/2 of
// while none of s's surface beyond it lies under s's disc (a splat beside such a corner whose
// disc does not reach the other plane). Returns a flag per disc of `through`.
std::vector<std::uint8_t> reflex_partners(const Disc& s, std::span<const Vec3f> continuous,
                                          std::span<const Disc> through);

struct ClipResult {
  ClipMode mode = ClipMode::None;
  std::vector<ClipPlane> planes;  // oriented, de-duplicated, scaled (ClipPlane), at most 16
  bool undefined_4_15 = false;    // eqs. 4.13–4.15 do not decide this splat (any rule reports it)
  bool capped = false;            // more than kMaxClipPlanes distinct planes; the nearest kept
};

// The clip planes of `s` from its partners (discs that cross it and that its surface ends at,
// nearest first) under `rule`. `continuous` are the centres of s's continuous neighbours (for
// orienting a plane that passes through s's centre). `reflex` (ClipRule::Classified only) are
// partners found by reflex_partners; they are oriented by their own eq. 4.14 sign instead of
// by the side s lies on (s's surface is on both sides of each).
// `margin` (FeatureOptions::clip_margin) moves every plane's line that many radii of s onto
// its clipped side.
// ClipRule::Classified also corrects the plane of a concave partner (eq. 4.14: it lies above
// s's plane, a valley) for the partner's curvature (Disc::shape): the plane is the partner
// surface's tangent at its centre, and where that surface curves away from it onto the clipped
// side (the crease of a union of two spheres), the disc stops short of the surface it meets
// and opens a thin gap. The plane moves onto its clipped side by the largest sag of the
// partner's surface at the ends of the chord where it cuts s (its line in s's plane moves at
// most kMaxSagShift radii of s); what the disc then reaches past the true crease lies behind the partner's surface. It
// never moves the other way, and convex creases are left alone: there the extra part would be
// in view (the rim of a hole, whose wall curves away from its tangent planes too).
inline constexpr float kMaxSagShift = 0.5f;
ClipResult classify_partners(const Disc& s, std::span<const Disc> partners,
                             std::span<const Vec3f> continuous, ClipRule rule,
                             std::span<const Disc> reflex = {}, float margin = 0.0f);

// Clipping never uncovers a gap of the other surface: where the discs of the surface a plane
// stands for stop short of the crease (samples of a sparse face whose discs do not reach the
// edge; the sample nearest an open crease fallen on the other side of it), the discs of `s`
// that reached over it kept it covered. For each plane of a union (or single) clip, at three
// points of the line where the planes meet (the middle half of s's chord), the surface's discs
// among `others` (s's sharp-edge neighbours whose normal is within `w_s` of the plane's) are
// asked how far from the line, within that plane, they first cover it, in steps of
// kMaxSagShift·r/8; the line moves out by the widest such gap (none when a disc reaches the
// line; a gap wider than kMaxSagShift·r is left alone: the surface is not there). Returns how
// many planes moved. Intersection and nearest-plane clips are left as they are.
int keep_uncovered(const Disc& s, ClipResult& clip, std::span<const Disc> others, float w_s);

}  // namespace pointillist
