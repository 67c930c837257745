// Z-buffered splat rasterizer (square, circle and normal-oriented ellipse kernels, as in the
// software and OpenGL drivers of QSplat: Rusinkiewicz & Levoy, SIGGRAPH 2000, section 4.1).
//
// Deterministic in parallel: the image is split into horizontal bands; every band draws all the
// splats that touch it with a depth test on (depth, colour): equal depths go to the smaller
// packed colour, so what a pixel shows is the minimum over the splats covering it and depends
// neither on the band layout and thread count nor on the order of the stream.
#include "pointillist/render/splat_raster.hpp"

#include <algorithm>
#include <cstdint>
#include <atomic>
#include <cassert>
#include <cmath>
#include <limits>

#include <type_traits>

#include "raster/clip_lanes.hpp"
#include "raster/clip_pinholes.hpp"
#include "raster/unpack_rgb.hpp"
#include "raster/splat_ellipse.hpp"
#include "simd.hpp"

namespace pointillist {
namespace {

constexpr int kBandsPerThread = 3;
constexpr int kBandPixels = 1 << 17;
// A disc of radius ≥ √½ px, or a square of half side ≥ ½ px, always holds a pixel centre.
constexpr float kDiscAlwaysCovers = 0.70711f;
constexpr float kSquareAlwaysCovers = 0.5f;

// Four pixels of a row at once.
using render_detail::Float4;
using render_detail::Int4;
using render_detail::kLanes;
using render_detail::load4;
using render_detail::select4;
using render_detail::splat4;
using render_detail::store4;
using render_detail::kEllipseStride;
using render_detail::prepare_ellipses;

using render_detail::pack_rgb;

// One band of the image: depths in the output buffer (full image, rows top to bottom) and packed
// colors (0x00BBGGRR) in a band-sized buffer whose first row is the band's first row.
struct Target {
  std::uint32_t* color;
  float* depth;
  int width, height;
  int row_begin, row_end;
  float width_f, height_f;
  std::uint64_t* clipped;  // the worker's count of covered pixels discarded by clip planes
  std::uint8_t* clip_mask;  // the image's pixels where they did (row-major), or null
};

// v clamped to [lo, hi]; NaN gives lo. Keeps coordinates of splats next to the eye (huge or
// infinite) in the range where float-to-int conversion is defined.
inline float clampf(float v, float lo, float hi) { return std::min(hi, std::max(lo, v)); }
// floor and ceil for |v| < 2^31 (cheaper than the SSE2 sequences of std::floor/std::ceil).
inline int floor_int(float v) {
  const int t = static_cast<int>(v);
  return t - (v < static_cast<float>(t));
}
inline int ceil_int(float v) {
  const int t = static_cast<int>(v);
  return t + (v > static_cast<float>(t));
}

// The depth test: nearer wins; at equal depth the smaller packed colour (colours are below 2^24,
// so signed and unsigned order agree).
inline void plot(const Target& t, int i, int j, float z, std::uint32_t c) {
  if (i < 0 || i >= t.width || j < t.row_begin || j >= t.row_end) return;
  const std::size_t w = static_cast<std::size_t>(t.width);
  const std::size_t p = static_cast<std::size_t>(j) * w + i;
  std::uint32_t& old = t.color[static_cast<std::size_t>(j - t.row_begin) * w + i];
  if (z < t.depth[p] || (z == t.depth[p] && c < old)) {
    t.depth[p] = z;
    old = c;
  }
}

// No clip test: every covered pixel is drawn.
struct NoClip {
  Int4 operator()(Float4, float) const { return Int4{}; }
  void tally(Int4, int, int) const {}
};


// The clip test of a splat with sharp-feature planes (clip_lanes.hpp), per pixel: the pixel's
// ray meets the splat's plane at P (the centre where it misses); one plane test per plane.
struct PixelClip {
  float cx, cy, cz, nx, ny, nz, nc;  // centre and normal, eye coordinates; n·c
  float half_w, half_h, inv_f;
  bool ortho;  // parallel rays along +z from (a, b, 0)
  const float* planes;
  std::uint32_t count;
  ClipMode mode;
  std::uint64_t* discarded;  // the band's count of covered pixels discarded
  std::uint8_t* mask;        // the image's pixels where they were, or null
  int width;
  // Adds the lanes of `m` (covered pixels this test discarded: pixels x0 + lane of row y) to
  // the count, and marks them.
  void tally(Int4 m, int x0, int y) const {
    *discarded += render_detail::lane_count(m);
    if (mask != nullptr) render_detail::mark_lanes(mask, width, m, x0, y);
  }
  // Lanes of pixel centres (px, py) whose fragment is discarded.
  Int4 operator()(Float4 px, float py) const {
    const Float4 a = (px - half_w) * inv_f;
    const float b = (half_h - py) * inv_f;
    if (ortho) {  // the pixel's ray meets the splat's plane at depth (n·c − nx·a − ny·b) / nz
      const Float4 z = (nc - nx * a - ny * b) / nz;
      const Int4 valid = (z > splat4(0.0f)) & (z < splat4(std::numeric_limits<float>::infinity())) &
                         (z > splat4(-std::numeric_limits<float>::infinity()));
      return render_detail::clip_discard4(planes, count, mode, select4(valid, a, splat4(cx)),
                                          select4(valid, splat4(b), splat4(cy)),
                                          select4(valid, z, splat4(cz)));
    }
    const Float4 t = nc / (nx * a + (ny * b + nz));
    const Int4 valid = (t > splat4(0.0f)) & (t < splat4(std::numeric_limits<float>::infinity()));
    return render_detail::clip_discard4(planes, count, mode, select4(valid, t * a, splat4(cx)),
                                        select4(valid, t * b, splat4(cy)),
                                        select4(valid, t, splat4(cz)));
  }
};

// Pixels whose centre lies in [x − hx, x + hx] × [y − hy, y + hy], clipped to the band.
struct PixelBox {
  int i0, i1, j0, j1;
};
inline PixelBox pixel_box(const Target& t, float x, float y, float hx, float hy) {
  // ceil(x − hx − ½), floor(x + hx − ½), ceil(y − hy − ½), floor(y + hy − ½) of the clamped
  // values, all four at once: truncate, then step up (ceil lanes) or down (floor lanes).
  const Float4 v = render_detail::min4(
      Float4{t.width_f, t.width_f, t.height_f, t.height_f},
      render_detail::max4(splat4(-1.0f),
                          Float4{x - hx - 0.5f, x + hx - 0.5f, y - hy - 0.5f, y + hy - 0.5f}));
  const Int4 truncated = render_detail::to_int4(v);
  const Float4 back = render_detail::to_float4(truncated);
  const Int4 ceil_lanes{-1, 0, -1, 0};
  const Int4 r = truncated - ((v > back) & ceil_lanes) + ((v < back) & ~ceil_lanes);
  return {std::max(r[0], 0), std::min(r[1], t.width - 1), std::max(r[2], t.row_begin),
          std::min(r[3], t.row_end - 1)};
}

// The pixel holding (x, y) and the offset from (x, y) to its centre (the nearest centre).
struct NearestCentre {
  int i, j;
  float dx, dy;
};
inline NearestCentre nearest_centre(const Target& t, float x, float y) {
  const int i = floor_int(clampf(x, -1.0f, t.width_f + 1.0f));
  const int j = floor_int(clampf(y, -1.0f, t.height_f + 1.0f));
  return {i, j, static_cast<float>(i) + 0.5f - x, static_cast<float>(j) + 0.5f - y};
}

// Depth-tests and writes the pixels of box `b` that the shape covers. `inside(dx)` takes the
// x offsets from the splat centre to four pixel centres and returns a test of a row's y offset
// dy that gives the lanes inside the shape. Four pixels at a time, column group by column
// group (the x part of the test is computed once per group). Lanes outside the shape are
// written back unchanged; they are in the band's own rows, so no other thread touches them. The
// last group of a row is shifted left to stay in the image (pixels seen twice are unchanged the
// second time: the depth test is strict). Needs width ≥ 4.
template <class Inside, class Clip>
inline void fill_box(const Target& t, const PixelBox& b, float x, float y, float z,
                     std::uint32_t c, Inside inside, const Clip& clip) {
  const Float4 lane_centre{0.5f, 1.5f, 2.5f, 3.5f};
  const Float4 zv = splat4(z);
  const Int4 cv = Int4{} + static_cast<std::int32_t>(c);
  const std::size_t w = static_cast<std::size_t>(t.width);
  // When rows are a whole number of groups, groups start at multiples of four: every access is
  // then 16-byte aligned, and the next splat (usually a neighbour) reads exactly what this one
  // stored, which store-to-load forwarding handles (a partial overlap would stall).
  const int first = (t.width % kLanes == 0) ? (b.i0 & ~(kLanes - 1)) : b.i0;
  for (int i = first; i <= b.i1; i += kLanes) {
    const int s = std::min(i, t.width - kLanes);
    // (s + k + 0.5) is exact, so each lane rounds once, as nearest_centre does.
    const Float4 px = static_cast<float>(s) + lane_centre;
    const auto row_test = inside(px - x);
    // Lanes of pixels before i were seen by the previous group (the last group shifted left).
    [[maybe_unused]] const Int4 fresh = Int4{0, 1, 2, 3} + s >= i;
    float* depth = t.depth + static_cast<std::size_t>(b.j0) * w + s;
    std::uint32_t* color = t.color + static_cast<std::size_t>(b.j0 - t.row_begin) * w + s;
    float cy = static_cast<float>(b.j0) + 0.5f;
    for (int j = b.j0; j <= b.j1; ++j, cy += 1.0f, depth += w, color += w) {
      const Float4 old_depth = load4(depth);
      const Int4 old_color = load4(color);
      const Int4 cover = row_test(cy - y);
      Int4 m = cover & ((zv < old_depth) | ((zv == old_depth) & (cv < old_color)));
      if constexpr (!std::is_same_v<Clip, NoClip>) {
        const Int4 cut = cover & clip(px, cy);
        clip.tally(cut & fresh, s, j);
        m &= ~cut;
      }
      store4(depth, select4(m, zv, old_depth));
      store4(color, select4(m, cv, old_color));
    }
  }
}

// The same one pixel at a time, for images narrower than four pixels.
template <class Inside, class Clip>
inline void fill_box_narrow(const Target& t, const PixelBox& b, float x, float y, float z,
                            std::uint32_t c, Inside inside, const Clip& clip) {
  for (int j = b.j0; j <= b.j1; ++j) {
    const float dy = static_cast<float>(j) + 0.5f - y;
    for (int i = b.i0; i <= b.i1; ++i) {
      const float px = static_cast<float>(i) + 0.5f;
      if (!inside(splat4(px - x))(dy)[0]) continue;
      if (clip(splat4(px), dy + y)[0]) {
        clip.tally(Int4{-1, 0, 0, 0}, i, j);
        continue;
      }
      plot(t, i, j, z, c);
    }
  }
}

template <class Inside, class Clip>
inline void fill(const Target& t, const PixelBox& b, float x, float y, float z, std::uint32_t c,
                 Inside inside, const Clip& clip) {
  if (t.width >= kLanes) {
    fill_box(t, b, x, y, z, c, inside, clip);
  } else {
    fill_box_narrow(t, b, x, y, z, c, inside, clip);
  }
}

// The pixel holding a splat that covers no pixel centre, unless the clip test discards it.
template <class Clip>
inline void plot_nearest(const Target& t, const NearestCentre& n, float z, std::uint32_t c,
                         const Clip& clip) {
  if constexpr (!std::is_same_v<Clip, NoClip>) {
    if (clip(splat4(static_cast<float>(n.i) + 0.5f), static_cast<float>(n.j) + 0.5f)[0]) {
      clip.tally(Int4{-1, 0, 0, 0}, n.i, n.j);
      return;
    }
  }
  plot(t, n.i, n.j, z, c);
}

template <class Clip>
inline void draw_square(const Target& t, float x, float y, float z, float r,
                        std::uint32_t c, const Clip& clip) {
  if (r < kSquareAlwaysCovers) {
    const NearestCentre n = nearest_centre(t, x, y);
    if (!(std::abs(n.dx) <= r && std::abs(n.dy) <= r)) {
      plot_nearest(t, n, z, c, clip);
      return;
    }
  }
  const Float4 rv = splat4(r);
  // Rows are within the box already; columns are tested because of the shifted last group.
  fill(t, pixel_box(t, x, y, r, r), x, y, z, c, [&](Float4 dx) {
    const Int4 in_x = (dx <= rv) & (-dx <= rv);
    return [in_x](float) { return in_x; };
  }, clip);
}

template <class Clip>
inline void draw_circle(const Target& t, float x, float y, float z, float r,
                        std::uint32_t c, const Clip& clip) {
  const float r2 = r * r;
  if (r < kDiscAlwaysCovers) {
    const NearestCentre n = nearest_centre(t, x, y);
    if (!(n.dx * n.dx + n.dy * n.dy <= r2)) {
      plot_nearest(t, n, z, c, clip);
      return;
    }
  }
  const Float4 r2v = splat4(r2);
  fill(t, pixel_box(t, x, y, r, r), x, y, z, c, [&](Float4 dx) {
    const Float4 dx2 = dx * dx;
    return [dx2, r2v](float dy) { return dx2 + dy * dy <= r2v; };
  }, clip);
}

// Ellipse {d : A·dx² + 2B·dx·dy + C·dy² ≤ r²} (see ellipse_parameters).
template <class Clip>
inline void draw_ellipse(const Target& t, float x, float y, float z, float r,
                         const float* e, std::uint32_t c, const Clip& clip) {
  const float a = e[0], b2 = e[1], cc = e[2];
  const float hx = r * e[3], hy = r * e[4];
  const float r2 = r * r;
  if (r * e[5] < kDiscAlwaysCovers) {
    // Thin: may hold no pixel centre. The box is small here (r < 7.1 px as ratio ≥ 0.1).
    const NearestCentre n = nearest_centre(t, x, y);
    bool covers = false;
    const int i0 = ceil_int(clampf(x - hx - 0.5f, -2.0f, t.width_f + 1.0f));
    const int i1 = floor_int(clampf(x + hx - 0.5f, -2.0f, t.width_f + 1.0f));
    const int j0 = ceil_int(clampf(y - hy - 0.5f, -2.0f, t.height_f + 1.0f));
    const int j1 = floor_int(clampf(y + hy - 0.5f, -2.0f, t.height_f + 1.0f));
    for (int j = j0; j <= j1 && !covers; ++j) {
      for (int i = i0; i <= i1 && !covers; ++i) {
        const float dx = static_cast<float>(i) + 0.5f - x, dy = static_cast<float>(j) + 0.5f - y;
        covers = a * dx * dx + b2 * dx * dy + cc * dy * dy <= r2;  // as in the lanes below
      }
    }
    if (!covers) {
      plot_nearest(t, n, z, c, clip);
      return;
    }
  }
  const Float4 av = splat4(a), r2v = splat4(r2);
  fill(t, pixel_box(t, x, y, hx, hy), x, y, z, c, [&](Float4 dx) {
    const Float4 adx2 = av * dx * dx, b2dx = b2 * dx;
    return [=](float dy) { return adx2 + b2dx * dy + cc * dy * dy <= r2v; };
  }, clip);
}

struct BandLayout {
  int count = 1;
  int rows_log2 = 0;  // rows per band = 2^rows_log2 (the last band may be shorter)
  int rows() const { return 1 << rows_log2; }
};

// Bands small enough for their depths and colors to stay in a core's L2 cache (about
// kBandPixels pixels), and at least kBandsPerThread per thread so that threads share the work
// evenly. The layout changes speed only, never the image.
BandLayout choose_bands(int width, int height, unsigned threads) {
  BandLayout b;
  const int wanted = static_cast<int>(threads) * kBandsPerThread;
  b.rows_log2 = 2;
  while ((2 << b.rows_log2) * width <= kBandPixels && (height >> (b.rows_log2 + 1)) >= wanted) {
    ++b.rows_log2;
  }
  b.count = (height + b.rows() - 1) >> b.rows_log2;
  return b;
}

// Rows touched by the chunk's splats: [min(y − r), max(y + r)] (r = size/2), so that a band can
// skip chunks that miss it (a chunk is a subtree, so its splats are close together on screen).
void row_extent(const SplatChunk& chunk, RasterScratch::Chunk& out) {
  float lo = std::numeric_limits<float>::infinity(), hi = -lo;
  for (std::size_t i = 0; i < chunk.count; ++i) {
    const float r = 0.5f * chunk.size_px[i];
    lo = std::min(lo, chunk.y_px[i] - r);
    hi = std::max(hi, chunk.y_px[i] + r);
  }
  out.y_min_px = lo;
  out.y_max_px = hi;
}

template <SplatShape kShape, class Clip>
inline void draw_shape(const Target& t, const SplatChunk& s, const RasterScratch::Chunk& sc,
                       std::size_t i, const Clip& clip) {
  const float r = 0.5f * s.size_px[i];
  const std::uint32_t c = s.shaded[i];
  if constexpr (kShape == SplatShape::Square) {
    draw_square(t, s.x_px[i], s.y_px[i], s.depth[i], r, c, clip);
  } else if constexpr (kShape == SplatShape::Circle) {
    draw_circle(t, s.x_px[i], s.y_px[i], s.depth[i], r, c, clip);
  } else {
    draw_ellipse(t, s.x_px[i], s.y_px[i], s.depth[i], r, &sc.ellipse[kEllipseStride * i], c,
                 clip);
  }
}

// kFeatures: splats with clip planes test each covered pixel against them.
template <SplatShape kShape, bool kFeatures>
inline void draw_one(const Target& t, const SplatChunk& s, const RasterScratch::Chunk& sc,
                     std::size_t i) {
  if constexpr (kFeatures) {
    const std::uint8_t code = s.clip_code[i];
    if (clip_count(code) != 0) {
      const CameraFrame& cam = *sc.camera;
      const Vec3f d = s.center[i] - cam.eye, n = s.normal[i];
      const Vec3f ce{dot(d, cam.right), dot(d, cam.up), dot(d, cam.forward)};
      const Vec3f ne{dot(n, cam.right), dot(n, cam.up), dot(n, cam.forward)};
      const PixelClip clip{ce.x, ce.y, ce.z, ne.x, ne.y, ne.z, dot(ne, ce),
                           0.5f * t.width_f, 0.5f * t.height_f, 1.0f / cam.focal_px, cam.ortho,
                           sc.planes.data() + 4 * static_cast<std::size_t>(s.clip_first[i]),
                           clip_count(code), clip_mode(code), t.clipped, t.clip_mask, t.width};
      draw_shape<kShape>(t, s, sc, i, clip);
      return;
    }
  }
  draw_shape<kShape>(t, s, sc, i, NoClip{});
}

// Draws every splat that may touch the band, chunk by chunk in stream order. A splat touches
// rows whose centre is within its radius of y, and the row holding y, so y + r ≥ first row and
// y − r < end row is a safe test.
template <SplatShape kShape, bool kFeatures>
void draw_band(const SplatStream& stream, std::size_t first, std::size_t end,
               const RasterScratch& scratch, bool banded, const Target& t) {
  const float band_lo = static_cast<float>(t.row_begin), band_hi = static_cast<float>(t.row_end);
  for (std::size_t c = first; c < end; ++c) {
    const SplatChunk& s = stream.chunks[c];
    const RasterScratch::Chunk& sc = scratch.chunks[c];
    if (!banded || (sc.y_min_px >= band_lo && sc.y_max_px < band_hi)) {
      for (std::size_t i = 0; i < s.count; ++i) draw_one<kShape, kFeatures>(t, s, sc, i);
      continue;
    }
    if (!(sc.y_max_px >= band_lo && sc.y_min_px < band_hi)) continue;
    for (std::size_t i = 0; i < s.count; ++i) {
      const float y = s.y_px[i], r = 0.5f * s.size_px[i];
      if (y + r >= band_lo && y - r < band_hi) draw_one<kShape, kFeatures>(t, s, sc, i);
    }
  }
}

void clear_band(const Target& t, Rgb8 background) {
  const std::size_t w = static_cast<std::size_t>(t.width);
  const std::size_t rows = static_cast<std::size_t>(t.row_end - t.row_begin);
  const std::size_t first = static_cast<std::size_t>(t.row_begin) * w;
  std::fill(t.color, t.color + rows * w, pack_rgb(background));
  std::fill(t.depth + first, t.depth + first + rows * w, std::numeric_limits<float>::infinity());
}

void draw_chunks(const SplatStream& stream, std::size_t first, std::size_t end,
                 const RasterScratch& scratch, SplatShape shape, bool banded, const Target& t) {
  const bool f = stream.has_features;
  switch (shape) {
    case SplatShape::Square:
      (f ? draw_band<SplatShape::Square, true> : draw_band<SplatShape::Square, false>)(
          stream, first, end, scratch, banded, t);
      break;
    case SplatShape::Circle:
      (f ? draw_band<SplatShape::Circle, true> : draw_band<SplatShape::Circle, false>)(
          stream, first, end, scratch, banded, t);
      break;
    case SplatShape::Ellipse:
      (f ? draw_band<SplatShape::Ellipse, true> : draw_band<SplatShape::Ellipse, false>)(
          stream, first, end, scratch, banded, t);
      break;
  }
}

// The band's packed pixels to the output's 3-byte pixels (raster/unpack_rgb.hpp).
void unpack_band(const Target& t, std::span<Rgb8> out) {
  const std::size_t w = static_cast<std::size_t>(t.width);
  render_detail::unpack_rgb(t.color, static_cast<std::size_t>(t.row_end - t.row_begin) * w,
                            out.data() + static_cast<std::size_t>(t.row_begin) * w);
}

// Per-chunk preparation of chunks [first, end): ellipse parameters, row extents, eye-space
// clip planes.
void prepare_chunks(const SplatStream& stream, std::size_t first, std::size_t end,
                    const CameraFrame& camera, const RenderSettings& settings, bool banded,
                    ThreadPool& pool, RasterScratch& scratch) {
  const bool ellipses = settings.shape == SplatShape::Ellipse;
  if (scratch.chunks.size() < end) scratch.chunks.resize(end);
  const bool features = stream.has_features;
  if (ellipses || banded || features) pool.run(end - first, [&](std::size_t k) {
    const std::size_t c = first + k;
    if (ellipses) prepare_ellipses(stream.chunks[c], camera, scratch.chunks[c]);
    if (banded) row_extent(stream.chunks[c], scratch.chunks[c]);
    if (features) {
      render_detail::eye_space_planes(stream.chunks[c], camera, scratch.chunks[c].planes);
      scratch.chunks[c].camera = &camera;
    }
  });
}

Target band_target(const CameraFrame& camera, const BandLayout& bands, int b,
                   std::uint32_t* color, float* depth, std::uint64_t* clipped,
                   std::uint8_t* clip_mask = nullptr) {
  return Target{color,
                depth,
                camera.width,
                camera.height,
                b << bands.rows_log2,
                std::min(camera.height, (b + 1) << bands.rows_log2),
                static_cast<float>(camera.width),
                static_cast<float>(camera.height),
                clipped,
                clip_mask};
}

// Sharp features: a cleared mask of the pixels clipping empties, for the frame.
std::uint8_t* start_clip_mask(const CameraFrame& camera, RasterScratch& scratch) {
  if (!scratch.clip_mask_active) {
    scratch.clip_mask.assign(static_cast<std::size_t>(camera.width) * camera.height, 0);
    scratch.clip_mask_active = true;
  }
  return scratch.clip_mask.data();
}

// After the frame: clipping never opens a pinhole (raster/clip_pinholes.hpp).
void fill_pinholes(const CameraFrame& camera, RasterScratch& scratch, std::span<Rgb8> color,
                   std::span<float> depth) {
  scratch.pinholes_filled =
      scratch.clip_mask_active && scratch.clipped_fragments > 0 && !depth.empty()
          ? render_detail::fill_clipped_pinholes(color, depth, scratch.clip_mask, camera.width,
                                                 camera.height)
          : 0;
  scratch.clip_mask_active = false;
}

}  // namespace

void rasterize_splats(const SplatStream& stream, const CameraFrame& camera,
                      const RenderSettings& settings, ThreadPool& pool, RasterScratch& scratch,
                      std::span<Rgb8> color, std::span<float> depth) {
  [[maybe_unused]] const std::size_t pixels =
      static_cast<std::size_t>(camera.width) * static_cast<std::size_t>(camera.height);
  assert(color.size() == pixels && depth.size() == pixels);
  const BandLayout bands = choose_bands(camera.width, camera.height, pool.thread_count());
  const bool banded = bands.count > 1;
  prepare_chunks(stream, 0, stream.chunk_count, camera, settings, banded, pool, scratch);

  // One worker per thread takes bands off a shared counter and packs colors in its own
  // band-sized buffer; which worker draws a band does not matter.
  const std::size_t workers =
      std::min<std::size_t>(pool.thread_count(), static_cast<std::size_t>(bands.count));
  const std::size_t band_pixels =
      static_cast<std::size_t>(bands.rows()) * static_cast<std::size_t>(camera.width);
  scratch.band_colors.resize(std::max(scratch.band_colors.size(), workers));
  for (std::size_t k = 0; k < workers; ++k) scratch.band_colors[k].resize(band_pixels);
  std::atomic<int> next_band{0};
  std::atomic<std::uint64_t> clipped{0};
  scratch.clip_mask_active = false;
  std::uint8_t* mask = stream.has_features ? start_clip_mask(camera, scratch) : nullptr;
  pool.run(workers, [&](std::size_t worker) {
    std::uint64_t clipped_here = 0;
    for (int b = next_band++; b < bands.count; b = next_band++) {
      const Target t = band_target(camera, bands, b, scratch.band_colors[worker].data(),
                                   depth.data(), &clipped_here, mask);
      clear_band(t, settings.background);
      draw_chunks(stream, 0, stream.chunk_count, scratch, settings.shape, banded, t);
      unpack_band(t, color);
    }
    clipped += clipped_here;
  });
  scratch.clipped_fragments = clipped;
  fill_pinholes(camera, scratch, color, depth);
}

void begin_splats(const CameraFrame& camera, const RenderSettings& settings, ThreadPool& pool,
                  RasterScratch& scratch, std::span<float> depth) {
  const std::size_t pixels =
      static_cast<std::size_t>(camera.width) * static_cast<std::size_t>(camera.height);
  assert(depth.size() == pixels);
  if (scratch.image.size() < pixels) scratch.image.resize(pixels);
  scratch.clipped_fragments = 0;
  scratch.clip_mask_active = false;
  const BandLayout bands = choose_bands(camera.width, camera.height, pool.thread_count());
  pool.run(static_cast<std::size_t>(bands.count), [&](std::size_t b) {
    const int band = static_cast<int>(b);
    std::uint32_t* color = scratch.image.data() +
                           (static_cast<std::size_t>(band) << bands.rows_log2) *
                               static_cast<std::size_t>(camera.width);
    clear_band(band_target(camera, bands, band, color, depth.data(), nullptr),
               settings.background);
  });
}

void draw_splats(const SplatStream& stream, std::size_t first_chunk, std::size_t end_chunk,
                 const CameraFrame& camera, const RenderSettings& settings, ThreadPool& pool,
                 RasterScratch& scratch, std::span<float> depth) {
  if (first_chunk >= end_chunk) return;
  const BandLayout bands = choose_bands(camera.width, camera.height, pool.thread_count());
  const bool banded = bands.count > 1;
  prepare_chunks(stream, first_chunk, end_chunk, camera, settings, banded, pool, scratch);
  std::atomic<std::uint64_t> clipped{0};
  std::uint8_t* mask = stream.has_features ? start_clip_mask(camera, scratch) : nullptr;
  pool.run(static_cast<std::size_t>(bands.count), [&](std::size_t b) {
    const int band = static_cast<int>(b);
    std::uint64_t clipped_here = 0;
    std::uint32_t* color = scratch.image.data() +
                           (static_cast<std::size_t>(band) << bands.rows_log2) *
                               static_cast<std::size_t>(camera.width);
    draw_chunks(stream, first_chunk, end_chunk, scratch, settings.shape, banded,
                band_target(camera, bands, band, color, depth.data(), &clipped_here, mask));
    clipped += clipped_here;
  });
  scratch.clipped_fragments += clipped;
}

void finish_splats(const CameraFrame& camera, ThreadPool& pool, RasterScratch& scratch,
                   std::span<Rgb8> color, std::span<float> depth) {
  const BandLayout bands = choose_bands(camera.width, camera.height, pool.thread_count());
  pool.run(static_cast<std::size_t>(bands.count), [&](std::size_t b) {
    const int band = static_cast<int>(b);
    const std::uint32_t* packed = scratch.image.data() +
                                  (static_cast<std::size_t>(band) << bands.rows_log2) *
                                      static_cast<std::size_t>(camera.width);
    unpack_band(band_target(camera, bands, band, const_cast<std::uint32_t*>(packed), nullptr,
                            nullptr),
                color);
  });
  fill_pinholes(camera, scratch, color, depth);
}

}  // namespace pointillist
