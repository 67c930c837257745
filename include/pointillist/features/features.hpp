// Sharp edges, corners and intersecting surfaces of a splat set, found from the splats alone
// (Rafael Ivo's dissertation; specs/sharp-features.md is our specification, with the equation
// numbers used below):
//  1. the bounding-sphere neighbour graph (eq. 3.1, neighbour_graph.hpp);
//  2. sharp edges: neighbours whose normals differ, n_i·n_j < w_s (eqs. 3.2–3.3);
//  3. for each sharp edge, whether the discs really cross (eqs. 4.3–4.12) and whether the
//     splat's surface ends at the other splat's surface (a crease: clip) or passes through it
//     (an intersection: no clip, the surface ids separate them);
//  4. the clip planes of each splat, oriented, de-duplicated and combined by union or
//     intersection (eqs. 4.13–4.18, generalised for mixed corners);
//  5. surface ids: breadth-first search over the continuous edges (§1.8).
// The renderer discards a fragment of a splat where its clip planes say so (clip_discards) and
// blends a pixel's front surface only from fragments of one surface id.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "pointillist/core/math.hpp"
#include "pointillist/core/progress.hpp"
#include "pointillist/core/thread_pool.hpp"

namespace pointillist {

// How a sharp edge is told apart from an intersection of two surfaces that both continue.
enum class EdgeTest {
  // Per pair (spec §1.4 [P]): S_j may clip S_i iff S_i and its continuous neighbours do not lie
  // on both sides of S_j's plane by more than 0.1·r_i.
  Side,
  // Linsen's gap test (dissertation §4.1): S_i is on the boundary of its surface (and every
  // crossing partner clips it) iff the angular gap between its continuous neighbours, projected
  // into its plane, exceeds FeatureOptions::linsen_alpha_deg somewhere.
  Linsen,
};

// How the planes of several partners combine.
enum class ClipRule {
  // Pointillist's rule (spec §1.7 [I], §4.8 items 3–5): each partner's kept side is the side of
  // its plane where the splat's own surface lies; partners are combined by union when every
  // pair is convex, by intersection when every pair is reflex, and per fragment by the partner
  // whose line is nearest where the pairs disagree (the mixed corner).
  Classified,
  // The dissertation (eqs. 4.13–4.15 and 4.17): orientation and union/intersection from the
  // concave/convex classification; where it is undefined the splat is not clipped (counted).
  Dissertation,
  // Zwicker et al. 2004: every partner clips on its own (union), oriented by its own 4.14 sign.
  Independent,
  // Only the partner with the nearest centre (the dissertation's Fig. 6.4b).
  NearestPartner,
};

struct FeatureOptions {
  float sharp_threshold = 0.9f;  // w_s: an edge is sharp when n_i·n_j < w_s; in [-1, 1]
  // Raise the threshold on rough scans: when the normals of three quarters of the neighbour
  // pairs that face the same way differ by up to an angle that, times kSpreadFactor, exceeds
  // the threshold's angle, the threshold becomes the cosine of that product, at most
  // kMaxRaisedAngle (FeatureData::options holds the one used). Off when the user gives one.
  bool adapt_threshold = true;
  EdgeTest edge_test = EdgeTest::Side;
  float linsen_alpha_deg = 90.0f;  // gap that makes a boundary, EdgeTest::Linsen; (0, 360)
  ClipRule clip_rule = ClipRule::Classified;
  // The radius the renderer draws over the splat radius (QualitySettings::radius_scale): the
  // graph and the crossing tests use the drawn discs. In [1, 2].
  float radius_scale = 1.1f;
  // How far past the crease a disc is kept, in its radii, in [0, 0.5]: 0 for exact data. A
  // quantized model (.ptl v2: centres a few percent of a radius off their face, normals a
  // degree or two off) needs some, or the discs of two faces stop short of each other and open
  // thin holes along the crease; for_quantized_model gives them kQuantizedClipMargin.
  float clip_margin = 0.0f;
  // A scan's noise moves the lines out too: each splat's planes by the root-mean-square
  // distance of its and its partners' smooth neighbours from their fitted surfaces (Disc::noise,
  // 0 on exact data), when that is more than clip_margin. The part of that distance below
  // noise_floor drawn radii is not counted (in [0, 1]): a quantized model's centres and normals
  // leave about 0.11 radii on exact data, which clip_margin covers.
  float noise_floor = 0.0f;
};
inline constexpr float kQuantizedClipMargin = 0.1f;
// The smooth majority's spread times this is where a crease begins (FeatureOptions::
// adapt_threshold). Measured, the angle of the third quartile of neighbour normal differences:
// 0° (cube) to 18° (crossed cylinders with random sampling's discs) on the test scenes, 10°
// with 5° of noise, 12° on the dragon, 28° on the photogrammetric lion, where the default 26°
// cut the carving into ragged pieces and 40° draws its creases cleanly.
inline constexpr float kSpreadFactor = 1.4f;
// The threshold rises to at most this angle (radians, 45°), so that a coarse model, where
// crease pairs are many of the neighbours, keeps its right-angle creases.
inline constexpr float kMaxRaisedAngle = 0.25f * kPi;
inline constexpr float kQuantizedNoiseFloor = 0.12f;
// Fit residuals below this many drawn radii are no noise: on exact data the second-order fit leaves up to
// 0.0045 radii at curved creases (the random-sampled hole wall of T4), not noise; counted as
// noise, it moved the wall's lines past the rim, where the quality mode showed the wall over the
// top face (T4-R close-up: label errors 5.6 % of the crease band, 0.4 % with this floor).
// Noise that matters is tens of times more (T14-2: about 0.1 radii).
inline constexpr float kFitNoiseFloor = 0.02f;

// `options` for the leaves of a quantized model (.ptl v2, .qs): at least kQuantizedClipMargin
// and kQuantizedNoiseFloor.
inline FeatureOptions for_quantized_model(FeatureOptions options) {
  if (options.clip_margin < kQuantizedClipMargin) options.clip_margin = kQuantizedClipMargin;
  if (options.noise_floor < kQuantizedNoiseFloor) options.noise_floor = kQuantizedNoiseFloor;
  return options;
}

// Throws OptionError naming the field when a value is out of range.
void validate_feature_options(const FeatureOptions& options);

// A clip plane in the splat's own frame of reference (model space): a point P on the splat
// keeps its fragment on the plane's side n·P − h >= 0. Scaled so that, for P in the splat's
// plane, n·P − h is the distance from P to the line where the two planes meet.
struct ClipPlane {
  Vec3f n;
  float h = 0;
};
inline float plane_side(const ClipPlane& p, Vec3f point) { return dot(p.n, point) - p.h; }

enum class ClipMode : std::uint8_t {
  None,          // no planes
  Union,         // discard where any plane says so (the kept region is convex at the splat)
  Intersection,  // discard where every plane says so (a reflex corner)
  Nearest,       // the plane whose line is nearest to the point decides (mixed corners)
};

// Whether `mode` and `planes` discard the fragment at `point` (on the splat's plane).
inline bool clip_discards(std::span<const ClipPlane> planes, ClipMode mode, Vec3f point) {
  switch (mode) {
    case ClipMode::None: return false;
    case ClipMode::Union:
      for (const ClipPlane& p : planes) if (plane_side(p, point) < 0) return true;
      return false;
    case ClipMode::Intersection:
      for (const ClipPlane& p : planes) if (plane_side(p, point) >= 0) return false;
      return !planes.empty();
    case ClipMode::Nearest: {
      float best = INFINITY, side = 0;
      for (const ClipPlane& p : planes) {
        const float s = plane_side(p, point);
        if (std::fabs(s) < best) best = std::fabs(s), side = s;
      }
      return side < 0;
    }
  }
  return false;
}

// A surface id shared by no splat: an inner node of a hierarchy whose subtree has several ids.
// Its fragments blend with any surface.
constexpr std::uint32_t kMixedSurface = 0xffffffffu;
// At most this many planes per splat (the nearest partners are kept).
constexpr int kMaxClipPlanes = 16;

// The dissertation's statistics (Tables 6.1–6.3) and ours.
struct FeatureStats {
  std::uint64_t splats = 0;
  std::uint64_t edges = 0;          // |E|, undirected
  std::uint64_t sharp_edges = 0;    // E_s
  std::uint64_t crossing_edges = 0;  // E_ir: sharp edges whose discs cross
  std::uint64_t antiparallel_edges = 0;  // sharp edges between (nearly) parallel planes
  std::uint64_t candidates = 0;     // P_c: splats with a sharp edge
  std::uint64_t clipped = 0;        // P_r: splats with a clip plane
  std::uint64_t pass_through = 0;   // crossing partners rejected by the edge test (intersections)
  std::uint64_t undefined_4_15 = 0;  // splats with partners where eqs. 4.13–4.15 are undefined
  std::uint64_t nearest_rule = 0;   // splats clipped by ClipMode::Nearest
  std::uint64_t capped = 0;         // splats that had more than kMaxClipPlanes distinct planes
  float spread_deg = 0;             // neighbour normals: 3/4 of the pairs differ by at most this
  bool threshold_raised = false;    // FeatureOptions::adapt_threshold raised it above the spread
  std::uint64_t segments = 0;       // surface ids
  std::uint64_t large_segments = 0;  // segments with at least 0.5 % of the splats
  // [k] = splats with k clip planes, k = 1..kMaxClipPlanes ([0] unused).
  std::array<std::uint64_t, kMaxClipPlanes + 1> plane_histogram{};

  double mean_degree() const { return splats ? 2.0 * static_cast<double>(edges) / splats : 0; }
};

// What the features module computes, per splat of its input (structure of arrays).
struct FeatureData {
  std::vector<std::uint32_t> surface_id;
  std::vector<ClipMode> clip_mode;
  std::vector<std::uint32_t> clip_offset;  // size n + 1: planes of splat i are
  std::vector<ClipPlane> clip_planes;      // clip_planes[clip_offset[i] .. clip_offset[i + 1])
  FeatureOptions options;                  // what they were computed with
  FeatureStats stats;

  std::size_t size() const { return surface_id.size(); }
  std::span<const ClipPlane> planes(std::size_t i) const {
    return {clip_planes.data() + clip_offset[i], clip_planes.data() + clip_offset[i + 1]};
  }
};

// Features of the splats (centres, unit normals, splat radii; the drawn radius is
// options.radius_scale × radius). Normals must point outward consistently. Parallel; the result
// does not depend on the thread count. Progress phases "neighbour graph", "sharp features".
// Throws OptionError for invalid options.
FeatureData compute_features(std::span<const Vec3f> centers, std::span<const Vec3f> normals,
                             std::span<const float> radii, ThreadPool& pool,
                             const FeatureOptions& options = {},
                             Progress& progress = Progress::none());

// Empty, or what to tell the user when the features found look like noise rather than creases:
// more than half of the clipped splats met more than kMaxClipPlanes distinct planes (on the CSG
// test scenes, even with 5° of normal noise, at most 7 %; on a photogrammetric scan of a carved
// statue, 60 % at the threshold 0.9, which cut it into ragged pieces, and 45 % at the 0.77 its
// spread raises it to, which draws it cleanly).
std::string noisy_features_warning(const FeatureStats& stats, const FeatureOptions& options);

}  // namespace pointillist
