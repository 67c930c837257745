// The per-splat rules of the features module, one function each, on discs given by value (the
// tests build the dissertation's configurations by hand; compute_features applies them to every
// splat of a model). Equation numbers refer to specs/sharp-features.md.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "pointillist/core/math.hpp"
#include "pointillist/features/features.hpp"

namespace pointillist {

// A circular splat as drawn: centre, unit normal, drawn radius.
struct Disc {
  Vec3f c;
  Vec3f n;
  float r = 0;
};

enum class Crossing {
  Cross,     // the two discs meet (closed intervals: touching chords count)
  Apart,     // they lie side by side (a false-positive sharp edge)
  Parallel,  // the planes are (anti)parallel, |n_a × n_b|² < 1e-6: no line, never partners
};

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
ClipResult classify_partners(const Disc& s, std::span<const Disc> partners,
                             std::span<const Vec3f> continuous, ClipRule rule,
                             std::span<const Disc> reflex = {}, float margin = 0.0f);

}  // namespace pointillist
