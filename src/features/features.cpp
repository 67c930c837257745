// compute_features and compute_feature_part: the graph, then every splat's sharp edges, partners
// and planes in parallel blocks (concatenated in splat order), then the surfaces.
#include <algorithm>
#include <cstdio>
#include <cmath>
#include <string>

#include "pointillist/core/error.hpp"
#include "pointillist/features/feature_parts.hpp"
#include "pointillist/features/features.hpp"
#include "pointillist/features/neighbour_graph.hpp"
#include "pointillist/features/rules.hpp"

namespace pointillist {
namespace {

// What an edge of the graph is: sharp (normals apart), continuous (one smooth surface), or
// neither: parallel discs stacked above each other (two surfaces side by side, such as the
// nearly parallel parts of two crossed cylinders, or the two faces of a thin slab), whose
// normals agree but whose centres are not on each other's planes (on_planes_of_each_other).
// One byte per directed edge, in the graph's order.
enum EdgeKind : std::uint8_t { kStacked, kContinuous, kSharp };

struct Block {
  std::vector<ClipMode> modes;
  std::vector<std::uint32_t> plane_counts;
  std::vector<ClipPlane> planes;
  FeatureStats stats;
};

}  // namespace

void validate_feature_options(const FeatureOptions& o) {
  if (!(o.sharp_threshold >= -1.0f && o.sharp_threshold <= 1.0f)) {
    throw OptionError("--sharp-threshold must be in [-1, 1] (the cosine of the angle between two "
                      "neighbours' normals below which their edge is sharp; 0.9 is about 26°), "
                      "not " + std::to_string(o.sharp_threshold));
  }
  if (!(o.linsen_alpha_deg > 0.0f && o.linsen_alpha_deg < 360.0f)) {
    throw OptionError("the Linsen gap angle must be in (0, 360) degrees, not " +
                      std::to_string(o.linsen_alpha_deg));
  }
  if (!(o.clip_margin >= 0.0f && o.clip_margin <= 0.5f)) {
    throw OptionError("the clip margin must be in [0, 0.5] splat radii, not " +
                      std::to_string(o.clip_margin));
  }
  if (!(o.noise_floor >= 0.0f && o.noise_floor <= 1.0f)) {
    throw OptionError("the noise floor must be in [0, 1] splat radii, not " +
                      std::to_string(o.noise_floor));
  }
  if (!(o.radius_scale >= 1.0f && o.radius_scale <= 2.0f)) {
    throw OptionError("the features' radius scale must be in [1, 2] (the renderer's "
                      "--radius-scale), not " + std::to_string(o.radius_scale));
  }
}

std::string noisy_features_warning(const FeatureStats& s, const FeatureOptions& o) {
  if (s.clipped == 0 || s.capped * 2 <= s.clipped) return {};
  const double degrees = std::acos(std::clamp(o.sharp_threshold, -1.0f, 1.0f)) * 180.0 / kPi;
  char text[640];
  std::snprintf(text, sizeof text,
                "%.0f %% of the clipped splats meet more than %d distinct planes, and %llu "
                "surfaces were found (%llu with at least 0.5 %% of the splats): the normals "
                "differ by more than the sharp threshold (%.2f, %.0f degrees) between most "
                "neighbouring discs, as on a noisy or finely carved scan, so the planes cut the "
                "surface into ragged pieces. Draw it with --no-features, or find only stronger "
                "creases with a lower --sharp-threshold (0.7 is 46 degrees, 0.5 is 60)",
                100.0 * static_cast<double>(s.capped) / static_cast<double>(s.clipped),
                kMaxClipPlanes, static_cast<unsigned long long>(s.segments),
                static_cast<unsigned long long>(s.large_segments), o.sharp_threshold, degrees);
  return text;
}


namespace {

// The part's own splats' features over `graph` (rows of own splats and of their neighbours
// complete), with the threshold of `options` as given. `owned` empty: every splat is the part's.
FeaturePart features_over_graph(const NeighbourGraph& graph, std::span<const Vec3f> centers,
                                std::span<const Vec3f> normals, std::span<const float> drawn,
                                std::span<const std::uint64_t> keys,
                                std::span<const std::uint8_t> owned, const FeatureOptions& options,
                                ThreadPool& pool, Progress& progress) {
  const std::size_t n = centers.size();
  const auto own = [&](std::size_t i) { return owned.empty() || owned[i] != 0; };
  const auto key = [&](std::size_t i) { return keys.empty() ? std::uint64_t{i} : keys[i]; };
  FeaturePart out;
  const bool reflex_rule =
      options.edge_test == EdgeTest::Side && options.clip_rule == ClipRule::Classified;
  constexpr std::size_t kBlock = 4096;
  std::vector<Block> blocks((n + kBlock - 1) / kBlock);
  // Each edge's kind, and the surface's shape at every splat with a sharp edge (a possible
  // partner) from its continuous neighbours: Pointillist's rule corrects partner planes at
  // curved creases.
  std::vector<std::uint8_t> kinds(graph.neighbours.size());
  std::vector<Shape> shapes;
  std::vector<float> noise;
  const bool classified = options.clip_rule == ClipRule::Classified;
  if (classified) shapes.resize(n), noise.resize(n);
  const float w_s = options.sharp_threshold;
  pool.run(blocks.size(), [&](std::size_t b) {
    std::vector<Vec3f> around, around_normals;
    for (std::size_t i = b * kBlock, end = std::min(n, i + kBlock); i < end; ++i) {
      around.clear();
      around_normals.clear();
      bool sharp = false;
      for (std::uint64_t e = graph.offsets[i]; e < graph.offsets[i + 1]; ++e) {
        const std::uint32_t j = graph.neighbours[e];
        if (dot(normals[i], normals[j]) < w_s) {
          kinds[e] = kSharp;
          sharp = true;
        } else if (on_planes_of_each_other(centers[i], normals[i], drawn[i], centers[j],
                                           normals[j], drawn[j], w_s)) {
          kinds[e] = kContinuous;
          around.push_back(centers[j]);
          around_normals.push_back(normals[j]);
        } else {
          kinds[e] = kStacked;
        }
      }
      if (classified && sharp) {
        shapes[i] = fit_shape(centers[i], normals[i], around, around_normals);
        // The residual less what the model's quantization alone leaves (noise_floor); none
        // when it is what the second-order fit alone leaves on exact data (kFitNoiseFloor).
        const float residual = fit_residual(centers[i], normals[i], shapes[i], around);
        const float floor = options.noise_floor * drawn[i];
        noise[i] = residual < kFitNoiseFloor * drawn[i]
                       ? 0.0f
                       : std::sqrt(std::max(0.0f, residual * residual - floor * floor));
      }
    }
  });
  const auto disc = [&](std::size_t j) {
    return classified ? Disc{centers[j], normals[j], drawn[j], shapes[j], noise[j]}
                      : Disc{centers[j], normals[j], drawn[j]};
  };
  {
    ProgressPhase phase(progress, "sharp features", n);
    pool.run(blocks.size(), [&](std::size_t b) {
      Block& block = blocks[b];
      const std::size_t first = b * kBlock, end = std::min(n, first + kBlock);
      std::vector<Vec3f> continuous;
      std::vector<std::size_t> crossing;  // into `sharp`
      std::vector<Disc> partners, through, sharp;
      for (std::size_t i = first; i < end; ++i) {
        if (!own(i)) continue;
        const Disc s = disc(i);
        continuous.clear();
        crossing.clear();
        sharp.clear();
        bool candidate = false;
        for (std::uint64_t e = graph.offsets[i]; e < graph.offsets[i + 1]; ++e) {
          const std::uint32_t j = graph.neighbours[e];
          if (kinds[e] != kSharp) {
            if (kinds[e] == kContinuous) continuous.push_back(centers[j]);
            continue;
          }
          candidate = true;
          sharp.push_back(disc(j));
          const Crossing x = disc_crossing(s, sharp.back());
          // Each sharp edge counted once over the whole set: at its end of lower key.
          if (key(j) > key(i)) {
            ++block.stats.sharp_edges;
            block.stats.crossing_edges += x == Crossing::Cross;
            block.stats.antiparallel_edges += x == Crossing::Parallel;
          }
          if (x == Crossing::Cross) crossing.push_back(sharp.size() - 1);
        }
        block.stats.candidates += candidate;
        // Partners: crossing discs at which this splat's surface ends, nearest first.
        const bool boundary = options.edge_test == EdgeTest::Linsen && !crossing.empty() &&
                              linsen_boundary(s, continuous, options.linsen_alpha_deg);
        partners.clear();
        through.clear();
        for (const std::size_t k : crossing) {
          const Disc& p = sharp[k];
          const bool ends = options.edge_test == EdgeTest::Linsen ? boundary
                                                                   : surface_ends_at(s, continuous, p);
          (ends ? partners : through).push_back(p);
        }
        // Of the crossings the surface passes through, only those at a reflex vertex of the
        // splat's face clip it (Pointillist's rule only): keep them in `through`.
        const std::size_t passing = through.size();
        if (reflex_rule && !through.empty()) {
          const std::vector<std::uint8_t> reflex = reflex_partners(s, continuous, through);
          std::size_t kept = 0;
          for (std::size_t k = 0; k < through.size(); ++k) {
            if (reflex[k]) through[kept++] = through[k];
          }
          through.resize(kept);
        } else {
          through.clear();
        }
        block.stats.pass_through += passing - through.size();
        const auto nearer = [&](const Disc& a, const Disc& c) {
          return length_squared(a.c - s.c) < length_squared(c.c - s.c);
        };
        std::stable_sort(partners.begin(), partners.end(), nearer);
        std::stable_sort(through.begin(), through.end(), nearer);
        ClipResult clip = classify_partners(s, partners, continuous, options.clip_rule, through,
                                            options.clip_margin);
        if (classified) keep_uncovered(s, clip, sharp, w_s);
        block.stats.undefined_4_15 += clip.undefined_4_15;
        block.stats.capped += clip.capped;
        block.modes.push_back(clip.mode);
        block.plane_counts.push_back(static_cast<std::uint32_t>(clip.planes.size()));
        if (!clip.planes.empty()) {
          ++block.stats.clipped;
          ++block.stats.plane_histogram[clip.planes.size()];
          block.stats.nearest_rule += clip.mode == ClipMode::Nearest;
          block.planes.insert(block.planes.end(), clip.planes.begin(), clip.planes.end());
        }
      }
      progress.advance(end - first);
    });
  }

  std::size_t owned_count = 0;
  for (const Block& block : blocks) owned_count += block.modes.size();
  out.clip_mode.reserve(owned_count);
  out.clip_offset.reserve(owned_count + 1);
  out.clip_offset.push_back(0);
  for (const Block& block : blocks) {
    add_feature_counts(out.stats, block.stats);
    out.clip_mode.insert(out.clip_mode.end(), block.modes.begin(), block.modes.end());
    for (std::uint32_t count : block.plane_counts) {
      out.clip_offset.push_back(out.clip_offset.back() + count);
    }
    out.clip_planes.insert(out.clip_planes.end(), block.planes.begin(), block.planes.end());
  }
  out.stats.splats = owned_count;

  // Surfaces inside the part: breadth-first search over the continuous edges, seeded at the own
  // splats in increasing order (spec §1.8 [P]), so they are numbered in the order of their first
  // splats. The search goes through halo splats too (every edge between splats of the part is an
  // edge of the whole set, so what it joins is joined; only edges to splats outside the part are
  // missing): each halo splat it reaches becomes a link, which the join follows into the part
  // that owns it.
  constexpr std::uint32_t kNone = 0xffffffffu;
  std::vector<std::uint32_t> label(n, kNone);
  std::vector<std::uint32_t> queue(n);
  for (std::size_t seed = 0; seed < n; ++seed) {
    if (!own(seed) || label[seed] != kNone) continue;
    const auto id = static_cast<std::uint32_t>(out.component_first.size());
    std::size_t head = 0, tail = 0, owned_here = 0;
    queue[tail++] = static_cast<std::uint32_t>(seed);
    label[seed] = id;
    while (head < tail) {
      const std::uint32_t s = queue[head++];
      owned_here += own(s);
      for (std::uint64_t e = graph.offsets[s]; e < graph.offsets[s + 1]; ++e) {
        const std::uint32_t j = graph.neighbours[e];
        if (label[j] == kNone && kinds[e] == kContinuous) {
          label[j] = id;
          queue[tail++] = j;
        }
      }
    }
    out.component_first.push_back(key(seed));
    out.component_size.push_back(owned_here);
  }
  out.component.reserve(owned_count);
  for (std::size_t i = 0; i < n; ++i) {
    if (own(i)) {
      out.component.push_back(label[i]);
      out.row_entries += graph.offsets[i + 1] - graph.offsets[i];
    } else if (label[i] != kNone) {
      out.links.push_back({.component = label[i], .other = key(i)});
    }
  }
  return out;
}

std::vector<float> drawn_radii(std::span<const float> radii, const FeatureOptions& options) {
  std::vector<float> drawn(radii.size());
  for (std::size_t i = 0; i < radii.size(); ++i) drawn[i] = radii[i] * options.radius_scale;
  return drawn;
}

void check_part(const FeaturePartInput& part) {
  const std::size_t n = part.centers.size();
  if (part.normals.size() != n || part.radii.size() != n || part.keys.size() != n ||
      part.owned.size() != n) {
    throw Error("sharp features of a part: " + std::to_string(n) + " centres but " +
                std::to_string(part.normals.size()) + " normals, " +
                std::to_string(part.radii.size()) + " radii, " + std::to_string(part.keys.size()) +
                " keys and " + std::to_string(part.owned.size()) + " ownership flags");
  }
  for (std::size_t i = 1; i < n; ++i) {
    if (!(part.keys[i - 1] < part.keys[i])) {
      throw Error("sharp features of a part: splat " + std::to_string(i) + "'s key " +
                  std::to_string(part.keys[i]) + " does not follow " +
                  std::to_string(part.keys[i - 1]) + "; give the splats in the whole set's order");
    }
  }
}

}  // namespace

FeaturePart compute_feature_part(const FeaturePartInput& part, const FeatureOptions& options,
                                 ThreadPool& pool, Progress& progress) {
  validate_feature_options(options);
  check_part(part);
  const std::vector<float> drawn = drawn_radii(part.radii, options);
  const NeighbourGraph graph = build_neighbour_graph(part.centers, drawn, pool, progress);
  return features_over_graph(graph, part.centers, part.normals, drawn, part.keys, part.owned,
                             options, pool, progress);
}

FeaturePartSpread feature_part_spread(const FeaturePartInput& part, const FeatureOptions& options,
                                      ThreadPool& pool) {
  validate_feature_options(options);
  check_part(part);
  const std::vector<float> drawn = drawn_radii(part.radii, options);
  const NeighbourGraph graph = build_neighbour_graph(part.centers, drawn, pool);
  FeaturePartSpread out;
  out.histogram = normal_spread_histogram(graph, part.normals, part.owned);
  for (std::size_t i = 0; i < graph.vertex_count(); ++i) {
    if (!part.owned[i]) continue;
    for (const std::uint32_t j : graph.row(i)) {
      if (!part.owned[j] && dot(part.normals[i], part.normals[j]) < options.sharp_threshold) {
        out.r_sharp = std::max(out.r_sharp, drawn[j]);
      }
    }
  }
  return out;
}

FeatureData compute_features(std::span<const Vec3f> centers, std::span<const Vec3f> normals,
                             std::span<const float> radii, ThreadPool& pool,
                             const FeatureOptions& options, Progress& progress) {
  validate_feature_options(options);
  const std::vector<float> drawn = drawn_radii(radii, options);
  const NeighbourGraph graph = build_neighbour_graph(centers, drawn, pool, progress);
  FeatureStats spread_stats;
  const FeatureOptions decided =
      adapt_sharp_threshold(options, normal_spread_histogram(graph, normals), spread_stats);
  FeaturePart part =
      features_over_graph(graph, centers, normals, drawn, {}, {}, decided, pool, progress);
  const FeaturePart* const parts[] = {&part};
  const FeatureJoin join = join_feature_parts(parts, centers.size(), {});
  FeatureData out;
  out.options = decided;
  out.stats = joined_feature_stats(parts, join, spread_stats);
  out.surface_id = std::move(part.component);
  for (std::uint32_t& id : out.surface_id) id = join.surface[0][id];
  out.clip_mode = std::move(part.clip_mode);
  out.clip_offset = std::move(part.clip_offset);
  out.clip_planes = std::move(part.clip_planes);
  return out;
}

}  // namespace pointillist
