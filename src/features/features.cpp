// compute_features: the graph, then every splat's sharp edges, partners and planes in parallel
// blocks (concatenated in splat order), then the surface ids.
#include <algorithm>
#include <cstdio>
#include <cmath>
#include <string>

#include "pointillist/core/error.hpp"
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

void add(FeatureStats& to, const FeatureStats& from) {
  to.sharp_edges += from.sharp_edges;
  to.crossing_edges += from.crossing_edges;
  to.antiparallel_edges += from.antiparallel_edges;
  to.candidates += from.candidates;
  to.clipped += from.clipped;
  to.pass_through += from.pass_through;
  to.undefined_4_15 += from.undefined_4_15;
  to.nearest_rule += from.nearest_rule;
  to.capped += from.capped;
  for (std::size_t k = 0; k < to.plane_histogram.size(); ++k) {
    to.plane_histogram[k] += from.plane_histogram[k];
  }
}

// Breadth-first search over the continuous edges, seeded in increasing splat index (spec §1.8
// [P]): ids are numbered in the order of each surface's smallest splat index.
std::uint64_t segment(const NeighbourGraph& graph, std::span<const std::uint8_t> kinds,
                      std::vector<std::uint32_t>& ids, std::uint64_t& large) {
  const std::size_t n = graph.vertex_count();
  constexpr std::uint32_t kNone = 0xffffffffu;
  ids.assign(n, kNone);
  std::vector<std::uint32_t> queue(n);
  std::uint32_t next_id = 0;
  large = 0;
  const std::size_t large_size = std::max<std::size_t>(1, (n + 199) / 200);  // 0.5 %
  for (std::size_t seed = 0; seed < n; ++seed) {
    if (ids[seed] != kNone) continue;
    std::size_t head = 0, tail = 0;
    queue[tail++] = static_cast<std::uint32_t>(seed);
    ids[seed] = next_id;
    while (head < tail) {
      const std::uint32_t s = queue[head++];
      for (std::uint64_t e = graph.offsets[s]; e < graph.offsets[s + 1]; ++e) {
        const std::uint32_t j = graph.neighbours[e];
        if (ids[j] == kNone && kinds[e] == kContinuous) {
          ids[j] = next_id;
          queue[tail++] = j;
        }
      }
    }
    if (tail >= large_size) ++large;
    ++next_id;
  }
  return next_id;
}

// The angle (radians) within which the normals of three quarters of the neighbour pairs agree,
// over every 4th edge (the statistic needs no more); pairs facing apart, such as a thin part's
// two sides, are not the surface's roughness.
float normal_spread(const NeighbourGraph& graph, std::span<const Vec3f> normals) {
  std::vector<float> dots;
  dots.reserve(graph.neighbours.size() / 4 + 1);
  for (std::size_t i = 0; i < graph.vertex_count(); ++i) {
    for (std::uint64_t e = graph.offsets[i]; e < graph.offsets[i + 1]; e += 4) {
      const float d = dot(normals[i], normals[graph.neighbours[e]]);
      if (d > 0) dots.push_back(d);
    }
  }
  if (dots.empty()) return 0;
  const auto quartile = dots.begin() + static_cast<std::ptrdiff_t>(dots.size() / 4);
  std::nth_element(dots.begin(), quartile, dots.end());
  return std::acos(std::min(*quartile, 1.0f));
}

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

FeatureData compute_features(std::span<const Vec3f> centers, std::span<const Vec3f> normals,
                             std::span<const float> radii, ThreadPool& pool,
                             const FeatureOptions& options, Progress& progress) {
  validate_feature_options(options);
  const std::size_t n = centers.size();
  FeatureData out;
  out.options = options;
  std::vector<float> drawn(n);
  for (std::size_t i = 0; i < n; ++i) drawn[i] = radii[i] * options.radius_scale;
  const NeighbourGraph graph = build_neighbour_graph(centers, drawn, pool, progress);
  out.stats.splats = n;
  out.stats.edges = graph.edge_count();

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
  // The threshold raised above a rough scan's spread.
  const float spread = normal_spread(graph, normals);
  out.stats.spread_deg = spread * 180.0f / kPi;
  const float raised = std::cos(std::min(kSpreadFactor * spread, kMaxRaisedAngle));
  if (options.adapt_threshold && raised < out.options.sharp_threshold) {
    out.options.sharp_threshold = raised;
    out.stats.threshold_raised = true;
  }
  const float w_s = out.options.sharp_threshold;
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
      block.modes.resize(end - first);
      block.plane_counts.resize(end - first);
      std::vector<Vec3f> continuous;
      std::vector<std::size_t> crossing;  // into `sharp`
      std::vector<Disc> partners, through, sharp;
      for (std::size_t i = first; i < end; ++i) {
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
          if (j > i) {
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
        block.modes[i - first] = clip.mode;
        block.plane_counts[i - first] = static_cast<std::uint32_t>(clip.planes.size());
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

  out.clip_mode.reserve(n);
  out.clip_offset.reserve(n + 1);
  out.clip_offset.push_back(0);
  for (const Block& block : blocks) {
    add(out.stats, block.stats);
    out.clip_mode.insert(out.clip_mode.end(), block.modes.begin(), block.modes.end());
    for (std::uint32_t count : block.plane_counts) {
      out.clip_offset.push_back(out.clip_offset.back() + count);
    }
    out.clip_planes.insert(out.clip_planes.end(), block.planes.begin(), block.planes.end());
  }
  out.stats.segments = segment(graph, kinds, out.surface_id, out.stats.large_segments);
  return out;
}

}  // namespace pointillist
