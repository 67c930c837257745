// Clipping never opens a hole: pixels that lost every fragment to sharp-feature clip planes,
// between covered pixels, take the colour and depth of the nearest of them.
#pragma once

#include <cstdint>
#include <span>

#include "pointillist/core/math.hpp"
#include "simd.hpp"

namespace pointillist::render_detail {

// Marks the lanes of `m` (pixels x0 + lane of row y) in `mask`, a row-major image `width` wide:
// where a rasterizer's clip test discarded a covered pixel.
inline void mark_lanes(std::uint8_t* mask, int width, Int4 m, int x0, int y) {
  for (int l = 0; l < kLanes; ++l) {
    if (m[l] && x0 + l < width) mask[static_cast<std::size_t>(y) * width + x0 + l] = 1;
  }
}

// The widest gap filled, in pixels.
inline constexpr int kMaxPinholeGap = 2;

// `clipped` marks the pixels (row-major, width × height) where a clip plane discarded a covered
// fragment; depth is +infinity where nothing was drawn. Each such empty pixel that lies in a
// gap of at most kMaxPinholeGap empty, clipped pixels between two covered ones (along a row, a
// column or a diagonal) takes the colour and depth of the covered pixel nearest to it (ties: the
// nearer depth, then the first direction). A wider gap, or one that reaches pixels no clip plane
// emptied (the silhouette, a hole in the samples), stays. Reads only the image as drawn, so the
// result does not depend on the order of the pixels. Returns the number of pixels filled.
std::uint64_t fill_clipped_pinholes(std::span<Rgb8> color, std::span<float> depth,
                                    std::span<const std::uint8_t> clipped, int width, int height);

}  // namespace pointillist::render_detail
