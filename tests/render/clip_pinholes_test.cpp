// The fill of pixels that clipping emptied: only narrow gaps between covered pixels, only where
// a clip plane discarded something, each from its nearest covered pixel.
#include "raster/clip_pinholes.hpp"

#include <gtest/gtest.h>

#include <limits>
#include <string>
#include <vector>

using namespace pointillist;
using render_detail::fill_clipped_pinholes;

namespace {

constexpr float kEmpty = std::numeric_limits<float>::infinity();

// An image from rows of characters: '.' empty, 'x' empty and clipped, a digit d covered with
// depth d and colour (10·d, 0, 0).
struct Picture {
  int width = 0, height = 0;
  std::vector<Rgb8> color;
  std::vector<float> depth;
  std::vector<std::uint8_t> clipped;
  explicit Picture(const std::vector<std::string>& rows) {
    height = static_cast<int>(rows.size());
    width = static_cast<int>(rows[0].size());
    for (const std::string& r : rows) {
      for (char c : r) {
        const bool on = c >= '0' && c <= '9';
        depth.push_back(on ? float(c - '0') : kEmpty);
        color.push_back(on ? Rgb8{std::uint8_t(10 * (c - '0')), 0, 0} : Rgb8{0, 0, 0});
        clipped.push_back(c == 'x');
      }
    }
  }
  std::uint64_t fill() { return fill_clipped_pinholes(color, depth, clipped, width, height); }
  float depth_at(int x, int y) const { return depth[std::size_t(y) * width + x]; }
};

TEST(ClipPinholes, OneAndTwoPixelGapsBetweenCoveredPixelsAreFilledFromTheNearest) {
  Picture p({"3x5..", "3xx5.", "3xxx5"});
  EXPECT_EQ(p.fill(), 3u);
  EXPECT_EQ(p.depth_at(1, 0), 3.0f);  // one pixel: both sides 1 away, the nearer depth
  EXPECT_EQ(p.depth_at(1, 1), 3.0f);  // two pixels: each from its own side
  EXPECT_EQ(p.depth_at(2, 1), 5.0f);
  EXPECT_EQ(p.color[std::size_t(1) * 5 + 2], (Rgb8{50, 0, 0}));
  for (int x = 1; x <= 3; ++x) EXPECT_EQ(p.depth_at(x, 2), kEmpty);  // three: too wide
}

TEST(ClipPinholes, OnlyPixelsThatClippingEmptiedAndOnlyBetweenTwoSides) {
  // A gap no clip plane made ('.'), a clipped pixel on the silhouette (covered on one side
  // only) and a gap that reaches an unclipped empty pixel all stay empty.
  Picture p({"3..5", "3x..", "3x.5"});
  EXPECT_EQ(p.fill(), 0u);
}

TEST(ClipPinholes, FilledPixelsDoNotFeedEachOther) {
  // (1, 0) is bracketed only through (1, 1), itself empty: it stays. (1, 1) lies between 1 and
  // 2 on its row: the nearer depth. (2, 2) between 4 and 7. (3, 3) has 7 above and nothing
  // below: it stays.
  Picture p({"4x...", "1x2..", ".4x7.", "...x."});
  EXPECT_EQ(p.fill(), 2u);
  EXPECT_EQ(p.depth_at(1, 0), kEmpty);
  EXPECT_EQ(p.depth_at(1, 1), 1.0f);
  EXPECT_EQ(p.depth_at(2, 2), 4.0f);
  EXPECT_EQ(p.depth_at(3, 3), kEmpty);
}

TEST(ClipPinholes, DiagonalsBracketToo) {
  // A pixel whose only covered neighbours are on a diagonal, one each side.
  Picture p({"..6", ".x.", "2.."});
  EXPECT_EQ(p.fill(), 1u);
  EXPECT_EQ(p.depth_at(1, 1), 2.0f);
}

}  // namespace
