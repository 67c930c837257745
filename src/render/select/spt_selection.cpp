// Level-of-detail selection from a Sequential Point Tree (Dachsbacher, Vogelgsang & Stamminger,
// "Sequential Point Trees", SIGGRAPH 2003, section 4): the per-entry test r_min ≤ r < r_max is a
// branch-free pass over contiguous arrays, here vectorized by the compiler on the CPU (the
// paper's GPU vertex program), with whole chunks culled against the view frustum first.
//
// Parallel and deterministic: the scanned prefix of every visible range is cut into blocks of
// kBlock entries; each block is one task writing one stream chunk, and chunks are in list order.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "pointillist/core/error.hpp"
#include "pointillist/render/spt_render.hpp"
#include "pointillist/render/splat_raster.hpp"
#include "frame_pass.hpp"
#include "shading.hpp"
#include "select/subtree_selection.hpp"

namespace pointillist {
namespace {

constexpr std::uint32_t kBlock = 1u << 14;  // entries per task
constexpr std::uint32_t kTile = 256;        // entries per mask pass (stays in L1)
constexpr float kMaxCoordinate = 1e9f;

struct Block {
  std::uint32_t begin, end;
};

struct ViewConstants {
  Vec3f eye, right, up, forward;
  float focal_px, half_w, half_h, width, height;
  float epsilon2;      // (epsilon_px / f)²: compared with error² / r² (orthographic: r = 1)
  float facing_limit;  // 0 with backface culling (drop (c − eye)·n > 0), else +infinity
  bool ortho;          // orthographic: parallel rays along forward
  // The hybrid lists' s_N (HybridLod::suppress_below), or null; and the square of the cosine
  // within which of edge-on a suppressed entry keeps its splat.
  const float* suppress = nullptr;
  float silhouette_cos2 = 0;
};

// Hybrid mode: an entry seen nearly edge-on (|cos| of the angle between its normal and the view
// direction below kSilhouetteCos) keeps its splat even where the triangles around it are drawn.
// There the triangles of a quantized model (.ptl leaf positions are within a fraction of a splat
// radius of the mesh's vertices) can fall up to a pixel short of the true silhouette, and the
// splat, as in the pure SPT, covers it.
constexpr float kSilhouetteCos = 0.05f;
// Only splats at most this many error bounds (--epsilon pixels) across are kept so: the gap they
// fill is under a pixel, and a large splat kept edge-on (a ground quad's corner seen from eye
// height) would cover the sky. Squared.
constexpr float kSilhouetteSplat2 = 32.0f * 32.0f;

// Entry i of [begin, end) is selected (mask 1) iff error² ≤ r²ε² < parent_error² and it faces the
// eye, (c − eye)·n ≤ facing_limit (mask 2: in its interval but facing away). Written without
// branches over the structure-of-arrays so that GCC vectorizes it (at -O3, which the release build
// uses: check with -fopt-info-vec). Testing the facing here, on every scanned entry, is cheaper
// than projecting and shading the backfacing half of the selection only to drop it.
void select_mask(const SequentialPointTree& t, std::uint32_t begin, std::uint32_t end,
                 const ViewConstants& v, std::uint8_t* __restrict mask) {
  const float* __restrict cx = t.center_x.data() + begin;
  const float* __restrict cy = t.center_y.data() + begin;
  const float* __restrict cz = t.center_z.data() + begin;
  const float* __restrict nx = t.normal_x.data() + begin;
  const float* __restrict ny = t.normal_y.data() + begin;
  const float* __restrict nz = t.normal_z.data() + begin;
  const float* __restrict err = t.error.data() + begin;
  const float* __restrict perr = t.parent_error.data() + begin;
  const float ex = v.eye.x, ey = v.eye.y, ez = v.eye.z, eps2 = v.epsilon2;
  const float facing_limit = v.facing_limit;
  const std::uint32_t n = end - begin;
  if (v.suppress) {
    // Hybrid lists: as below, minus the entries whose triangles replace them, (r + ρ)·ε < s,
    // unless seen nearly edge-on.
    const float* __restrict sup = v.suppress + begin;
    const float* __restrict diameter = t.diameter.data() + begin;
    const std::uint8_t* __restrict leaf = t.is_leaf.data() + begin;
    const float s2 = v.silhouette_cos2;
    const float fx = v.forward.x, fy = v.forward.y, fz = v.forward.z;
    for (std::uint32_t i = 0; i < n; ++i) {
      const float dx = v.ortho ? fx : cx[i] - ex, dy = v.ortho ? fy : cy[i] - ey,
                  dz = v.ortho ? fz : cz[i] - ez;
      const float d2 = dx * dx + dy * dy + dz * dz;
      const float re2 = v.ortho ? eps2 : d2 * eps2;
      const float rho = leaf[i] ? 0.0f : 0.5f * diameter[i];
      const float far = std::sqrt(d2) + rho;
      const float far2 = v.ortho ? eps2 : far * far * eps2;
      const float facing = dx * nx[i] + dy * ny[i] + dz * nz[i];
      // Edge-on and small: at most kSilhouetteSplat error bounds across.
      const int edge_on = (facing * facing < s2 * d2) &
                          (diameter[i] * diameter[i] < kSilhouetteSplat2 * re2);
      const int kept = static_cast<int>(!(far2 < sup[i] * sup[i])) | edge_on;
      const int in = (err[i] * err[i] <= re2) & (re2 < perr[i] * perr[i]) & kept;
      mask[i] = static_cast<std::uint8_t>(in + (in & (facing > facing_limit)));
    }
    return;
  }
  if (v.ortho) {
    // Every entry is seen at the same scale and from the same direction.
    const float fx = v.forward.x, fy = v.forward.y, fz = v.forward.z;
    for (std::uint32_t i = 0; i < n; ++i) {
      const float facing = fx * nx[i] + fy * ny[i] + fz * nz[i];
      const int in = (err[i] * err[i] <= eps2) & (eps2 < perr[i] * perr[i]);
      mask[i] = static_cast<std::uint8_t>(in + (in & (facing > facing_limit)));
    }
    return;
  }
  for (std::uint32_t i = 0; i < n; ++i) {
    const float dx = cx[i] - ex, dy = cy[i] - ey, dz = cz[i] - ez;
    const float re2 = (dx * dx + dy * dy + dz * dz) * eps2;
    const float facing = dx * nx[i] + dy * ny[i] + dz * nz[i];
    const int in = (err[i] * err[i] <= re2) & (re2 < perr[i] * perr[i]);
    mask[i] = static_cast<std::uint8_t>(in + (in & (facing > facing_limit)));
  }
}

// Index one past the last entry of [begin, end) (sorted by parent_error descending) whose
// parent_error exceeds `limit`: later entries cannot be drawn.
std::uint32_t prefix_end(const SequentialPointTree& t, std::uint32_t begin, std::uint32_t end,
                         float limit) {
  const auto first = t.parent_error.begin() + begin, last = t.parent_error.begin() + end;
  return static_cast<std::uint32_t>(
      std::partition_point(first, last, [limit](float pe) { return pe > limit; }) -
      t.parent_error.begin());
}

bool sphere_outside(const CameraFrame& cam, const Sphere& s) {
  if (dot(s.center - cam.eye, cam.forward) <= -s.radius) return true;
  for (const Plane& p : cam.planes) {
    if (p.distance(s.center) <= -s.radius) return true;
  }
  return false;
}

struct BlockCounters {
  std::uint64_t scanned = 0, backface = 0, frustum = 0;
};

// Selects, projects and shades the entries of one block into `out`. Per tile: the vectorized
// mask pass, a compaction of the selected indices, then projection and shading four splats at a
// time, keeping the lanes in front of the eye and on the image.
void run_block(const SequentialPointTree& t, Block b, const ViewConstants& v,
               const render_detail::Shader& shader, bool with_colors, bool with_discs,
               SplatChunk& out, BlockCounters& counters) {
  using render_detail::Float4;
  using render_detail::Int4;
  using render_detail::kLanes;
  using render_detail::splat4;
  out.count = 0;
  std::uint8_t mask[kTile];
  std::uint32_t selected[kTile + kLanes];
  counters.scanned += b.end - b.begin;
  const Vec3f base_color = shader.base_color();
  const float* cx = t.center_x.data();
  const float* cy = t.center_y.data();
  const float* cz = t.center_z.data();
  for (std::uint32_t tile = b.begin; tile < b.end; tile += kTile) {
    const std::uint32_t tile_end = std::min(b.end, tile + kTile);
    select_mask(t, tile, tile_end, v, mask);
    std::uint32_t k = 0;
    std::uint64_t backface = 0;
    for (std::uint32_t i = 0; i < tile_end - tile; ++i) {
      selected[k] = tile + i;
      k += mask[i] == 1;
      backface += mask[i] == 2;
    }
    counters.backface += backface;
    if (k == 0) continue;
    // Pad to whole groups with the last selected entry (its lanes are dropped below).
    for (std::uint32_t p = k; p % kLanes; ++p) selected[p] = selected[k - 1];
    out.reserve(out.count + k + kLanes, with_colors, with_discs);
    for (std::uint32_t g = 0; g < k; g += kLanes) {
      const std::uint32_t* idx = selected + g;
      const Float4 dx = Float4{cx[idx[0]], cx[idx[1]], cx[idx[2]], cx[idx[3]]} - v.eye.x;
      const Float4 dy = Float4{cy[idx[0]], cy[idx[1]], cy[idx[2]], cy[idx[3]]} - v.eye.y;
      const Float4 dz = Float4{cz[idx[0]], cz[idx[1]], cz[idx[2]], cz[idx[3]]} - v.eye.z;
      const Float4 z = dx * v.forward.x + dy * v.forward.y + dz * v.forward.z;
      const Float4 inv_z = v.ortho ? splat4(1.0f) : 1.0f / render_detail::max4(splat4(1e-30f), z);
      const Float4 x = v.half_w + v.focal_px * (dx * v.right.x + dy * v.right.y + dz * v.right.z) * inv_z;
      const Float4 y = v.half_h - v.focal_px * (dx * v.up.x + dy * v.up.y + dz * v.up.z) * inv_z;
      const Float4 diameter{t.diameter[idx[0]], t.diameter[idx[1]], t.diameter[idx[2]],
                            t.diameter[idx[3]]};
      const Float4 size = diameter * v.focal_px * inv_z;
      // Kept: in front of the eye, not a hair in front of it, and touching the image (with a
      // pixel of margin: a splat below a pixel still draws the pixel holding its centre).
      const Float4 half = 0.5f * size + 1.0f;
      const Int4 visible = (z > 0.0f) & (size < kMaxCoordinate) & (x + half >= 0.0f) &
                           (x - half <= v.width) & (y + half >= 0.0f) & (y - half <= v.height);
      Float4 normal[3], to_eye[3], base[3];
      normal[0] = Float4{t.normal_x[idx[0]], t.normal_x[idx[1]], t.normal_x[idx[2]], t.normal_x[idx[3]]};
      normal[1] = Float4{t.normal_y[idx[0]], t.normal_y[idx[1]], t.normal_y[idx[2]], t.normal_y[idx[3]]};
      normal[2] = Float4{t.normal_z[idx[0]], t.normal_z[idx[1]], t.normal_z[idx[2]], t.normal_z[idx[3]]};
      // Shading (as the QSplat traversal's finish_chunk): normal, unit vector to the eye, base.
      const Float4 inv_len = 1.0f / render_detail::sqrt4(
          render_detail::max4(splat4(1e-30f), dx * dx + dy * dy + dz * dz));
      for (int c = 0; c < 3; ++c) to_eye[c] = splat4(-v.forward[c]);
      if (!v.ortho) {
        to_eye[0] = -dx * inv_len;
        to_eye[1] = -dy * inv_len;
        to_eye[2] = -dz * inv_len;
      }
      if (with_colors) {
        constexpr float kScale = 1.0f / 255.0f;
        const Rgb8* col = t.colors.data();
        base[0] = Float4{float(col[idx[0]].r), float(col[idx[1]].r), float(col[idx[2]].r),
                         float(col[idx[3]].r)} * kScale;
        base[1] = Float4{float(col[idx[0]].g), float(col[idx[1]].g), float(col[idx[2]].g),
                         float(col[idx[3]].g)} * kScale;
        base[2] = Float4{float(col[idx[0]].b), float(col[idx[1]].b), float(col[idx[2]].b),
                         float(col[idx[3]].b)} * kScale;
      } else {
        for (int c = 0; c < 3; ++c) base[c] = splat4(base_color[c]);
      }
      Int4 rgb[3];
      shader.shade4(normal, to_eye, base, rgb);
      const Int4 packed = rgb[0] | rgb[1] << 8 | rgb[2] << 16;
      const std::uint32_t lanes = std::min<std::uint32_t>(kLanes, k - g);
      for (std::uint32_t l = 0; l < lanes; ++l) {
        // Written unconditionally, kept by advancing the count (no branch on the lane).
        const std::size_t o = out.count;
        out.x_px[o] = x[l];
        out.y_px[o] = y[l];
        out.depth[o] = z[l];
        out.size_px[o] = size[l];
        out.shaded[o] = static_cast<std::uint32_t>(packed[l]);
        out.node[o] = idx[l];
        out.normal[o] = Vec3f{normal[0][l], normal[1][l], normal[2][l]};
        if (with_discs) {
          out.center[o] = Vec3f{cx[idx[l]], cy[idx[l]], cz[idx[l]]};
          out.radius[o] = 0.5f * diameter[l];
        }
        if (with_colors) out.color[o] = t.colors[idx[l]];
        const bool kept = visible[l] != 0;
        out.count += kept;
        counters.frustum += !kept;
      }
    }
  }
}

ViewConstants spt_view(const CameraFrame& camera, const RenderSettings& settings,
                       float epsilon_px) {
  ViewConstants v;
  v.eye = camera.eye;
  v.right = camera.right;
  v.up = camera.up;
  v.forward = camera.forward;
  v.focal_px = camera.focal_px;
  v.half_w = 0.5f * static_cast<float>(camera.width);
  v.half_h = 0.5f * static_cast<float>(camera.height);
  v.width = static_cast<float>(camera.width);
  v.height = static_cast<float>(camera.height);
  const float epsilon = epsilon_px / camera.focal_px;  // world error per unit distance
  v.epsilon2 = epsilon * epsilon;
  v.ortho = camera.ortho;
  v.facing_limit = settings.culls_backfaces() ? 0.0f : std::numeric_limits<float>::infinity();
  return v;
}

// The blocks of list range [begin, end) whose bounding sphere is `bounds`: the prefix that can
// be drawn from the eye, cut into kBlock entries.
void range_blocks(const SequentialPointTree& tree, std::uint32_t begin, std::uint32_t end,
                  const Sphere& bounds, const CameraFrame& camera, float epsilon_px,
                  std::vector<Block>& blocks) {
  const float epsilon = epsilon_px / camera.focal_px;
  // Orthographic: every entry is seen at distance 1 (ε is then in world units).
  const float r_lo = camera.ortho ? 1.0f
                                  : std::max(0.0f, distance(bounds.center, camera.eye) - bounds.radius);
  const std::uint32_t stop = prefix_end(tree, begin, end, r_lo * epsilon);
  for (std::uint32_t b = begin; b < stop; b += kBlock) {
    blocks.push_back({b, std::min(stop, b + kBlock)});
  }
}

}  // namespace

namespace render_detail {

Sphere spt_top_bounds(const SequentialPointTree& tree) {
  return {tree.view_sphere.center,
          tree.view_sphere.radius + (tree.node_count() ? tree.diameter[0] : 0)};
}

bool spt_chunk_outside(const CameraFrame& camera, const Sphere& bounds) {
  return sphere_outside(camera, bounds);
}

void select_spt_range(const SequentialPointTree& tree, std::uint32_t begin, std::uint32_t end,
                      const Sphere& bounds, const CameraFrame& camera,
                      const RenderSettings& settings, float epsilon_px, const Shader& shader,
                      bool with_discs, SplatChunk& out, SptSelectionStats& stats) {
  const auto v = spt_view(camera, settings, epsilon_px);
  thread_local std::vector<Block> blocks;
  blocks.clear();
  range_blocks(tree, begin, end, bounds, camera, epsilon_px, blocks);
  const std::size_t first = out.count;
  thread_local SplatChunk part;
  for (const Block& b : blocks) {
    BlockCounters counters;
    run_block(tree, b, v, shader, tree.has_colors, with_discs, part, counters);
    stats.entries_scanned += counters.scanned;
    stats.culled_frustum += counters.frustum;
    stats.culled_backface += counters.backface;
    // Appended to `out` in list order.
    out.reserve(out.count + part.count, tree.has_colors, with_discs);
    const std::size_t o = out.count, n = part.count;
    std::copy_n(part.x_px.begin(), n, out.x_px.begin() + o);
    std::copy_n(part.y_px.begin(), n, out.y_px.begin() + o);
    std::copy_n(part.depth.begin(), n, out.depth.begin() + o);
    std::copy_n(part.size_px.begin(), n, out.size_px.begin() + o);
    std::copy_n(part.shaded.begin(), n, out.shaded.begin() + o);
    std::copy_n(part.normal.begin(), n, out.normal.begin() + o);
    std::copy_n(part.node.begin(), n, out.node.begin() + o);
    if (tree.has_colors) std::copy_n(part.color.begin(), n, out.color.begin() + o);
    if (with_discs) {
      std::copy_n(part.center.begin(), n, out.center.begin() + o);
      std::copy_n(part.radius.begin(), n, out.radius.begin() + o);
    }
    out.count = o + n;
  }
  stats.splats += out.count - first;
}

}  // namespace render_detail

void select_splats_spt(const SequentialPointTree& tree, const CameraFrame& camera,
                       const RenderSettings& settings, const SptRenderOptions& options,
                       ThreadPool& pool, SplatStream& stream, SptSelectionStats& stats) {
  if (!(options.epsilon_px > 0.0f) || !std::isfinite(options.epsilon_px)) {
    throw OptionError("SPT error bound " + std::to_string(options.epsilon_px) +
                      " px is invalid; give a positive number of pixels (--epsilon 1 draws full "
                      "detail)");
  }
  stats = {};
  stream.chunk_count = 0;
  stream.has_colors = tree.has_colors;
  stats.entries_total = tree.node_count();
  stats.chunks_total = tree.chunks.size();
  if (tree.node_count() == 0) return;

  if (!options.suppress_below.empty() && options.suppress_below.size() != tree.node_count()) {
    throw Error("SPT selection: " + std::to_string(options.suppress_below.size()) +
                " suppression bounds given for " + std::to_string(tree.node_count()) +
                " entries; build the hybrid lists from this tree");
  }
  const render_detail::Shader shader(settings, camera);
  ViewConstants v = spt_view(camera, settings, options.epsilon_px);
  if (!options.suppress_below.empty()) {
    v.suppress = options.suppress_below.data();
    v.silhouette_cos2 = kSilhouetteCos * kSilhouetteCos;
  }

  // The ranges to scan and their prefixes, cut into blocks.
  std::vector<Block> blocks;
  auto add_range = [&](std::uint32_t begin, std::uint32_t end, const Sphere& bounds) {
    range_blocks(tree, begin, end, bounds, camera, options.epsilon_px, blocks);
  };
  // The top list's sphere: the first chunk's bounds do not cover it; use the whole model's.
  const Sphere model_sphere = render_detail::spt_top_bounds(tree);
  if (tree.top_end > 0) add_range(0, tree.top_end, model_sphere);
  for (const SptChunk& c : tree.chunks) {
    if (options.chunk_culling && settings.frustum_culling && sphere_outside(camera, c.bounds)) {
      ++stats.chunks_culled;
      continue;
    }
    add_range(c.begin, c.end, c.bounds);
  }

  if (stream.chunks.size() < blocks.size()) stream.chunks.resize(blocks.size());
  stream.chunk_count = blocks.size();
  std::vector<BlockCounters> counters(blocks.size());
  pool.run(blocks.size(), [&](std::size_t b) {
    run_block(tree, blocks[b], v, shader, tree.has_colors, stream.with_discs, stream.chunks[b],
              counters[b]);
  });
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    stats.entries_scanned += counters[b].scanned;
    stats.culled_frustum += counters[b].frustum;
    stats.culled_backface += counters[b].backface;
    stats.splats += stream.chunks[b].count;
  }
}

void render_spt(const SequentialPointTree& tree, const Camera& camera,
                const RenderSettings& settings, const SptRenderOptions& options, ThreadPool& pool,
                Frame& frame, SptSelectionStats* details) {
  SptSelectionStats selection;
  render_detail::frame_pass(camera, settings, nullptr, nullptr, pool, frame,
                            [&](const CameraFrame& cam, SplatStream& stream) {
                              select_splats_spt(tree, cam, settings, options, pool, stream,
                                                selection);
                              return selection.as_selection();
                            });
  if (details) *details = selection;
}

}  // namespace pointillist
