#include "pointillist/render/eye_dome.hpp"

#include <cmath>
#include <string>

#include "pointillist/core/error.hpp"

namespace pointillist {

void apply_eye_dome_lighting(Frame& frame, float strength, ThreadPool& pool) {
  if (!(strength >= 0.0f) || !std::isfinite(strength)) {
    throw OptionError("eye-dome lighting strength " + std::to_string(strength) +
                      " is invalid; give a number >= 0 (1 is the usual strength)");
  }
  if (strength == 0.0f || frame.width <= 0 || frame.height <= 0) return;
  const int w = frame.width, h = frame.height;
  const std::size_t n = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  // log2 of every pixel's depth (NaN where nothing is drawn: every comparison with it is false).
  Buffer<float>& log_depth = frame.scratch.log_depth;
  log_depth.resize(n);
  const float* depth = frame.depth.data();
  float* ld = log_depth.data();
  parallel_for(pool, static_cast<std::size_t>(h), 16, [&](std::size_t y0, std::size_t y1) {
    for (std::size_t i = y0 * w; i < y1 * w; ++i) {
      const float d = depth[i];
      ld[i] = std::isfinite(d) && d > 0.0f ? std::log2(d) : std::nanf("");
    }
  });
  const float k = -300.0f * strength / 8.0f;
  Rgb8* color = frame.color.data();
  parallel_for(pool, static_cast<std::size_t>(h), 16, [&](std::size_t y0, std::size_t y1) {
    for (int y = static_cast<int>(y0); y < static_cast<int>(y1); ++y) {
      for (int x = 0; x < w; ++x) {
        const std::size_t i = static_cast<std::size_t>(y) * w + x;
        const float d = ld[i];
        if (std::isnan(d)) continue;
        float sum = 0.0f;
        for (int dy = -1; dy <= 1; ++dy) {
          const int ny = y + dy;
          if (ny < 0 || ny >= h) continue;
          for (int dx = -1; dx <= 1; ++dx) {
            const int nx = x + dx;
            if ((dx == 0 && dy == 0) || nx < 0 || nx >= w) continue;
            const float dn = ld[static_cast<std::size_t>(ny) * w + nx];
            if (d > dn) sum += d - dn;  // false for an undrawn (NaN) neighbour
          }
        }
        if (sum <= 0.0f) continue;
        const float shade = std::exp(k * sum);
        Rgb8& c = color[i];
        c = {static_cast<std::uint8_t>(float(c.r) * shade + 0.5f),
             static_cast<std::uint8_t>(float(c.g) * shade + 0.5f),
             static_cast<std::uint8_t>(float(c.b) * shade + 0.5f)};
      }
    }
  });
}

}  // namespace pointillist
