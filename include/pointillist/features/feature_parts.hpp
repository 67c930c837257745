// Sharp features of a splat set too large to hold whole (the chunked conversion), found part by
// part with the same results as compute_features over the whole set:
//  1. each part (its own splats plus a halo of other parts' splats around them) adds its
//     neighbour pairs' normal agreement to a SpreadHistogram; the histograms of all parts add up
//     to the whole set's, which decides the sharp threshold (adapt_sharp_threshold);
//  2. each part finds its own splats' sharp edges, clip planes and the surfaces they form inside
//     the part, and lists the halo splats those surfaces reach (compute_feature_part);
//  3. resolve_feature_links finds those splats' surfaces in the parts that own them, and
//     join_feature_parts merges the pairs and numbers the surfaces as compute_features does (in
//     the order of each surface's first splat).
// A part's splats are given in the whole set's order (`keys`, ascending); the results for its own
// splats are bit for bit those of the whole set when the halo holds every splat within two graph
// edges of them: feature_halo_reach says how far that is.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "pointillist/features/features.hpp"
#include "pointillist/features/neighbour_graph.hpp"

namespace pointillist {

// How often neighbour pairs' normals agree, as a histogram that parts add up: one count per
// bucket of the pair's n_i·n_j (every 4th entry of each row, pairs facing the same way), the
// bucket being the cosine's float bits shifted right by kShift (cosines 1 part in 2^15 apart).
struct SpreadHistogram {
  static constexpr unsigned kShift = 8;
  // Buckets in groups of 256 (a cosine's bits >> 16), allocated as they are first counted:
  // group g's counts are fine[slot[g] - 1] when slot[g] != 0.
  std::vector<std::uint32_t> slot;
  std::vector<std::array<std::uint64_t, 256>> fine;

  void add(const SpreadHistogram& other);
  void count(float cosine);  // cosines <= 0 are not counted, those above 1 count as 1
  std::uint64_t total() const;
  // The angle (radians) within which three quarters of the pairs agree: the cosine of the
  // bucket holding the pair ranked a quarter up from the least agreeing one (its middle value);
  // 0 when nothing was counted.
  float spread() const;
};

// The histogram of `graph`'s rows of the splats with owned[i] != 0 (all when `owned` is empty).
SpreadHistogram normal_spread_histogram(const NeighbourGraph& graph,
                                        std::span<const Vec3f> normals,
                                        std::span<const std::uint8_t> owned = {});

// `options` with the threshold raised above the spread (FeatureOptions::adapt_threshold), and
// `stats` told the spread and whether it was raised.
FeatureOptions adapt_sharp_threshold(const FeatureOptions& options,
                                     const SpreadHistogram& histogram, FeatureStats& stats);

// One part: its own splats and the halo, in the whole set's order.
struct FeaturePartInput {
  std::span<const Vec3f> centers, normals;
  std::span<const float> radii;            // splat radii (drawn: options.radius_scale times)
  std::span<const std::uint64_t> keys;     // each splat's place in the whole set, ascending
  std::span<const std::uint8_t> owned;     // 1: the part's own splat, 0: halo
};

// What a part adds to the spread (its own rows; a halo one drawn radius wide is enough), and the
// largest drawn radius among its halo splats that are sharp neighbours of its own splats at
// options.sharp_threshold (which adaptation only lowers): feature_halo_reach's r_sharp.
struct FeaturePartSpread {
  SpreadHistogram histogram;
  float r_sharp = 0;
};
FeaturePartSpread feature_part_spread(const FeaturePartInput& part,
                                      const FeatureOptions& options, ThreadPool& pool);

// A halo splat that one of the part's surfaces reaches by smooth edges: the part that owns it
// has it on a surface of its own, which is the same surface.
struct FeatureLink {
  std::uint32_t component = 0;  // the part's surface
  std::uint32_t reserved = 0;   // (no padding bytes: links go to disk and between ranks)
  std::uint64_t other = 0;      // the halo splat's key
};

// What a part finds for its own splats (in their order).
struct FeaturePart {
  std::vector<ClipMode> clip_mode;
  std::vector<std::uint32_t> clip_offset;  // own splats + 1
  std::vector<ClipPlane> clip_planes;
  std::vector<std::uint32_t> component;    // each own splat's surface inside the part
  // Per surface inside the part, numbered in the order of their first splats: that first
  // splat's key, and the surface's splat count.
  std::vector<std::uint64_t> component_first;
  std::vector<std::uint64_t> component_size;
  std::vector<FeatureLink> links;          // one per halo splat reached, by key
  std::uint64_t row_entries = 0;           // own splats' graph rows, summed (each edge twice overall)
  FeatureStats stats;                      // of the own splats; no edges, no surfaces yet
};

// Finds the own splats' features with the threshold of `options` as given (no adaptation:
// adapt_sharp_threshold decided it for the whole set). Throws OptionError for invalid options,
// Error when the spans differ in size or keys are not ascending.
FeaturePart compute_feature_part(const FeaturePartInput& part, const FeatureOptions& options,
                                 ThreadPool& pool, Progress& progress = Progress::none());

// How far around a part the halo must reach: every splat whose centre lies within
// feature_halo_reach(r_own, r_sharp) + its own drawn radius of the part's own centres' box, where
// r_own is the largest drawn radius among the part's own splats and r_sharp the largest among
// the splats that are sharp neighbours of them (n_i·n_j below the threshold), at least r_own;
// the whole set's largest will do (graph edges join centres nearer than the sum of their drawn
// radii, and a sharp neighbour's own row must be complete: its shape fit reads it).
inline float feature_halo_reach(float r_own, float r_sharp) { return r_own + 2.0f * r_sharp; }

// A part's surface: the part's index in the list given to join_feature_parts, and the surface's
// number in the part.
struct PartSurface {
  std::uint32_t part, component;
};

// The pairs of surfaces that `links` of part `from` join with part `to`'s, whose own splats'
// keys (ascending) and surfaces are `to_keys` and `to_components`: links to splats `to` does not
// own are left alone. Appends to `joined`.
void resolve_feature_links(std::uint32_t from, std::span<const FeatureLink> links,
                           std::uint32_t to, std::span<const std::uint64_t> to_keys,
                           std::span<const std::uint32_t> to_components,
                           std::vector<std::pair<PartSurface, PartSurface>>& joined);

// What the surfaces of all parts come to.
struct FeatureJoin {
  std::vector<std::vector<std::uint32_t>> surface;  // per part, per part surface: its id
  std::uint64_t segments = 0, large_segments = 0;
};

// Merges the parts' surfaces that `joined` pairs (resolve_feature_links, over every part's
// links and the parts that own their splats) and numbers the surfaces in the order of their
// first splats, over `splats` splats in all (large: at least 0.5 % of them), as
// compute_features does.
FeatureJoin join_feature_parts(std::span<const FeaturePart* const> parts, std::uint64_t splats,
                               std::span<const std::pair<PartSurface, PartSurface>> joined);

// Adds the counts of `from` to `to` (sharp, crossing and antiparallel edges, candidates,
// clipped splats and their plane histogram, pass-throughs, undefined, nearest-rule and capped
// splats); splats, edges, spread and surfaces are left alone.
void add_feature_counts(FeatureStats& to, const FeatureStats& from);

// The whole set's statistics from the parts' and the join.
FeatureStats joined_feature_stats(std::span<const FeaturePart* const> parts,
                                  const FeatureJoin& join, const FeatureStats& spread_stats);

}  // namespace pointillist
