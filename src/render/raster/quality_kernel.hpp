// Pieces shared by the quality rasterizer and reconstruct_pixel: the reconstruction rule, the
// kernel's exponential and the layout of the per-splat setup.
#pragma once

#include <cstdint>
#include <cstring>
#include <span>
#include <vector>

#include "pointillist/core/camera.hpp"
#include "pointillist/core/thread_pool.hpp"
#include "pointillist/lod/sphere_tree.hpp"
#include "pointillist/render/quality.hpp"
#include "pointillist/render/splat_stream.hpp"
#include "simd.hpp"

namespace pointillist::quality_detail {

using render_detail::Float4;
using render_detail::Int4;

// The rule of Reconstruction: a fragment's interval [key, bound]. ZThreshold: key = depth,
// bound = depth + ε·r; ZRange: [depth_min − m·r, depth_max + m·r].
struct RuleConstants {
  bool z_range = true;
  float z_threshold = 1, z_range_margin = 0.5f;
};
inline RuleConstants rule_constants(const QualitySettings& q) {
  return {q.reconstruction == Reconstruction::ZRange, q.z_threshold, q.z_range_margin};
}
inline float fragment_key(const RuleConstants& k, float depth, float depth_min, float radius) {
  return k.z_range ? depth_min - k.z_range_margin * radius : depth;
}
inline float fragment_bound(const RuleConstants& k, float depth, float depth_max, float radius) {
  return k.z_range ? depth_max + k.z_range_margin * radius : depth + k.z_threshold * radius;
}

// e^(−x) lane by lane for x in [0, 80] (clamped; NaN gives 1): 2^y with y = −x·log2(e) split
// into an integer n and f in [−½, ½], 2^f by its Taylor polynomial of degree 6 (relative error
// below 1e-7 plus rounding), and n added to the exponent bits.
inline Float4 exp_neg4(Float4 x) {
  x = render_detail::min4(render_detail::splat4(80.0f),
                          render_detail::max4(render_detail::splat4(0.0f), x));
  const Float4 y = x * -1.44269504088896341f;
  const Int4 n = render_detail::to_int4(y - 0.5f);  // y − ½ < 0: truncation rounds toward y
  const Float4 f = y - render_detail::to_float4(n);
  Float4 p = f * 1.5403530393381609e-4f + 1.3333558146428443e-3f;
  p = p * f + 9.6181291076284772e-3f;
  p = p * f + 5.5504108664821580e-2f;
  p = p * f + 2.4022650695910071e-1f;
  p = p * f + 6.9314718055994531e-1f;
  p = p * f + 1.0f;
  Int4 bits;
  std::memcpy(&bits, &p, sizeof bits);
  bits += n << 23;
  Float4 out;
  std::memcpy(&out, &bits, sizeof out);
  return out;
}

// Where four pixels' rays meet a splat's plane (unit normal n and n·c in eye coordinates):
// depth t and the eye-space X, Y of the hit. Perspective rays t·(a, b, 1) (na = n_x·a + n_z,
// computed once per column); orthographic rays along +z from (a, b, 0). The occluder pass
// computes its hits with this too, so that it agrees with the rasterizer.
inline void ray_hits(bool ortho, Float4 a, Float4 na, float b, float nx, float ny, float nz,
                     float nc, Float4& t, Float4& x, Float4& y) {
  if (ortho) {
    t = (nc - nx * a - ny * b) / nz;
    x = a;
    y = render_detail::splat4(b);
  } else {
    t = nc / (na + ny * b);
    x = t * a;
    y = t * b;
  }
}

// Per-splat setup, kStride floats per splat (quality_setup.cpp writes it).
enum SplatField : int {
  kI0, kI1, kJ0, kJ1,     // pixel box (inclusive, clipped to the image; i1 < i0 when empty)
  kCx, kCy, kCz,          // centre in eye coordinates (x right, y up, z = depth)
  kNx, kNy, kNz,          // unit normal in eye coordinates
  kNc,                    // n·c
  kInvR2,                 // 1 / r²
  kSx, kSy,               // projected centre in pixels (for the low-pass)
  kDepthLo, kDepthHi,     // the disc's depth interval c_z ± r·√(1 − n_z²)
  kKey, kBound,           // ZRange: the widened interval; ZThreshold: unused, ε·r
  kBaseR, kBaseG, kBaseB, // base color, linear 0..1
  kWx, kWy, kWz,          // unit normal in world space (blended for shading)
  // Sharp features (SplatStream::has_features), uint32 bits: surface id, the first of the
  // splat's clip planes in the chunk's eye-space planes (4 floats each), SplatChunk::clip_code.
  kSurface, kClipFirst, kClipCode,
  kStride = 28,
};

inline float bits_to_float(std::uint32_t u) {
  float f;
  std::memcpy(&f, &u, sizeof f);
  return f;
}
inline std::uint32_t float_to_bits(float f) {
  std::uint32_t u;
  std::memcpy(&u, &f, sizeof u);
  return u;
}

// What the per-splat setup needs to know about the view.
struct SetupConstants {
  CameraFrame camera;
  RuleConstants rule;
  float lowpass_radius_px = 1;
  float radius_scale = 1;  // disc radius / node radius
  bool has_colors = false;
  Vec3f base_color;
  int band_rows = 1, band_count = 1;  // rows of the image drawn by one band, bands
};

// The setup constants rasterize_quality uses for a stream of `camera` (its band layout for
// `threads` workers).
SetupConstants quality_setup(const CameraFrame& camera, const RenderSettings& settings,
                             const QualitySettings& quality, bool has_colors, unsigned threads);

// Grows the per-chunk setup buffers of `scratch` to at least `chunks` chunks.
inline void fit_chunks(QualityScratch& scratch, std::size_t chunks) {
  if (scratch.chunk_splats.size() < chunks) scratch.chunk_splats.resize(chunks);
  if (scratch.chunk_bins.size() < chunks) scratch.chunk_bins.resize(chunks);
  if (scratch.chunk_planes.size() < chunks) scratch.chunk_planes.resize(chunks);
}

// Splats [begin, end) of chunk `chunk` of a stream.
struct StreamPiece {
  std::uint32_t chunk = 0, begin = 0, end = 0;
};

// rasterize_quality over splats of `stream` taken piece by piece in the order of `pieces`
// instead of in stream order, with every chunk's setup already in `scratch` (prepare_chunk with
// quality_setup(camera, settings, quality, stream.has_colors, pool.thread_count()) and the
// stream's has_features). The image is rasterize_quality's on a stream holding the pieces' splats in that
// order.
void rasterize_quality_pieces(const SplatStream& stream, std::span<const StreamPiece> pieces,
                              const CameraFrame& camera, const RenderSettings& settings,
                              const QualitySettings& quality, ThreadPool& pool,
                              QualityScratch& scratch, std::span<Rgb8> color,
                              std::span<float> depth);

// Writes the setup of every splat of `chunk` into `splats` (kStride floats each) and bins the
// splats by band: bins[b] .. bins[b + 1] − 1 (offsets counted from bins[band_count + 1]) are
// the indices, in stream order, of the chunk's splats whose pixel box meets band b. With
// `features`, also the splats' surface ids and clip planes, the planes moved into eye
// coordinates (n_e, h_e: n_e·P − h_e for P in eye coordinates) into `planes`.
void prepare_chunk(const SplatChunk& chunk, const SetupConstants& k, bool features,
                   std::vector<float>& splats, std::vector<std::uint32_t>& bins,
                   std::vector<float>& planes);

}  // namespace pointillist::quality_detail
