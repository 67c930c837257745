// The per-splat rules: disc crossing, side and gap tests, orientation, union or intersection.
// All arithmetic is relative to the splat's centre, so that models far from the origin keep
// their precision.
#include <algorithm>
#include <cmath>

#include "pointillist/features/rules.hpp"

namespace pointillist {
namespace {

// Tolerance of the classification's sign tests, in radii of the splat (spec Q4).
constexpr float kClassifyTolerance = 1e-3f;
// Tolerance of the side test, in radii of the splat (spec §1.4).
constexpr float kSideTolerance = 0.1f;

// Chord [t0, t1] of the line p + t·d through a disc centred at the origin of `q` coordinates
// (q = p − c), radius r; false when the line misses it.
bool chord(Vec3f q, Vec3f d, float r, double& t0, double& t1) {
  const double a = dot(d, d), b = dot(q, d), c = static_cast<double>(dot(q, q)) - double(r) * r;
  const double disc = b * b - a * c;
  if (disc < 0) return false;
  const double s = std::sqrt(disc);
  t0 = (-b - s) / a;
  t1 = (-b + s) / a;
  return true;
}

// The plane of `partner` with its kept side toward `keep_positive`, as seen from the splat:
// n·P − h, h = n·c_partner.
ClipPlane oriented_plane(const Disc& partner, bool keep_positive) {
  const float sign = keep_positive ? 1.0f : -1.0f;
  return {partner.n * sign, dot(partner.n, partner.c) * sign};
}

// Pointillist's orientation: the kept side of the partner's plane is the side where the splat's
// own surface lies: its centre, or the centroid of it and its continuous neighbours when the
// centre is near the plane; the convex default (keep the back side) when both are on it.
// A centre closer to the plane than kOrientByCentre·r does not decide: a quantized model moves
// centres by several percent of the radius, which put some on the wrong side of the crease (the
// kept half turned over: a disc shown beyond the edge and cut on its own face).
constexpr float kOrientByCentre = 0.25f;
bool keep_positive_side(const Disc& s, const Disc& partner, std::span<const Vec3f> continuous) {
  const float tol = kClassifyTolerance * s.r;
  const float side = dot(s.c - partner.c, partner.n);
  if (std::fabs(side) > kOrientByCentre * s.r || continuous.empty()) {
    if (std::fabs(side) > tol) return side > 0;
  }
  Vec3f sum{0, 0, 0};
  for (Vec3f c : continuous) sum += c - s.c;
  const Vec3f centroid = s.c + sum / static_cast<float>(continuous.size() + 1);
  const float cside = dot(centroid - partner.c, partner.n);
  if (std::fabs(cside) > tol) return cside > 0;
  return false;
}

// How far the plane of `partner`, kept on its positive side when keep_positive, moves onto its
// clipped side so that it reaches the partner's curved surface where it cuts s: the largest
// sag ½ wᵀ S w of that surface toward the clipped side at the two ends of s's chord on the
// line where the planes meet (w: the end's offset from the partner's centre in its tangent
// plane). 0 where the surface curves toward the kept side, or is flat.
float sag_shift(const Disc& s, const Disc& partner, bool keep_positive) {
  const Shape& k = partner.shape;
  if (k.xx == 0 && k.xy == 0 && k.yy == 0) return 0;
  const Vec3f e_raw = partner.n - s.n * dot(partner.n, s.n);
  const float e_len = length(e_raw);
  if (e_len < 1e-3f) return 0;
  const Vec3f e = e_raw / e_len;                           // in s's plane, toward the line
  const Vec3f along = normalized(cross(s.n, partner.n));  // the line's direction
  const Vec3f to_partner = partner.c - s.c;
  const float t = dot(partner.n, to_partner) / e_len;     // s's centre to the line
  const float half = std::fabs(t) < s.r ? std::sqrt(s.r * s.r - t * t) : 0.0f;
  const TangentFrame f = tangent_frame(partner.n);
  const float sign = keep_positive ? 1.0f : -1.0f;
  float shift = 0;
  for (float end : {-half, half}) {
    shift = std::max(shift, sign * sag(k, f, e * t + along * end - to_partner));
  }
  // At most kMaxSagShift radii within s's plane, where the line moves by shift / sin(angle).
  return std::min(shift, kMaxSagShift * s.r * e_len);
}

// How far (along its normal) a partner's plane moves onto its clipped side for a scan's noise:
// kNoiseMargin times the splat's fit residual and its partners' (root mean square) combined. A
// noisy partner's plane misses its surface by about its residual where it cuts s, and s is
// drawn as far off its own; with the discs of each face stopping at planes that are off by that
// much in either direction, the two faces left cracks along the crease where both fell short
// (cube with 2° normal and 0.1 h position noise, T14-2: 837 hole pixels at the corner
// close-up in quality mode). Measured on T14-2 and T14-5, both sampling modes, overview and
// close-up, with the renderer's fill of clipped pinholes: 0.75 left 6 hole pixels (T14-2), 1.0
// none, 1.5 none but 1.7 times the label errors in the crease band, the price of a convex
// crease's overhang, which is in view. Nearly 0 on exact data: the fit residual is 0 to second
// order, and what higher orders leave is below kFitNoiseFloor.
constexpr float kNoiseMargin = 1.0f;
float noise_shift(float own_noise, float partner_noise) {
  return kNoiseMargin * std::sqrt(own_noise * own_noise + partner_noise * partner_noise);
}

// Sign of eq. 4.14's term for one partner: +1 concave, −1 convex, 0 within the tolerance.
int concavity(const Disc& s, const Disc& partner) {
  const float v = dot(partner.c - s.c, s.n);
  const float tol = kClassifyTolerance * s.r;
  return v > tol ? 1 : (v < -tol ? -1 : 0);
}

// Removes planes equal to an earlier one, keeping the first (nearest) of each, with its
// partner's centre. The spec's tolerance (§1.12: n·n′ > 1 − 1e-6, |h − h′| < 1e-4·r) merges the
// exact planes of CSG faces but none of a quantized model's (its normals are 14-bit codes): a
// .ptl cube then kept 4.7 planes a clipped splat. Within 1° and 2 % of the radius the planes
// are the same crease; a curved rim's neighbouring tangent planes differ by several degrees.
constexpr float kSamePlaneCos = 0.99863f;  // cos 3°
constexpr float kSamePlaneOffset = 0.15f;
void deduplicate(std::vector<ClipPlane>& planes, std::vector<Vec3f>& centres, float r) {
  std::size_t kept = 0;
  for (std::size_t k = 0; k < planes.size(); ++k) {
    bool same = false;
    for (std::size_t m = 0; m < kept && !same; ++m) {
      same = dot(planes[k].n, planes[m].n) > kSamePlaneCos &&
             std::fabs(planes[k].h - planes[m].h) < kSamePlaneOffset * r;
    }
    if (!same) {
      planes[kept] = planes[k];
      centres[kept] = centres[k];
      ++kept;
    }
  }
  planes.resize(kept);
  centres.resize(kept);
}

// Union or intersection from the pairs of planes (spec §4.8 item 4): b's centre projected into
// the splat's plane lies on a's kept side (convex pair) or on its clipped side (reflex pair).
constexpr float kSameCreaseSin = 0.0872f;  // sin 5°
// n·x − h for a point x near the splat's centre c, computed relative to c for precision.
float side_near(const ClipPlane& p, Vec3f x, Vec3f c) {
  return dot(p.n, x - c) - (p.h - dot(p.n, c));
}

ClipMode combine_pairs(const Disc& s, const std::vector<ClipPlane>& planes,
                       const std::vector<Vec3f>& centres, std::span<const Vec3f> continuous) {
  if (planes.size() == 1) return ClipMode::Union;
  const float tol = kClassifyTolerance * s.r;
  bool convex = false, reflex = false, near_convex = false, near_reflex = false;
  std::vector<Vec3f> line(planes.size());
  for (std::size_t a = 0; a < planes.size(); ++a) line[a] = normalized(cross(planes[a].n, s.n));
  for (std::size_t b = 0; b < planes.size(); ++b) {
    const Vec3f x = centres[b] - s.n * dot(centres[b] - s.c, s.n);
    // The point of b's line (in the splat's plane) nearest to b's centre: on the crease.
    const Vec3f nb = planes[b].n - s.n * dot(planes[b].n, s.n);
    const Vec3f foot = x - nb * (side_near(planes[b], x, s.c) / std::max(dot(nb, nb), 1e-12f));
    for (std::size_t a = 0; a < planes.size(); ++a) {
      if (a == b) continue;
      // Lines within 5° in the splat's plane are one crease (a quantized model's normals differ
      // by a degree or two): union and intersection of the two keep the same region but for a
      // sliver, and their pair says little about a corner. They only decide when no pair of
      // lines further apart does, by where b's line touches the crease: along a curved rim
      // every partner's line is within a few degrees of the next, and at a hole's rim (the
      // face's region bends away from each tangent line) the union of the cuts took a sliver of
      // the face between the lines' crossings, a dashed 1-px gap along the rim.
      if (length(cross(line[a], line[b])) < kSameCreaseSin) {
        const float side = side_near(planes[a], foot, s.c);
        near_convex |= side > tol;
        near_reflex |= side < -tol;
        continue;
      }
      const float side = side_near(planes[a], x, s.c);
      convex |= side > tol;
      reflex |= side < -tol;
    }
  }
  if (!convex && !reflex) {
    return near_reflex && !near_convex ? ClipMode::Intersection : ClipMode::Union;
  }
  if (convex && reflex) {
    // A mixed corner by the partners' centres (the step's riser at the corner where it meets
    // floor and front: one partner convex, one concave). What decides the region to keep is
    // the splat's own face there: when none of its surface (its centre and smooth neighbours)
    // lies on the clipped side of any plane, the face is a convex corner of its polygon, kept
    // where every plane keeps (union of the clipped regions); otherwise the nearest plane
    // decides, pixel by pixel. (With random sampling's large discs, the nearest-plane rule let
    // the riser's discs show past the front at the corner in a wedge of 45–272 pixels.)
    const float side_tol = kSideTolerance * s.r;
    bool beyond = false;
    for (std::size_t k = 0; k <= continuous.size() && !beyond; ++k) {
      const Vec3f x = k == 0 ? s.c : continuous[k - 1];
      for (const ClipPlane& p : planes) {
        if (side_near(p, x, s.c) < -side_tol) {
          beyond = true;
          break;
        }
      }
    }
    return beyond ? ClipMode::Nearest : ClipMode::Union;
  }
  return reflex ? ClipMode::Intersection : ClipMode::Union;
}

// Whether eqs. 4.13–4.14 classify the partners, and their verdict: union when both sets have
// the same type. Single partners use eq. 4.17 directly (union).
struct Classification {
  bool defined = false;
  bool concave_with_s = false;  // S ∪ N_cp concave (eq. 4.14)
  bool union_rule = true;
};
Classification classify_4_15(const Disc& s, std::span<const Disc> partners) {
  Classification c;
  int with_s = concavity(s, partners[0]);
  for (const Disc& p : partners) {
    if (concavity(s, p) != with_s) with_s = 0;
  }
  if (with_s == 0) return c;
  c.concave_with_s = with_s > 0;
  if (partners.size() == 1) {
    c.defined = true;
    return c;
  }
  Vec3f mean{0, 0, 0};
  for (const Disc& p : partners) mean += p.c - s.c;
  mean = s.c + mean / static_cast<float>(partners.size());
  int among = 0;
  bool first = true;
  for (const Disc& p : partners) {
    const float v = dot(mean - p.c, p.n);
    const float tol = kClassifyTolerance * p.r;
    const int sign = v > tol ? 1 : (v < -tol ? -1 : 0);
    among = first ? sign : (sign == among ? among : 0);
    first = false;
  }
  if (among == 0) return c;
  c.defined = true;
  c.union_rule = (among > 0) == c.concave_with_s;
  return c;
}

}  // namespace

Shape fit_shape(Vec3f c, Vec3f n, std::span<const Vec3f> neighbour_centres,
                std::span<const Vec3f> neighbour_normals) {
  const TangentFrame f = tangent_frame(n);
  // Normal equations of dn ≈ S dp in the frame: A = Σ a aᵀ, B = Σ b aᵀ, S = B A⁻¹.
  double a11 = 0, a12 = 0, a22 = 0, b11 = 0, b12 = 0, b21 = 0, b22 = 0;
  for (std::size_t k = 0; k < neighbour_centres.size(); ++k) {
    const Vec3f dp = neighbour_centres[k] - c, dn = neighbour_normals[k] - n;
    const double p1 = dot(dp, f.u), p2 = dot(dp, f.v), q1 = dot(dn, f.u), q2 = dot(dn, f.v);
    a11 += p1 * p1, a12 += p1 * p2, a22 += p2 * p2;
    b11 += q1 * p1, b12 += q1 * p2, b21 += q2 * p1, b22 += q2 * p2;
  }
  const double trace = a11 + a22;
  if (trace <= 0) return {};
  const double det = a11 * a22 - a12 * a12;
  if (det < 1e-2 * trace * trace) {  // neighbours along a line: the mean curvature over them
    const float mean = static_cast<float>((b11 + b22) / trace);
    return {mean, 0, mean};
  }
  const double s11 = (b11 * a22 - b12 * a12) / det, s12 = (b12 * a11 - b11 * a12) / det;
  const double s21 = (b21 * a22 - b22 * a12) / det, s22 = (b22 * a11 - b21 * a12) / det;
  return {static_cast<float>(s11), static_cast<float>(0.5 * (s12 + s21)), static_cast<float>(s22)};
}

float fit_residual(Vec3f c, Vec3f n, const Shape& shape, std::span<const Vec3f> neighbour_centres) {
  if (neighbour_centres.empty()) return 0;
  const TangentFrame f = tangent_frame(n);
  double sum = 0;
  for (const Vec3f x : neighbour_centres) {
    const float off = dot(x - c, n) + sag(shape, f, x - c);
    sum += double(off) * off;
  }
  return static_cast<float>(std::sqrt(sum / static_cast<double>(neighbour_centres.size())));
}

Crossing disc_crossing(const Disc& a, const Disc& b) {
  const Vec3f d = cross(a.n, b.n);
  const float dd = dot(d, d);
  if (dd < 1e-6f) return Crossing::Parallel;
  // The line's point P_o = t_a·n_a + t_b·n_b (eqs. 4.5–4.7) with a's centre as the origin:
  // h_a = 0, h_b = n_b·(c_b − c_a).
  const double c = dot(a.n, b.n);
  const double hb = dot(b.n, b.c - a.c);
  const double denom = 1.0 - c * c;
  const double ta = -c * hb / denom, tb = hb / denom;
  const Vec3f po = a.n * static_cast<float>(ta) + b.n * static_cast<float>(tb);
  double a0, a1, b0, b1;
  if (!chord(po, d, a.r, a0, a1)) return Crossing::Apart;
  if (!chord(po - (b.c - a.c), d, b.r, b0, b1)) return Crossing::Apart;
  return std::max(a0, b0) <= std::min(a1, b1) ? Crossing::Cross : Crossing::Apart;
}

bool surface_ends_at(const Disc& s, std::span<const Vec3f> continuous, const Disc& partner) {
  const float tol = kSideTolerance * s.r;
  const float own = dot(s.c - partner.c, partner.n);
  bool above = own > tol, below = own < -tol;
  for (Vec3f c : continuous) {
    const float side = dot(c - partner.c, partner.n);
    above |= side > tol;
    below |= side < -tol;
  }
  return !(above && below);
}

bool linsen_boundary(const Disc& s, std::span<const Vec3f> continuous, float alpha_deg) {
  if (continuous.size() < 2) return true;
  // A frame (u, v) of the splat's plane; v′_j = (c_j − c) × n (eq. 4.2) has the angular order of
  // the projections.
  const auto [u, v] = tangent_frame(s.n);
  std::vector<float> angles;
  angles.reserve(continuous.size());
  for (Vec3f c : continuous) {
    const Vec3f w = cross(c - s.c, s.n);
    if (dot(w, w) == 0) continue;  // a neighbour straight above or below: no direction
    angles.push_back(std::atan2(dot(w, v), dot(w, u)));
  }
  if (angles.size() < 2) return true;
  std::sort(angles.begin(), angles.end());
  const float alpha = deg_to_rad(alpha_deg);
  float gap = angles.front() + 2.0f * kPi - angles.back();
  for (std::size_t k = 1; k < angles.size(); ++k) gap = std::max(gap, angles[k] - angles[k - 1]);
  return gap > alpha;
}

std::vector<std::uint8_t> reflex_partners(const Disc& s, std::span<const Vec3f> continuous,
                                          std::span<const Disc> through) {
  std::vector<std::uint8_t> flags(through.size(), 0);
  const float tol = kSideTolerance * s.r;
  // Signed distance beyond the plane's far side (> 0 beyond): the far side of a partner below
  // s's plane (convex, eq. 4.14) is its front, of one above (concave) its back.
  const auto beyond = [&](const Disc& p, int sign, Vec3f x) {
    return dot(x - p.c, p.n) * static_cast<float>(sign);
  };
  // Which points of s's surface (its centre, then `continuous`) lie beyond each plane, as bit
  // sets, so that a pair's test is a few word ANDs.
  const std::size_t points = continuous.size() + 1, words = (points + 63) / 64;
  std::vector<std::uint64_t> far(through.size() * words, 0);
  std::vector<int> sign(through.size());
  std::vector<Vec3f> line(through.size());
  for (std::size_t a = 0; a < through.size(); ++a) {
    sign[a] = -concavity(s, through[a]);
    line[a] = normalized(cross(through[a].n, s.n));
    if (sign[a] == 0) continue;
    std::uint64_t* bits = &far[a * words];
    for (std::size_t k = 0; k < points; ++k) {
      const Vec3f x = k == 0 ? s.c : continuous[k - 1];
      if (beyond(through[a], sign[a], x) > tol) bits[k / 64] |= std::uint64_t{1} << (k % 64);
    }
  }
  for (std::size_t a = 0; a < through.size(); ++a) {
    const int sa = sign[a];
    if (sa == 0) continue;
    const Vec3f la = line[a];
    // One plane: the surface continues past it, but only beside the disc's chord on the line
    // where the planes meet (a splat near such a corner whose disc does not reach the other
    // plane). Straight across the chord lies none of the surface beyond the plane. The centre
    // is on the near side, or within the tolerance of the plane (a centre 0.07 r below the
    // step's floor, its disc reaching 0.93 r above it: random sampling puts splats there).
    if (const float d = -beyond(through[a], sa, s.c); d > -tol) {
      // Distance from s's centre to the line, within s's plane: d over the sine of the angle.
      const float sin_angle = length(cross(through[a].n, s.n));
      const float to_line = std::fabs(d) / std::max(sin_angle, 1e-3f);
      if (to_line < s.r) {
        const float half = std::sqrt(s.r * s.r - to_line * to_line);
        bool empty = true;
        for (std::size_t k = 1; k < points && empty; ++k) {
          const bool is_far = (far[a * words + k / 64] >> (k % 64)) & 1;
          empty = !(is_far && std::fabs(dot(continuous[k - 1] - s.c, la)) < half);
        }
        if (empty) flags[a] = 1;
      }
    }
    for (std::size_t b = a + 1; b < through.size(); ++b) {
      if (sign[b] == 0) continue;
      if (length(cross(la, line[b])) < 0.5f) continue;  // lines within 30°: not a corner
      bool empty = true;
      for (std::size_t w = 0; w < words && empty; ++w) empty = (far[a * words + w] & far[b * words + w]) == 0;
      if (empty) flags[a] = flags[b] = 1;
    }
  }
  return flags;
}

int keep_uncovered(const Disc& s, ClipResult& clip, std::span<const Disc> others, float w_s) {
  if (clip.mode != ClipMode::Union || clip.planes.empty()) return 0;
  constexpr int kSteps = 8, kAlong = 3;
  const float step = kMaxSagShift * s.r / kSteps;
  int moved = 0;
  std::vector<const Disc*> surface;
  for (ClipPlane& plane : clip.planes) {
    // The plane is scaled: within s's plane, side(X) = side(c) + (X − c)·e with e the unit
    // direction of n's in-plane part; the line where the planes meet passes through foot.
    const Vec3f in_plane = plane.n - s.n * dot(plane.n, s.n);
    const float len = length(in_plane);
    const float side_c = plane_side(plane, s.c);
    if (len < 1e-6f || std::fabs(side_c) >= s.r) continue;
    const Vec3f e = in_plane / len, along = cross(s.n, e), unit = normalized(plane.n);
    const Vec3f foot = s.c - e * side_c;
    // The discs of the plane's surface, and the direction within its plane, away from the
    // line, in which that surface lies (toward their centres).
    surface.clear();
    Vec3f mean{0, 0, 0};
    for (const Disc& q : others) {
      if (std::fabs(dot(q.n, unit)) < w_s) continue;
      surface.push_back(&q);
      mean += q.c - foot;
    }
    if (surface.empty()) continue;
    Vec3f into = cross(unit, along);
    if (dot(into, mean) < 0) into = -into;
    const float half = std::sqrt(s.r * s.r - side_c * side_c);
    float gap = 0;
    for (int k = 0; k < kAlong; ++k) {
      // The middle half of s's chord: s's neighbours are sure to include the discs that cover
      // the surface there, when any do.
      const Vec3f on_line = foot + along * (0.5f * half * (2.0f * static_cast<float>(k) / (kAlong - 1) - 1.0f));
      // Beyond another plane, the line is past a corner, where this plane's surface has ended.
      bool past_corner = false;
      for (const ClipPlane& p : clip.planes) past_corner |= &p != &plane && plane_side(p, on_line) < 0;
      if (past_corner) continue;
      // How far from the line the surface's discs first cover it.
      int first = kSteps + 1;
      for (int u = 0; u <= kSteps && first > kSteps; ++u) {
        const Vec3f z = on_line + into * (static_cast<float>(u) * step);
        for (const Disc* q : surface) {
          const float off = dot(q->n, z - q->c);
          if (std::fabs(off) <= s.r && length_squared(z - q->n * off - q->c) <= q->r * q->r) {
            first = u;
            break;
          }
        }
      }
      gap = std::max(gap, static_cast<float>(std::min(first, kSteps)) * step);
    }
    if (gap > 0) {
      plane.h -= gap;
      ++moved;
    }
  }
  return moved;
}

ClipResult classify_partners(const Disc& s, std::span<const Disc> partners,
                             std::span<const Vec3f> continuous, ClipRule rule,
                             std::span<const Disc> reflex, float margin) {
  ClipResult result;
  if (partners.empty() && (rule != ClipRule::Classified || reflex.empty())) return result;
  const Classification c = partners.empty() ? Classification{} : classify_4_15(s, partners);
  result.undefined_4_15 = !partners.empty() && !c.defined;
  std::vector<ClipPlane> planes;
  std::vector<Vec3f> centres;
  float partner_noise = 0;  // Σ of the partners' squared fit residuals (ClipRule::Classified)
  int noisy = 0;
  switch (rule) {
    case ClipRule::Classified:
      for (const Disc& p : partners) {
        const bool keep = keep_positive_side(s, p, continuous);
        ClipPlane plane = oriented_plane(p, keep);
        if (concavity(s, p) > 0) plane.h -= sag_shift(s, p, keep);
        partner_noise += p.noise * p.noise;
        ++noisy;
        planes.push_back(plane);
        centres.push_back(p.c);
      }
      for (const Disc& p : reflex) {
        const int sign = concavity(s, p);
        if (sign == 0) continue;
        partner_noise += p.noise * p.noise;
        ++noisy;
        planes.push_back(oriented_plane(p, sign > 0));
        centres.push_back(p.c);
      }
      break;
    case ClipRule::Dissertation:
      if (!c.defined) return result;
      // Eq. 4.17: S ∪ N_cp concave keeps the positive side of every partner, convex the
      // negative side.
      for (const Disc& p : partners) {
        planes.push_back(oriented_plane(p, c.concave_with_s));
        centres.push_back(p.c);
      }
      break;
    case ClipRule::Independent:
    case ClipRule::NearestPartner:
      for (const Disc& p : partners) {
        const int sign = concavity(s, p);
        if (sign == 0) continue;
        planes.push_back(oriented_plane(p, sign > 0));
        centres.push_back(p.c);
        if (rule == ClipRule::NearestPartner) break;
      }
      break;
  }
  deduplicate(planes, centres, s.r);
  if (planes.empty()) return result;
  if (planes.size() > static_cast<std::size_t>(kMaxClipPlanes)) {
    result.capped = true;
    planes.resize(kMaxClipPlanes);
    centres.resize(kMaxClipPlanes);
  }
  switch (rule) {
    case ClipRule::Classified: result.mode = combine_pairs(s, planes, centres, continuous); break;
    case ClipRule::Dissertation:
      result.mode = c.union_rule ? ClipMode::Union : ClipMode::Intersection;
      break;
    default: result.mode = ClipMode::Union; break;
  }
  // Scale each plane so that, within the splat's plane, n·P − h is the distance to the line
  // where the planes meet (ClipMode::Nearest compares these distances).
  // Then move each line out, onto the clipped side, by `margin` radii or for the noise
  // (noise_shift, at most kMaxSagShift radii), whichever is more: both allow for centres and
  // normals off their surface.
  const float noise =
      noisy > 0 ? noise_shift(s.noise, std::sqrt(partner_noise / static_cast<float>(noisy))) : 0.0f;
  for (ClipPlane& p : planes) {
    const float cos_angle = dot(p.n, s.n);
    const float scale = 1.0f / std::sqrt(std::max(1e-6f, 1.0f - cos_angle * cos_angle));
    p.n *= scale;
    p.h = p.h * scale - std::max(margin * s.r, std::min(noise * scale, kMaxSagShift * s.r));
  }
  result.planes = std::move(planes);
  return result;
}

}  // namespace pointillist
