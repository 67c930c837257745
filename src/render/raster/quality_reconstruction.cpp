// Per-pixel reconstruction of surfaces from splat fragments: which fragments belong to the front
// surface (Z-threshold: Zwicker, Pfister, van Baar, Gross, "Surface Splatting", SIGGRAPH 2001;
// Z-range: Räsänen, "Surface Splatting: Theory, Extensions and Implementation", MSc thesis,
// Helsinki University of Technology, 2002), then the normalised weighted mean of their
// attributes. Written for clarity; the rasterizer applies the same rule band by band.
#include <cmath>
#include <limits>
#include <string>

#include "pointillist/core/error.hpp"
#include "pointillist/render/quality.hpp"
#include "raster/quality_kernel.hpp"

namespace pointillist {
namespace {

void check_range(const char* field, float value, float lo, float hi, const char* why) {
  if (!(value >= lo && value <= hi)) {
    throw OptionError(std::string("quality setting ") + field + " = " + std::to_string(value) +
                      " is out of range; give a value in [" + std::to_string(lo) + ", " +
                      std::to_string(hi) + "] (" + why + ")");
  }
}

}  // namespace

void validate_quality_settings(const QualitySettings& q) {
  if (q.reconstruction != Reconstruction::ZThreshold && q.reconstruction != Reconstruction::ZRange) {
    throw OptionError("quality setting reconstruction = " +
                      std::to_string(static_cast<int>(q.reconstruction)) +
                      " is not a Reconstruction; use ZThreshold or ZRange");
  }
  if (!(q.z_threshold > 0.0f) || !std::isfinite(q.z_threshold)) {
    throw OptionError("quality setting z_threshold = " + std::to_string(q.z_threshold) +
                      " is invalid; give a positive number of splat radii (1 is the default)");
  }
  check_range("z_range_margin", q.z_range_margin, 0.0f, 1e6f, "splat radii, 0.5 is the default");
  check_range("radius_scale", q.radius_scale, 1.0f, 2.0f, "disc radius / node radius, 1.1 is the default");
  check_range("kernel_sigma", q.kernel_sigma, 0.1f, 4.0f, "splat radii, 0.5 is the default");
  check_range("lowpass_radius_px", q.lowpass_radius_px, 0.5f, 16.0f,
              "pixels, 0.75 is the default");
  if (!(q.opacity > 0.0f && q.opacity <= 1.0f)) {
    throw OptionError("quality setting opacity = " + std::to_string(q.opacity) +
                      " is out of range; give a value in (0, 1] (1 = opaque)");
  }
  if (q.max_layers < 1 || q.max_layers > 16) {
    throw OptionError("quality setting max_layers = " + std::to_string(q.max_layers) +
                      " is out of range; give 1 to 16 surfaces per pixel");
  }
}

std::vector<ReconstructedSurface> reconstruct_pixel(std::span<const Fragment> fragments,
                                                    const QualitySettings& quality,
                                                    int max_surfaces) {
  validate_quality_settings(quality);
  const quality_detail::RuleConstants rule = quality_detail::rule_constants(quality);
  std::vector<ReconstructedSurface> out;
  // Surfaces peel off front to back: surface k takes the fragments with lower < key <= B_k,
  // B_k being the smallest bound among the fragments with key > lower (the previous B).
  float lower = -std::numeric_limits<float>::infinity();
  while (static_cast<int>(out.size()) < max_surfaces) {
    float bound = std::numeric_limits<float>::infinity();
    bool any = false;
    for (const Fragment& f : fragments) {
      const float key = quality_detail::fragment_key(rule, f.depth, f.depth_min, f.radius);
      if (key > lower) {
        bound = std::min(bound, quality_detail::fragment_bound(rule, f.depth, f.depth_max, f.radius));
        any = true;
      }
    }
    if (!any) break;
    ReconstructedSurface s;
    float sum_depth = 0;
    Vec3f sum_color, sum_normal, front_normal;
    float front_key = std::numeric_limits<float>::infinity();
    for (const Fragment& f : fragments) {
      const float key = quality_detail::fragment_key(rule, f.depth, f.depth_min, f.radius);
      if (!(key > lower && key <= bound)) continue;
      s.weight += f.weight;
      sum_depth += f.weight * f.depth;
      sum_color += f.base_color * f.weight;
      sum_normal += f.normal * f.weight;
      ++s.fragment_count;
      if (key < front_key) {
        front_key = key;
        s.front_node = f.node;
        front_normal = f.normal;
      }
    }
    if (s.fragment_count == 0) break;  // only when bounds are NaN
    s.depth = sum_depth / s.weight;
    s.base_color = sum_color / s.weight;
    s.normal = normalized(sum_normal, front_normal);
    out.push_back(s);
    lower = bound;
  }
  return out;
}

}  // namespace pointillist
