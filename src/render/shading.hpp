// The shading model of RenderSettings (see render/settings.hpp), shared by the splat rasterizer
// and the reference triangle rasterizer so that both give the same color for the same surface.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "pointillist/core/camera.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/core/math.hpp"
#include "pointillist/core/normal_color.hpp"
#include "pointillist/render/settings.hpp"
#include "simd.hpp"

namespace pointillist::render_detail {


// round(255·c) for c clamped to [0, 1]; NaN gives 0. (std::max(0, c) is maxss: no branch.)
inline std::uint8_t to_unorm8(float c) {
  return static_cast<std::uint8_t>(std::min(1.0f, std::max(0.0f, c)) * 255.0f + 0.5f);
}

// The model of RenderSettings, evaluated in world space: light_dir_eye is turned into a world
// direction once, so callers pass world-space normals and view vectors.
class Shader {
 public:
  static constexpr int kTableIntervals = 1024;

  // Throws OptionError for a zero or non-finite light direction or an invalid shininess.
  Shader(const RenderSettings& s, const CameraFrame& cam) {
    const float len = length(s.light_dir_eye);
    if (!(len > 0.0f) || !std::isfinite(len)) {
      throw OptionError("light direction (" + std::to_string(s.light_dir_eye.x) + ", " +
                        std::to_string(s.light_dir_eye.y) + ", " +
                        std::to_string(s.light_dir_eye.z) +
                        ") is zero or not finite; give a direction toward the light in eye space");
    }
    if (!(s.shininess >= 0.0f) || !std::isfinite(s.shininess)) {
      throw OptionError("shininess " + std::to_string(s.shininess) +
                        " is invalid; give a finite exponent >= 0");
    }
    const Vec3f l = s.light_dir_eye / len;
    light_ = normalized(cam.right * l.x + cam.up * l.y - cam.forward * l.z);
    ambient_ = s.ambient;
    diffuse_ = s.diffuse;
    specular_ = s.specular;
    base_ = s.base_color;
    two_sided_ = s.two_sided;
    normal_colors_ = s.normal_colors;
    right_ = cam.right;
    up_ = cam.up;
    back_ = -cam.forward;
    table_ = power_table(s.shininess);
    power_ = table_->data();
  }

  Vec3f base_color() const { return base_; }

  // t^shininess for t in [0, 1] (linear interpolation in the table).
  float power(float t) const {
    t = std::min(1.0f, std::max(0.0f, t));
    const float u = t * kTableIntervals;
    const int i = static_cast<int>(u);
    const float f = u - static_cast<float>(i);
    return power_[i] + (power_[i + 1] - power_[i]) * f;
  }

  // n: unit normal, v: unit vector to the eye, both in world space; base: linear 0..1.
  Rgb8 shade(Vec3f n, Vec3f v, Vec3f base) const {
    if (two_sided_ && dot(n, v) < 0.0f) n = -n;  // seen from behind: lit as its front
    if (normal_colors_) {
      return encode_normal_color({dot(n, right_), dot(n, up_), dot(n, back_)});
    }
    const float ndl = dot(n, light_);
    const float k = ambient_ + diffuse_ * std::max(0.0f, ndl);
    // h is zero only when the light is exactly behind the surface (then n·l ≤ 0: no highlight);
    // the max keeps the division finite there.
    const Vec3f h = light_ + v;
    const float ndh = dot(n, h) / std::sqrt(std::max(dot(h, h), 1e-30f));
    const float spec = ndl > 0.0f ? specular_ * power(ndh) : 0.0f;
    return {to_unorm8(base.x * k + spec), to_unorm8(base.y * k + spec),
            to_unorm8(base.z * k + spec)};
  }

  // shade() for four surfaces at once (components of n, v and base as lanes). Writes
  // round(255·c) per channel into r, g, b.
  void shade4(const Float4 n_in[3], const Float4 v[3], const Float4 base[3], Int4 out[3]) const {
    const Float4 zero = splat4(0.0f), one = splat4(1.0f);
    Float4 n[3] = {n_in[0], n_in[1], n_in[2]};
    if (two_sided_) {  // seen from behind: lit as its front
      const Float4 ndv = n[0] * v[0] + n[1] * v[1] + n[2] * v[2];
      const Float4 sign = select4(ndv < zero, splat4(-1.0f), one);
      for (Float4& c : n) c = c * sign;
    }
    if (normal_colors_) {  // encode_normal_color of the eye-space normal, lane by lane
      const Vec3f axes[3] = {right_, up_, back_};
      for (int c = 0; c < 3; ++c) {
        const Float4 e = n[0] * axes[c].x + n[1] * axes[c].y + n[2] * axes[c].z;
        out[c] = to_int4(min4(one, max4(zero, 0.5f * e + 0.5f)) * 255.0f + 0.5f);
      }
      return;
    }
    const Float4 ndl = n[0] * light_.x + n[1] * light_.y + n[2] * light_.z;
    const Float4 k = ambient_ + diffuse_ * max4(zero, ndl);
    const Float4 hx = v[0] + light_.x, hy = v[1] + light_.y, hz = v[2] + light_.z;
    const Float4 hh = max4(splat4(1e-30f), hx * hx + hy * hy + hz * hz);
    const Float4 ndh = (n[0] * hx + n[1] * hy + n[2] * hz) / sqrt4(hh);
    // The power table, lane by lane (as power()).
    const Float4 u = min4(one, max4(zero, ndh)) * static_cast<float>(kTableIntervals);
    const Int4 i = to_int4(u);
    const Float4 f = u - to_float4(i);
    const Float4 p0{power_[i[0]], power_[i[1]], power_[i[2]], power_[i[3]]};
    const Float4 p1{power_[i[0] + 1], power_[i[1] + 1], power_[i[2] + 1], power_[i[3] + 1]};
    const Float4 spec = select4(ndl > zero, specular_ * (p0 + (p1 - p0) * f), zero);
    for (int c = 0; c < 3; ++c) {
      out[c] = to_int4(min4(one, max4(zero, base[c] * k + spec)) * 255.0f + 0.5f);
    }
  }

 private:
  Vec3f light_, base_;
  Vec3f right_, up_, back_;  // the eye's axes in world space (normal colours)
  bool normal_colors_ = false;
  float ambient_ = 0, diffuse_ = 0, specular_ = 0;
  bool two_sided_ = false;
  using PowerTable = std::array<float, kTableIntervals + 2>;
  // t^shininess at the table's points, computed once per shininess (a scene of thousands of
  // instances makes a Shader per instance and frame).
  static std::shared_ptr<const PowerTable> power_table(float shininess) {
    static std::mutex mutex;
    static std::map<float, std::shared_ptr<const PowerTable>> tables;
    std::lock_guard lock(mutex);
    std::shared_ptr<const PowerTable>& slot = tables[shininess];
    if (!slot) {
      auto t = std::make_shared<PowerTable>();
      for (int i = 0; i <= kTableIntervals; ++i) {
        const float p = std::pow(static_cast<float>(i) / kTableIntervals, shininess);
        (*t)[i] = p < 1e-30f ? 0.0f : p;  // no denormals in the interpolation
      }
      (*t)[kTableIntervals + 1] = 1.0f;  // interpolation guard
      slot = std::move(t);
    }
    return slot;
  }
  std::shared_ptr<const PowerTable> table_;
  const float* power_ = nullptr;
};

}  // namespace pointillist::render_detail
