#include "raster/clip_pinholes.hpp"

#include <cmath>
#include <limits>
#include <vector>

namespace pointillist::render_detail {

std::uint64_t fill_clipped_pinholes(std::span<Rgb8> color, std::span<float> depth,
                                    std::span<const std::uint8_t> clipped, int width,
                                    int height) {
  const auto at = [&](int x, int y) { return static_cast<std::size_t>(y) * width + x; };
  const auto inside = [&](int x, int y) { return x >= 0 && y >= 0 && x < width && y < height; };
  const auto covered = [&](int x, int y) { return std::isfinite(depth[at(x, y)]); };
  const auto gap = [&](int x, int y) { return !covered(x, y) && clipped[at(x, y)] != 0; };
  struct Fill {
    std::size_t to, from;
  };
  std::vector<Fill> fills;
  constexpr int kDirections[4][2] = {{1, 0}, {0, 1}, {1, 1}, {1, -1}};
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      if (!gap(x, y)) continue;
      std::size_t best = 0;
      int best_steps = kMaxPinholeGap + 1;
      float best_depth = std::numeric_limits<float>::infinity();
      for (const auto& d : kDirections) {
        // The first covered pixel each way, through clipped gap pixels only.
        int steps[2] = {0, 0};
        for (int side = 0; side < 2; ++side) {
          const int sx = side ? -d[0] : d[0], sy = side ? -d[1] : d[1];
          for (int k = 1; k <= kMaxPinholeGap; ++k) {
            const int px = x + k * sx, py = y + k * sy;
            if (!inside(px, py)) break;
            if (covered(px, py)) {
              steps[side] = k;
              break;
            }
            if (!gap(px, py)) break;
          }
        }
        if (steps[0] == 0 || steps[1] == 0 || steps[0] + steps[1] - 1 > kMaxPinholeGap) continue;
        for (int side = 0; side < 2; ++side) {
          const int k = steps[side];
          const std::size_t from = side ? at(x - k * d[0], y - k * d[1]) : at(x + k * d[0], y + k * d[1]);
          if (k < best_steps || (k == best_steps && depth[from] < best_depth)) {
            best = from;
            best_steps = k;
            best_depth = depth[from];
          }
        }
      }
      if (best_steps <= kMaxPinholeGap) fills.push_back({at(x, y), best});
    }
  }
  for (const Fill& f : fills) {
    color[f.to] = color[f.from];
    depth[f.to] = depth[f.from];
  }
  return fills.size();
}

}  // namespace pointillist::render_detail
