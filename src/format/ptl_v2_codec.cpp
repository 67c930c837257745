// Conservative QSplat quantization for .ptl version 2. QSplat 1.0 (Rusinkiewicz & Levoy,
// SIGGRAPH 2000) picks the cube that covers a child's extent and decodes it as the inscribed
// sphere, which misses a third of the true spheres (../shared/specs/qsplat-qs-format.md §4.3).
// Here the code is searched instead: the smallest decoded sphere that encloses the true one and
// stays inside the decoded parent, so culling against decoded spheres is conservative.
#include "ptl_v2_codec.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace pointillist::ptl2 {
namespace {

using qs_detail::kNormalGrid;
using qs_detail::kSphereCodeCount;
using qs_detail::kSphereGrid;

// The m = 13 cube: centre 0, radius 1 in parent units, i.e. the parent's own sphere (13·(1/13)
// rounds to exactly 1.0f in the table, so it decodes to the parent's bits).
constexpr std::uint32_t kParentCode = kSphereCodeCount - 1;

// 1 / (m / 13) for the cube sizes m = 1..13.
constexpr auto kInverseRadius = [] {
  std::array<double, kSphereGrid + 1> r{};
  for (int m = 1; m <= kSphereGrid; ++m) r[std::size_t(m)] = double(kSphereGrid) / m;
  return r;
}();

double distance_squared(Vec3f a, Vec3f b) {
  const double dx = double(a.x) - b.x, dy = double(a.y) - b.y, dz = double(a.z) - b.z;
  return dx * dx + dy * dy + dz * dz;
}

// Nearest `bits`-bit value of an 8-bit channel under bit-replicated decoding.
template <unsigned bits>
constexpr std::array<std::uint8_t, 256> nearest_channel_table() {
  std::array<std::uint8_t, 256> t{};
  for (int c = 0; c < 256; ++c) {
    int best = 0, best_error = 1 << 20;
    for (int v = 0; v < (1 << bits); ++v) {
      const int decoded = (v << (8 - bits)) | (v >> (2 * bits - 8));
      const int error = decoded > c ? decoded - c : c - decoded;
      if (error < best_error) best = v, best_error = error;
    }
    t[std::size_t(c)] = static_cast<std::uint8_t>(best);
  }
  return t;
}
constexpr auto kNearest5 = nearest_channel_table<5>();
constexpr auto kNearest6 = nearest_channel_table<6>();

}  // namespace

namespace {

// How far (parent units) the search's lattice estimate of a candidate's centre distance can be
// from the distance of its decoded float centre: each coordinate, centre + radius * offset with
// |offset| <= 1, rounds twice (at most one float epsilon of |centre| + radius in all), and the
// double arithmetic adds about 1e-15. Generous by a factor of 4, plus 1e-6.
double estimate_margin(const Sphere& parent) {
  const double c = std::max({std::fabs(double(parent.center.x)), std::fabs(double(parent.center.y)),
                             std::fabs(double(parent.center.z))});
  return 1e-6 + 4 * std::sqrt(3.0) * std::numeric_limits<float>::epsilon() *
                    (c / parent.radius + 1);
}

}  // namespace

bool encloses(const Sphere& outer, const Sphere& inner) {
  return std::sqrt(distance_squared(outer.center, inner.center)) + double(inner.radius) <=
         double(outer.radius);
}

namespace {

// The search of encode_enclosing_sphere and encode_enclosing_leaf: for each cube size m from
// the smallest that can hold `target`, every code whose decoded sphere holds `target` and lies
// inside `parent` is offered to `offer(code, decoded, m, squared distance of the centres)`,
// which returns false to stop; so
// does `go_on(m, radius)` before each size (radius m/13 in parent units, double). Within
// one size the cell nearest the target comes first, then the others in code order, so offers
// keep the least (value, code) explicitly. Only centres within `reach(m, radius)` of the
// target's (parent units, double; asked at each size and after each offer, negative when no
// code of that size is wanted) are decoded; the distance compared is the lattice estimate, so
// `reach` must allow for its difference from the decoded floats (estimate_margin).
template <class GoOn, class Reach, class Offer>
void search_enclosing(const Sphere& parent, const Sphere& target, GoOn&& go_on, Reach&& reach,
                      Offer&& offer) {
  const double rho = parent.radius;
  // Target in parent units; a candidate of size m has radius R = m/13 and centre coordinates
  // X = (m + 2x)/13 - 1 (spec §4.1). It can only qualify when every |X - t| <= R - s (encloses)
  // and |X| <= 1 - R (inside), which bounds x, y, z; the exact test runs on the decoded floats.
  const double t[3] = {(double(target.center.x) - parent.center.x) / rho,
                       (double(target.center.y) - parent.center.y) / rho,
                       (double(target.center.z) - parent.center.z) / rho};
  const double s = double(target.radius) / rho;
  // Widens the box by what the decoded floats may differ from the lattice; the exact test decides.
  const double slack = estimate_margin(parent);
  const int m_first = std::clamp(int(std::floor(kSphereGrid * s)), 1, kSphereGrid);
  // The distance from the target's centre to the nearest centre of each lattice, unbounded:
  // lattice coordinates u = 13 (X + 1) are even for even m, odd for odd m.
  double lattice_distance[2];
  for (int parity = 0; parity < 2; ++parity) {
    double e2 = 0;
    for (int a = 0; a < 3; ++a) {
      const double u = kSphereGrid * (t[a] + 1);
      const double k = 2 * std::floor((u - parity) * 0.5 + 0.5) + parity;
      const double e = (k - u) / kSphereGrid;
      e2 += e * e;
    }
    lattice_distance[parity] = std::sqrt(e2);
  }
  const std::int16_t* const codes = qs_detail::sphere_code_table().data();
  const qs_detail::SphereCandidate* const table = qs_detail::sphere_table().data();
  for (int m = m_first; m <= kSphereGrid; ++m) {
    const double radius = double(m) / kSphereGrid;
    if (!go_on(m, radius)) return;
    // No cell of this size is nearer the target than the nearest point of its lattice (centres
    // at (m + 2x)/13 - 1: the lattice depends only on m's parity); when that is out of reach,
    // the box is not worth computing. Cells are compared squared (the margins dwarf a rounding).
    double wanted = reach(m, radius);
    if (!(lattice_distance[m & 1] <= wanted)) continue;
    double wanted2 = wanted * wanted;
    const double box = std::min(radius - s, wanted) + slack;
    const double room = 1 - radius + slack;
    if (box < 0) continue;
    int lo[3], hi[3];
    bool empty = false;
    for (int a = 0; a < 3 && !empty; ++a) {
      const double x_lo = std::max(t[a] - box, -room), x_hi = std::min(t[a] + box, room);
      // x = (13 (X + 1) - m) / 2
      lo[a] = std::max(0, int(std::ceil((kSphereGrid * (x_lo + 1) - m) / 2)));
      hi[a] = std::min(kSphereGrid - m, int(std::floor((kSphereGrid * (x_hi + 1) - m) / 2)));
      empty = x_lo > x_hi || lo[a] > hi[a];
    }
    if (empty) continue;
    constexpr double kCell = 1.0 / kSphereGrid;
    const auto offset = [&](int a, int cell) {  // candidate centre minus target, axis a
      return (m + 2.0 * cell) * kCell - 1 - t[a];
    };
    const auto visit = [&](int x, int y, int z, double ex, double ey, double ez) {
      if (!(ex * ex + ey * ey + ez * ez <= wanted2)) return true;
      // x, y, z lie in the box, within 0..13 - m: sphere_code without its range checks
      const int code = codes[((m * kSphereGrid + x) * kSphereGrid + y) * kSphereGrid + z];
      if (code < 0) return true;
      const Sphere d = qs_detail::decode_sphere(parent, table[code]);
      // encloses(d, target), keeping the squared centre distance for `offer`
      const double dist2 = distance_squared(d.center, target.center);
      if (!(std::sqrt(dist2) + double(target.radius) <= double(d.radius))) return true;
      if (!encloses(parent, d)) return true;
      if (!offer(std::uint32_t(code), d, m, dist2)) return false;
      wanted = reach(m, radius);
      wanted2 = wanted * wanted;
      return true;
    };
    // The cell nearest the target first: it is usually the answer, and the bounds it sets let
    // `reach` skip most of the box undecoded.
    int near[3];
    for (int a = 0; a < 3; ++a) {
      // (either of two equally near cells will do)
      near[a] = std::clamp(int(std::floor((kSphereGrid * (t[a] + 1) - m) * 0.5 + 0.5)), lo[a],
                           hi[a]);
    }
    const double nx = offset(0, near[0]), ny = offset(1, near[1]), nz = offset(2, near[2]);
    // No cell of the box is nearer: when it is out of reach, they all are.
    if (!(nx * nx + ny * ny + nz * nz <= wanted2)) continue;
    if (!visit(near[0], near[1], near[2], nx, ny, nz)) return;
    for (int x = lo[0]; x <= hi[0]; ++x) {
      const double ex = offset(0, x);
      for (int y = lo[1]; y <= hi[1]; ++y) {
        const double ey = offset(1, y);
        for (int z = lo[2]; z <= hi[2]; ++z) {
          if (x == near[0] && y == near[1] && z == near[2]) continue;
          if (!visit(x, y, z, ex, ey, offset(2, z))) return;
        }
      }
    }
  }
}

}  // namespace

std::uint32_t encode_enclosing_sphere(const Sphere& parent, const Sphere& target, bool* exact) {
  if (!(parent.radius > 0) || !std::isfinite(parent.radius)) {
    *exact = encloses(parent, target);
    return kParentCode;
  }
  // The smallest size with a qualifying code, then the code nearest the target's centre (ties:
  // the lower code, the order of the search).
  int best = -1, best_m = 0;
  double best_distance = std::numeric_limits<double>::infinity();
  // Once a code qualifies, only centres about as near as its can still win: the lattice
  // distance in double differs from the decoded floats' by their rounding (parent units).
  const double margin = estimate_margin(parent);
  double near_enough = std::numeric_limits<double>::infinity();
  const auto go_on = [&](int m, double) { return best < 0 || m <= best_m; };
  const auto reach = [&](int, double) { return near_enough; };
  search_enclosing(parent, target, go_on, reach, [&](std::uint32_t code, const Sphere&, int m,
                                                    double dist) {
    if (best >= 0 && m > best_m) return false;
    if (dist < best_distance || (dist == best_distance && int(code) < best)) {
      best = int(code), best_m = m, best_distance = dist;
      near_enough = std::sqrt(dist) / parent.radius + margin;
    }
    return true;
  });
  if (best >= 0) {
    *exact = true;
    return std::uint32_t(best);
  }
  *exact = encloses(parent, target);
  return kParentCode;
}

LeafCode encode_enclosing_leaf(const Sphere& parent, const Sphere& target, LeafTrim mode) {
  // The largest trim whose sphere around the decoded centre still holds the target (encloses,
  // with the squared centre distance computed once).
  const auto trimmed = [&](std::uint32_t code, const Sphere& d, double dist2) {
    const double need = std::sqrt(dist2) + double(target.radius);
    std::uint32_t t = 0;
    while (t < max_leaf_trim(mode) &&
           need <= double(trimmed_leaf_radius(d.radius, t + 1, mode))) {
      ++t;
    }
    return LeafCode{code, t, trimmed_leaf_radius(d.radius, t, mode), true};
  };
  if (!(parent.radius > 0) || !std::isfinite(parent.radius)) {
    LeafCode c = trimmed(kParentCode, parent, distance_squared(parent.center, target.center));
    c.exact = encloses(parent, target);
    return c;
  }
  // Over all sizes that might still win: the smallest drawn (trimmed) radius, ties to the lower
  // code. A larger cube can win when its centre lies nearer the target's and the trim takes more
  // of it; none can once even its largest trim is above the best.
  LeafCode best{kParentCode, 0, std::numeric_limits<float>::infinity(), false};
  const float most_trimmed = trimmed_leaf_radius(1.0f, max_leaf_trim(mode), mode);
  // A candidate that cannot draw at or below the best so far is not decoded. A size of radius R
  // draws at most the best (radii with a relative margin of 1e-5 for their float rounding) from
  // its least such trim t on, which holds the target only when the centre distance is at most
  // R (1 - t step) - s: more by that margin and by what the decoded floats may differ from the
  // lattice estimate (estimate_margin).
  const double s = double(target.radius) / parent.radius;
  const double margin = estimate_margin(parent);
  const double step = 1.0 - double(trimmed_leaf_radius(1.0f, 1, mode));
  const double max_trim = max_leaf_trim(mode), steps = 1.0 / step;  // step: a power of 2
  // The best radius with its margin, in parent units (kept as the best changes).
  double bound = std::numeric_limits<double>::infinity();
  const auto reach = [&](int m, double radius) {
    // The least trim t with R (1 - t step) <= bound, rounded down a little so as never to
    // exceed it (a smaller t only widens the reach).
    const double t = std::max(0.0, std::ceil((1.0 - bound * kInverseRadius[m]) * steps - 1e-6));
    return t > max_trim ? -1.0 : radius * (1.0 - t * step) * (1 + 1e-5) - s + margin;
  };
  // A size whose most trimmed radius is clearly above the best cannot win, nor can larger ones.
  const auto go_on = [&](int, double radius) { return radius * most_trimmed <= bound; };
  search_enclosing(parent, target, go_on, reach, [&](std::uint32_t code, const Sphere& d, int,
                                                    double dist2) {
    if (d.radius * most_trimmed > best.radius) return false;
    const LeafCode c = trimmed(code, d, dist2);
    if (c.radius < best.radius || (c.radius == best.radius && c.code < best.code)) {
      best = c;
      bound = double(best.radius) * (1 + 1e-5) / parent.radius;
    }
    return true;
  });
  if (best.exact) return best;
  LeafCode c = trimmed(kParentCode, parent, distance_squared(parent.center, target.center));
  c.exact = encloses(parent, target);
  return c;
}

std::uint32_t encode_normal_nearest(Vec3f n) {
  const std::uint32_t q = qs_detail::encode_normal_by_bounds(n);
  const auto table = qs_detail::normal_table();
  const int face = int(q / (kNormalGrid * kNormalGrid));
  const int u = int(q / kNormalGrid) % kNormalGrid, v = int(q % kNormalGrid);
  // The atan-warped grid is not equal-angle; a neighbouring cell's centre can be nearer.
  std::uint32_t best = q;
  double best_dot = double(dot(table[q], n));
  for (int du = -1; du <= 1; ++du) {
    for (int dv = -1; dv <= 1; ++dv) {
      const int uu = u + du, vv = v + dv;
      if (uu < 0 || vv < 0 || uu >= kNormalGrid || vv >= kNormalGrid) continue;
      const auto c = std::uint32_t((face * kNormalGrid + uu) * kNormalGrid + vv);
      const double d =
          double(table[c].x) * n.x + double(table[c].y) * n.y + double(table[c].z) * n.z;
      if (d > best_dot) best = c, best_dot = d;
    }
  }
  return best;
}

double cone_half_angle(std::uint32_t k) {
  // Asked a few times for every interior node of a tree: computed once.
  static const double kHalfAngle[3] = {std::asin(double(qs_detail::cone_sin_bound(0))),
                                       std::asin(double(qs_detail::cone_sin_bound(1))),
                                       std::asin(double(qs_detail::cone_sin_bound(2)))};
  return k < 3 ? kHalfAngle[k] : std::numeric_limits<double>::infinity();
}

std::uint32_t encode_cone_at_least(double theta) {
  for (std::uint32_t k = 0; k < 3; ++k) {
    if (cone_half_angle(k) >= theta + 1e-6) return k;
  }
  return 3;
}

std::uint16_t encode_rgb565_nearest(Rgb8 c) {
  return static_cast<std::uint16_t>(kNearest5[c.r] << 11 | kNearest6[c.g] << 5 | kNearest5[c.b]);
}

double cosine_between(Vec3f a, Vec3f b) {
  const double la = std::sqrt(double(a.x) * a.x + double(a.y) * a.y + double(a.z) * a.z);
  const double lb = std::sqrt(double(b.x) * b.x + double(b.y) * b.y + double(b.z) * b.z);
  if (!(la > 0) || !(lb > 0)) return 1;
  const double d = (double(a.x) * b.x + double(a.y) * b.y + double(a.z) * b.z) / (la * lb);
  return std::clamp(d, -1.0, 1.0);
}

double angle_between(Vec3f a, Vec3f b) { return std::acos(cosine_between(a, b)); }

}  // namespace pointillist::ptl2
