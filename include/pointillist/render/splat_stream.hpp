// The splat stream: what selection produces and rasterizers consume (ARCHITECTURE.md, "Selection
// is separate from rasterization").
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "pointillist/core/buffer.hpp"
#include "pointillist/core/math.hpp"
#include "pointillist/features/features.hpp"

namespace pointillist {

// A run of consecutive splats, structure of arrays. The arrays are buffers whose size is the
// capacity; only the first `count` entries are splats. Buffers keep their memory across frames,
// are not zeroed when they grow, and the discs (center, radius) and colours are sized only when
// the stream carries them.
// Positions and sizes are finite, below 1e9 px in magnitude (selection drops other splats).
struct SplatChunk {
  std::size_t count = 0;
  Buffer<float> x_px;       // centre in pixels: column, 0 = left edge of the image
  Buffer<float> y_px;       // centre in pixels: row, 0 = top edge (pixel centres at +0.5)
  Buffer<float> depth;      // eye-space depth of the centre (> 0, world units)
  Buffer<float> size_px;    // projected diameter 2·r·f/z in pixels
  // Lit color (RenderSettings shading, evaluated once per splat), packed r | g << 8 | b << 16.
  Buffer<std::uint32_t> shaded;
  // The splat itself, in world space, so a rasterizer needs nothing but the stream: the disc
  // of centre `center`, radius `radius` and unit normal `normal` (for a stand-in of a subtree
  // that is not loaded, the normal turned toward the eye), and its colour.
  Buffer<Vec3f> center;
  Buffer<float> radius;
  Buffer<Vec3f> normal;
  Buffer<Rgb8> color;       // filled only when the stream has_colors
  Buffer<std::uint32_t> node;  // index of the node in its hierarchy (or SPT entry)
  // Sharp features, filled only when the stream has_features: the splat's surface id, unique
  // across the scene's instances (kMixedSurface blends with any surface), and its clip planes
  // in world space, clip_planes[clip_first[i] ..] (clip_count(clip_code[i]) of them, combined
  // by clip_mode(clip_code[i])).
  Buffer<std::uint32_t> surface;
  Buffer<std::uint32_t> clip_first;
  Buffer<std::uint8_t> clip_code;
  std::vector<ClipPlane> clip_planes;
  // Which instance of the scene the chunk's splats belong to (a chunk holds one instance's).
  std::uint32_t instance = 0;

  std::size_t capacity() const { return x_px.size(); }
  // Grows the buffers to at least `n` entries (keeping the first `count`): the colours only
  // `with_colors`, the discs only `with_discs`.
  void reserve(std::size_t n, bool with_colors, bool with_discs);
};

// A splat's plane count and clip mode packed in one byte (SplatChunk::clip_code).
constexpr std::uint8_t clip_code(std::size_t count, ClipMode mode) {
  return static_cast<std::uint8_t>(count | (static_cast<unsigned>(mode) << 5));
}
constexpr std::uint32_t clip_count(std::uint8_t code) { return code & 31u; }
constexpr ClipMode clip_mode(std::uint8_t code) { return static_cast<ClipMode>(code >> 5); }

// The 8-bit channels of a packed color (SplatChunk::shaded).
constexpr Rgb8 unpack_rgb(std::uint32_t c) {
  return {static_cast<std::uint8_t>(c), static_cast<std::uint8_t>(c >> 8),
          static_cast<std::uint8_t>(c >> 16)};
}

// Splats in stream order: chunk 0 first, each chunk in order. The order is the depth-first order
// of the hierarchy and does not depend on the thread count; the quality rasterizer sums in it
// (the fast one's image does not depend on it). Chunk boundaries depend only on the tree and the
// camera.
struct SplatStream {
  std::vector<SplatChunk> chunks;  // only the first `chunk_count` are in use
  std::size_t chunk_count = 0;
  bool has_colors = false;
  // Set by the caller before selection: whether selection fills each chunk's center and radius.
  // The quality rasterizer reads them; the fast one draws from the projected centre and size
  // only, and leaving the discs out saves 16 bytes of stores a splat (about a tenth of the
  // QSplat selection's time on the dragon).
  bool with_discs = true;
  // Whether the chunks carry surface ids and clip planes (a model with sharp features, drawn
  // with them).
  bool has_features = false;

  std::size_t size() const {
    std::size_t n = 0;
    for (std::size_t c = 0; c < chunk_count; ++c) n += chunks[c].count;
    return n;
  }
  // Called before a new selection: frees the buffers of chunks much larger than what they held
  // in the last frame (over 4× its count plus kTrimSlack splats; the chunks past chunk_count
  // held nothing). A chunk's index gets other parts of the scene from frame to frame, so
  // without this every index would keep the largest chunk it ever held: gigabytes for scenes
  // of thousands of instances.
  void trim();
  static constexpr std::size_t kTrimSlack = 1024;
};

}  // namespace pointillist
