// The software occlusion queries: a max-depth pyramid over the frame's depth buffer, the
// conservative test of a bounding sphere against it, the render queue and the emulated latency
// (see occlusion.hpp); and CHC++'s cost model for grouping multiqueries.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "pointillist/render/occlusion.hpp"

namespace pointillist {

namespace {
using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}
}  // namespace

void DepthPyramid::reset(std::span<const float> depth, int width, int height) {
  depth_ = depth;
  width_ = width;
  height_ = height;
  level_.clear();
  int w = width, h = height;
  while (w > 1 || h > 1) {
    w = (w + 1) / 2;
    h = (h + 1) / 2;
    level_.push_back({w, h, std::vector<float>(static_cast<std::size_t>(w) * h)});
  }
  refresh(0, 0, width, height);
}

float DepthPyramid::at(int level, int x, int y) const {
  if (level == 0) return depth_[static_cast<std::size_t>(y) * width_ + x];
  const Level& l = level_[static_cast<std::size_t>(level - 1)];
  return l.max[static_cast<std::size_t>(y) * l.width + x];
}

void DepthPyramid::refresh(int x0, int y0, int x1, int y1) {
  x0 = std::max(x0, 0);
  y0 = std::max(y0, 0);
  x1 = std::min(x1, width_);
  y1 = std::min(y1, height_);
  int below_w = width_, below_h = height_;
  for (std::size_t k = 0; k < level_.size() && x0 < x1 && y0 < y1; ++k) {
    x0 >>= 1;
    y0 >>= 1;
    x1 = (x1 + 1) >> 1;
    y1 = (y1 + 1) >> 1;
    Level& l = level_[k];
    const int level = static_cast<int>(k);  // the level below
    for (int y = y0; y < y1; ++y) {
      const int ya = 2 * y, yb = std::min(2 * y + 1, below_h - 1);
      for (int x = x0; x < x1; ++x) {
        const int xa = 2 * x, xb = std::min(2 * x + 1, below_w - 1);
        l.max[static_cast<std::size_t>(y) * l.width + x] =
            std::max(std::max(at(level, xa, ya), at(level, xb, ya)),
                     std::max(at(level, xa, yb), at(level, xb, yb)));
      }
    }
    below_w = l.width;
    below_h = l.height;
  }
}

bool DepthPyramid::descend(int level, int tx, int ty, int x0, int y0, int x1, int y1,
                           float z_min, std::uint64_t& tested) const {
  ++tested;
  if (z_min > at(level, tx, ty)) return false;  // everything there is strictly nearer
  if (level == 0) return true;
  const int below = level - 1;
  const Level* l = below == 0 ? nullptr : &level_[static_cast<std::size_t>(below - 1)];
  const int bw = l ? l->width : width_, bh = l ? l->height : height_;
  for (int cy = 2 * ty; cy <= std::min(2 * ty + 1, bh - 1); ++cy) {
    if ((((cy + 1) << below) - 1) < y0 || (cy << below) > y1) continue;
    for (int cx = 2 * tx; cx <= std::min(2 * tx + 1, bw - 1); ++cx) {
      if ((((cx + 1) << below) - 1) < x0 || (cx << below) > x1) continue;
      if (descend(below, cx, cy, x0, y0, x1, y1, z_min, tested)) return true;
    }
  }
  return false;
}

bool DepthPyramid::any_at_or_behind(int x0, int y0, int x1, int y1, float z_min,
                                    std::uint64_t& tested) const {
  x0 = std::max(x0, 0);
  y0 = std::max(y0, 0);
  x1 = std::min(x1, width_ - 1);
  y1 = std::min(y1, height_ - 1);
  if (x0 > x1 || y0 > y1) return false;
  // Start at the finest level where the rectangle spans at most two tiles each way.
  int level = 0;
  while (level < levels() - 1 && ((x1 >> level) - (x0 >> level) > 1 ||
                                  (y1 >> level) - (y0 >> level) > 1)) {
    ++level;
  }
  for (int ty = y0 >> level; ty <= y1 >> level; ++ty) {
    for (int tx = x0 >> level; tx <= x1 >> level; ++tx) {
      if (descend(level, tx, ty, x0, y0, x1, y1, z_min, tested)) return true;
    }
  }
  return false;
}

bool bound_may_be_visible(const DepthPyramid& pyramid, const CameraFrame& camera,
                          const QueryBound& bound, const QueryFootprint& footprint,
                          std::uint64_t& tested) {
  // In double: the bound must hold for the splats' float projections, which are within a few
  // ulps of the exact ones; the one-pixel margin below covers those.
  const Vec3f d = bound.center - camera.eye;
  const double cx = dot(d, camera.right), cy = dot(d, camera.up), cz = dot(d, camera.forward);
  const double r = bound.radius;
  const double z_min = cz - r * std::max(1.0f, footprint.depth_scale);
  // Splats are drawn at their centre's depth, and a splat of the node has its centre in the
  // sphere; the drawn disc lies within the sphere grown by the splat scale.
  const double rf = r * std::max(1.0f, footprint.footprint_scale) * (1.0 + 1e-6);
  if (!(z_min > 0) || !(cz - rf > 1e-9 * std::max(1.0, cz))) return true;
  // Tangent slopes of the sphere in the x–z and y–z planes (screen x = w/2 + f·t).
  const double den = cz * cz - rf * rf;
  const double f = camera.focal_px;
  const auto range = [&](double c, double& lo, double& hi) {
    if (camera.ortho) {  // parallel rays: the sphere's shadow on the image is c ± r
      lo = c - rf;
      hi = c + rf;
      return;
    }
    const double s = rf * std::sqrt(std::max(0.0, c * c + den));
    lo = (c * cz - s) / den;
    hi = (c * cz + s) / den;
  };
  double tx0, tx1, ty0, ty1;
  range(cx, tx0, tx1);
  range(cy, ty0, ty1);
  const double half_w = 0.5 * camera.width, half_h = 0.5 * camera.height;
  const double limit = 4.0 * (camera.width + camera.height);
  const auto clamp_px = [&](double v) { return std::clamp(v, -limit, limit); };
  // A splat covers pixel centres within its disc, or the pixel holding its centre: pixels
  // floor(x_lo) − 1 .. floor(x_hi) + 1 hold all of them with a pixel to spare.
  const double pad = std::max(0.0f, footprint.pad_px);
  const int x0 = static_cast<int>(std::floor(clamp_px(half_w + f * tx0 - pad))) - 1;
  const int x1 = static_cast<int>(std::floor(clamp_px(half_w + f * tx1 + pad))) + 1;
  const int y0 = static_cast<int>(std::floor(clamp_px(half_h - f * ty1 - pad))) - 1;
  const int y1 = static_cast<int>(std::floor(clamp_px(half_h - f * ty0 + pad))) + 1;
  // A splat's depth is a float computed in model space and scaled into the world: allow it a
  // relative error of 1e-5 below the exact nearest depth.
  const float z = static_cast<float>(z_min - 1e-5 * (cz + r));
  return pyramid.any_at_or_behind(x0, y0, x1, y1, z, tested);
}

SoftwareQueries::SoftwareQueries(DepthPyramid& pyramid, const CameraFrame& camera,
                                 QueryFootprint footprint, unsigned latency, Draw draw,
                                 OcclusionStats& stats)
    : pyramid_(pyramid), camera_(camera), footprint_(footprint), latency_(latency),
      draw_(std::move(draw)), stats_(stats) {}

void SoftwareQueries::draw_queue(bool last) {
  if (queue_.empty()) return;
  const Rect r = draw_(queue_, last);
  queue_.clear();
  ++stats_.flushes;
  if (last) return;
  const auto start = Clock::now();
  pyramid_.refresh(r.x0, r.y0, r.x1, r.y1);
  stats_.ms_hiz += ms_since(start);
}

void SoftwareQueries::flush() {
  draw_queue();
  ++flushes_;
}

void SoftwareQueries::finish() {
  draw_queue(true);
  ++flushes_;
}

QueryId SoftwareQueries::issue(std::span<const QueryBound> bounds) {
  if (!queue_.empty()) flush();  // R3: what was queued is drawn before the query
  const auto start = Clock::now();
  bool visible = false;
  for (const QueryBound& b : bounds) {
    if (bound_may_be_visible(pyramid_, camera_, b, footprint_, stats_.tiles_tested)) {
      visible = true;
      break;
    }
  }
  stats_.ms_query += ms_since(start);
  answers_.push_back({flushes_ + latency_, visible ? 1u : 0u});
  return static_cast<QueryId>(answers_.size() - 1);
}

bool SoftwareQueries::poll(QueryId id) const { return flushes_ >= answers_[id].available_at; }

std::uint32_t SoftwareQueries::result(QueryId id) {
  if (!poll(id)) {
    ++stats_.stalls;
    while (!poll(id)) flush();
  }
  return answers_[id].visible;
}

double keep_probability(std::uint64_t frames_invisible) {
  return 0.99 - 0.7 * std::exp(-static_cast<double>(frames_invisible));
}

namespace {

double failure_probability(std::span<const double> keep) {
  double product = 1.0;
  for (const double p : keep) product *= p;
  return 1.0 - product;
}

// Expected queries after the first of a group under its best plan (each query is made only when
// its parent group failed, so the terms add up without conditioning): re-query each node, or
// query both halves and plan each of them alike.
double extra_queries(std::span<const double> keep) {
  if (keep.size() < 2) return 0.0;
  const double fail = failure_probability(keep);
  const std::size_t half = (keep.size() + 1) / 2;
  const double each = fail * static_cast<double>(keep.size());
  const double halves =
      2.0 * fail + extra_queries(keep.first(half)) + extra_queries(keep.subspan(half));
  return std::min(each, halves);
}

}  // namespace

double split_query_cost(std::span<const double> keep) { return 1.0 + extra_queries(keep); }

bool split_failed_group(std::span<const double> keep) {
  if (keep.size() < 3) return false;  // two singles either way
  const std::size_t half = (keep.size() + 1) / 2;
  return 2.0 + (extra_queries(keep.first(half)) + extra_queries(keep.subspan(half))) /
                   failure_probability(keep) <
         static_cast<double>(keep.size());
}

std::vector<std::size_t> multiquery_groups(std::span<const double> keep, bool split) {
  std::vector<std::size_t> groups;
  std::size_t start = 0;
  while (start < keep.size()) {
    std::size_t m = 1;
    if (split) {
      double best = 1.0;  // V of one node
      for (std::size_t size = 2; start + size <= keep.size(); ++size) {
        const double v = static_cast<double>(size) / split_query_cost(keep.subspan(start, size));
        if (v >= best) best = v, m = size;
      }
    } else {
      double product = keep[start];
      const auto value = [](double size, double p) { return size / (1.0 + (1.0 - p) * size); };
      double best = value(1.0, product);
      while (start + m < keep.size()) {
        const double p = product * keep[start + m];
        const double v = value(static_cast<double>(m + 1), p);
        if (v < best) break;
        best = v;
        product = p;
        ++m;
      }
    }
    groups.push_back(m);
    start += m;
  }
  return groups;
}

}  // namespace pointillist
