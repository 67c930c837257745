// The spread histogram, the threshold it decides, and the join of parts' surfaces
// (feature_parts.hpp).
#include "pointillist/features/feature_parts.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <numeric>
#include <string>

#include "pointillist/core/error.hpp"

namespace pointillist {
namespace {

constexpr std::uint32_t kOneBits = 0x3f800000u;  // 1.0f
constexpr std::size_t kGroups = (kOneBits >> 16) + 1;

}  // namespace

void SpreadHistogram::count(float cosine) {
  if (!(cosine > 0.0f)) return;
  const std::uint32_t bits = std::min(std::bit_cast<std::uint32_t>(cosine), kOneBits);
  if (slot.empty()) slot.assign(kGroups, 0);
  std::uint32_t& s = slot[bits >> 16];
  if (s == 0) {
    fine.push_back({});
    s = static_cast<std::uint32_t>(fine.size());
  }
  ++fine[s - 1][(bits >> kShift) & 0xff];
}

void SpreadHistogram::add(const SpreadHistogram& other) {
  if (other.slot.empty()) return;
  if (slot.empty()) slot.assign(kGroups, 0);
  for (std::size_t g = 0; g < kGroups; ++g) {
    if (other.slot[g] == 0) continue;
    if (slot[g] == 0) {
      fine.push_back({});
      slot[g] = static_cast<std::uint32_t>(fine.size());
    }
    auto& to = fine[slot[g] - 1];
    const auto& from = other.fine[other.slot[g] - 1];
    for (std::size_t b = 0; b < to.size(); ++b) to[b] += from[b];
  }
}

std::uint64_t SpreadHistogram::total() const {
  std::uint64_t sum = 0;
  for (const auto& group : fine) sum = std::accumulate(group.begin(), group.end(), sum);
  return sum;
}

float SpreadHistogram::spread() const {
  const std::uint64_t m = total();
  if (m == 0) return 0.0f;
  // The pair of rank m / 4 counted from the least agreeing (smallest cosine).
  std::uint64_t rank = m / 4, below = 0;
  for (std::size_t g = 0; g < slot.size(); ++g) {
    if (slot[g] == 0) continue;
    const auto& group = fine[slot[g] - 1];
    for (std::size_t b = 0; b < group.size(); ++b) {
      below += group[b];
      if (below > rank) {
        const std::uint32_t bits = static_cast<std::uint32_t>((g << 16) | (b << kShift)) |
                                   (1u << (kShift - 1));
        const float cosine = std::min(std::bit_cast<float>(bits), 1.0f);
        return std::acos(cosine);
      }
    }
  }
  return 0.0f;
}

SpreadHistogram normal_spread_histogram(const NeighbourGraph& graph,
                                        std::span<const Vec3f> normals,
                                        std::span<const std::uint8_t> owned) {
  // Every 4th entry of each row (the statistic needs no more); pairs facing apart, such as a
  // thin part's two sides, are not the surface's roughness.
  SpreadHistogram h;
  for (std::size_t i = 0; i < graph.vertex_count(); ++i) {
    if (!owned.empty() && owned[i] == 0) continue;
    for (std::uint64_t e = graph.offsets[i]; e < graph.offsets[i + 1]; e += 4) {
      h.count(dot(normals[i], normals[graph.neighbours[e]]));
    }
  }
  return h;
}

FeatureOptions adapt_sharp_threshold(const FeatureOptions& options,
                                     const SpreadHistogram& histogram, FeatureStats& stats) {
  FeatureOptions out = options;
  const float spread = histogram.spread();
  stats.spread_deg = spread * 180.0f / kPi;
  stats.threshold_raised = false;
  const float raised = std::cos(std::min(kSpreadFactor * spread, kMaxRaisedAngle));
  if (options.adapt_threshold && raised < out.sharp_threshold) {
    out.sharp_threshold = raised;
    stats.threshold_raised = true;
  }
  return out;
}

void add_feature_counts(FeatureStats& to, const FeatureStats& from) {
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

void resolve_feature_links(std::uint32_t from, std::span<const FeatureLink> links,
                           std::uint32_t to, std::span<const std::uint64_t> to_keys,
                           std::span<const std::uint32_t> to_components,
                           std::vector<std::pair<PartSurface, PartSurface>>& joined) {
  for (const FeatureLink& l : links) {
    const auto it = std::lower_bound(to_keys.begin(), to_keys.end(), l.other);
    if (it == to_keys.end() || *it != l.other) continue;
    const std::uint32_t c = to_components[std::size_t(it - to_keys.begin())];
    joined.push_back({{from, l.component}, {to, c}});
  }
}

FeatureJoin join_feature_parts(std::span<const FeaturePart* const> parts, std::uint64_t splats,
                               std::span<const std::pair<PartSurface, PartSurface>> joined) {
  // Every part's surfaces numbered one after the other, then joined by a union-find.
  std::vector<std::size_t> base(parts.size() + 1, 0);
  for (std::size_t p = 0; p < parts.size(); ++p) {
    base[p + 1] = base[p] + parts[p]->component_first.size();
  }
  const std::size_t total = base.back();
  std::vector<std::size_t> up(total);
  std::iota(up.begin(), up.end(), std::size_t{0});
  const auto find = [&](std::size_t a) {
    while (up[a] != a) a = up[a] = up[up[a]];
    return a;
  };
  const auto index = [&](const PartSurface& s) {
    if (s.part >= parts.size() || s.component >= parts[s.part]->component_first.size()) {
      throw Error("sharp features: a joined surface (part " + std::to_string(s.part) +
                  ", surface " + std::to_string(s.component) + ") does not exist");
    }
    return base[s.part] + s.component;
  };
  for (const auto& [a, b] : joined) {
    const std::size_t x = find(index(a)), y = find(index(b));
    if (x != y) up[std::max(x, y)] = std::min(x, y);
  }
  // Each joined surface's first splat and size; ids in the order of first splats.
  constexpr std::uint64_t kUnset = ~std::uint64_t{0};
  std::vector<std::uint64_t> first(total, kUnset), size(total, 0);
  std::vector<std::size_t> root(total);
  for (std::size_t p = 0; p < parts.size(); ++p) {
    for (std::size_t c = 0; c < parts[p]->component_first.size(); ++c) {
      const std::size_t r = root[base[p] + c] = find(base[p] + c);
      first[r] = std::min(first[r], parts[p]->component_first[c]);
      size[r] += parts[p]->component_size[c];
    }
  }
  std::vector<std::size_t> roots;
  for (std::size_t s = 0; s < total; ++s) {
    if (first[s] != kUnset) roots.push_back(s);
  }
  std::sort(roots.begin(), roots.end(),
            [&](std::size_t a, std::size_t b) { return first[a] < first[b]; });
  std::vector<std::uint32_t> id(total, 0);
  FeatureJoin out;
  const std::uint64_t large_size = std::max<std::uint64_t>(1, (splats + 199) / 200);  // 0.5 %
  for (std::size_t k = 0; k < roots.size(); ++k) {
    id[roots[k]] = static_cast<std::uint32_t>(k);
    out.large_segments += size[roots[k]] >= large_size;
  }
  out.segments = roots.size();
  out.surface.resize(parts.size());
  for (std::size_t p = 0; p < parts.size(); ++p) {
    out.surface[p].resize(parts[p]->component_first.size());
    for (std::size_t c = 0; c < out.surface[p].size(); ++c) {
      out.surface[p][c] = id[root[base[p] + c]];
    }
  }
  return out;
}

FeatureStats joined_feature_stats(std::span<const FeaturePart* const> parts,
                                  const FeatureJoin& join, const FeatureStats& spread_stats) {
  FeatureStats s;
  std::uint64_t row_entries = 0;
  for (const FeaturePart* p : parts) {
    add_feature_counts(s, p->stats);
    s.splats += p->stats.splats;
    row_entries += p->row_entries;
  }
  s.edges = row_entries / 2;
  s.spread_deg = spread_stats.spread_deg;
  s.threshold_raised = spread_stats.threshold_raised;
  s.segments = join.segments;
  s.large_segments = join.large_segments;
  return s;
}

}  // namespace pointillist
