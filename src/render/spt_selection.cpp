// Level-of-detail selection from a Sequential Point Tree (Dachsbacher, Vogelgsang & Stamminger,
// "Sequential Point Trees", SIGGRAPH 2003, section 4): the per-entry test r_min ≤ r < r_max is a
// branch-free pass over contiguous arrays, here vectorized by the compiler on the CPU (the
// paper's GPU vertex program), with whole chunks culled against the view frustum first.
//
// Parallel and deterministic: the scanned prefix of every visible range is cut into blocks of
// kBlock entries; each block is one task writing one stream chunk, and chunks are in list order.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "pointillist/core/error.hpp"
#include "pointillist/render/spt_render.hpp"
#include "pointillist/render/splat_raster.hpp"
#include "render/shading.hpp"

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
  float epsilon2;  // (epsilon_px / f)²: compared with error² / r²
  bool backface;
};

// Entry i of [begin, end) is selected (mask 1) iff error² ≤ r²ε² < parent_error² and, with
// backface culling, (c − eye)·n ≤ 0 (mask 2: in its interval but facing away). Written without branches over the structure-of-arrays so
// that GCC vectorizes it (-O2 and -O3 both: see the -fopt-info-vec note in the README).
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
  const float facing_limit = v.backface ? 0.0f : std::numeric_limits<float>::infinity();
  const std::uint32_t n = end - begin;
  for (std::uint32_t i = 0; i < n; ++i) {
    const float dx = cx[i] - ex, dy = cy[i] - ey, dz = cz[i] - ez;
    const float re2 = (dx * dx + dy * dy + dz * dz) * eps2;
    const float facing = dx * nx[i] + dy * ny[i] + dz * nz[i];
    const int in = (err[i] * err[i] <= re2) & (re2 < perr[i] * perr[i]);
    // 1: draw; 2: in its interval but facing away; 0: not in its interval.
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

// Selects, projects and shades the entries of one block into `out`.
void run_block(const SequentialPointTree& t, Block b, const ViewConstants& v,
               const render_detail::Shader& shader, bool with_colors, SplatChunk& out,
               BlockCounters& counters) {
  using render_detail::Float4;
  using render_detail::Int4;
  out.count = 0;
  std::uint8_t mask[kTile];
  std::uint32_t selected[kTile];
  counters.scanned += b.end - b.begin;
  for (std::uint32_t tile = b.begin; tile < b.end; tile += kTile) {
    const std::uint32_t tile_end = std::min(b.end, tile + kTile);
    select_mask(t, tile, tile_end, v, mask);
    std::uint32_t k = 0;
    for (std::uint32_t i = 0; i < tile_end - tile; ++i) {
      selected[k] = tile + i;
      k += mask[i] == 1;
      counters.backface += mask[i] == 2;
    }
    if (k == 0) continue;
    out.reserve(out.count + k, with_colors);
    for (std::uint32_t s = 0; s < k; ++s) {
      const std::uint32_t i = selected[s];
      const Vec3f d{t.center_x[i] - v.eye.x, t.center_y[i] - v.eye.y, t.center_z[i] - v.eye.z};
      const float z = dot(d, v.forward);
      if (!(z > 0)) {
        ++counters.frustum;
        continue;
      }
      const float inv_z = 1.0f / z;
      const float x = v.half_w + v.focal_px * dot(d, v.right) * inv_z;
      const float y = v.half_h - v.focal_px * dot(d, v.up) * inv_z;
      const float size = t.diameter[i] * v.focal_px * inv_z;
      const float half = 0.5f * size + 1.0f;
      // Outside the image (with a pixel of margin: a tiny splat still draws its pixel) or a
      // hair in front of the eye.
      if (!(x + half >= 0 && x - half <= v.width && y + half >= 0 && y - half <= v.height &&
            size < kMaxCoordinate)) {
        ++counters.frustum;
        continue;
      }
      const std::size_t o = out.count++;
      out.x_px[o] = x;
      out.y_px[o] = y;
      out.depth[o] = z;
      out.size_px[o] = size;
      out.node[o] = i;
      out.normal[o] = Vec3f{t.normal_x[i], t.normal_y[i], t.normal_z[i]};
      if (with_colors) out.color[o] = t.colors[i];
    }
  }
  // Shading, four splats at a time (as the QSplat traversal's finish_chunk).
  const Vec3f base_color = shader.base_color();
  for (std::size_t i = 0; i < out.count; i += render_detail::kLanes) {
    const std::size_t lanes = std::min<std::size_t>(render_detail::kLanes, out.count - i);
    std::size_t idx[render_detail::kLanes];
    for (std::size_t l = 0; l < render_detail::kLanes; ++l) idx[l] = i + std::min(l, lanes - 1);
    Float4 normal[3], to_eye[3], base[3];
    for (int c = 0; c < 3; ++c) {
      normal[c] = Float4{out.normal[idx[0]][c], out.normal[idx[1]][c], out.normal[idx[2]][c],
                         out.normal[idx[3]][c]};
    }
    const std::uint32_t* node = out.node.data();
    to_eye[0] = v.eye.x - Float4{t.center_x[node[idx[0]]], t.center_x[node[idx[1]]],
                                 t.center_x[node[idx[2]]], t.center_x[node[idx[3]]]};
    to_eye[1] = v.eye.y - Float4{t.center_y[node[idx[0]]], t.center_y[node[idx[1]]],
                                 t.center_y[node[idx[2]]], t.center_y[node[idx[3]]]};
    to_eye[2] = v.eye.z - Float4{t.center_z[node[idx[0]]], t.center_z[node[idx[1]]],
                                 t.center_z[node[idx[2]]], t.center_z[node[idx[3]]]};
    const Float4 inv_len = 1.0f / render_detail::sqrt4(to_eye[0] * to_eye[0] +
                                                       to_eye[1] * to_eye[1] +
                                                       to_eye[2] * to_eye[2]);
    for (Float4& e : to_eye) e *= inv_len;
    if (with_colors) {
      constexpr float kScale = 1.0f / 255.0f;
      const Rgb8* col = out.color.data();
      base[0] = Float4{float(col[idx[0]].r), float(col[idx[1]].r), float(col[idx[2]].r),
                       float(col[idx[3]].r)} * kScale;
      base[1] = Float4{float(col[idx[0]].g), float(col[idx[1]].g), float(col[idx[2]].g),
                       float(col[idx[3]].g)} * kScale;
      base[2] = Float4{float(col[idx[0]].b), float(col[idx[1]].b), float(col[idx[2]].b),
                       float(col[idx[3]].b)} * kScale;
    } else {
      for (int c = 0; c < 3; ++c) base[c] = render_detail::splat4(base_color[c]);
    }
    Int4 rgb[3];
    shader.shade4(normal, to_eye, base, rgb);
    const Int4 packed = rgb[0] | rgb[1] << 8 | rgb[2] << 16;
    for (std::size_t l = 0; l < lanes; ++l) out.shaded[i + l] = static_cast<std::uint32_t>(packed[l]);
  }
}

}  // namespace

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

  const render_detail::Shader shader(settings, camera);
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
  const float epsilon = options.epsilon_px / camera.focal_px;  // world error per unit distance
  v.epsilon2 = epsilon * epsilon;
  v.backface = settings.backface_culling;

  // The ranges to scan and their prefixes, cut into blocks.
  std::vector<Block> blocks;
  auto add_range = [&](std::uint32_t begin, std::uint32_t end, const Sphere& bounds) {
    const float r_lo = std::max(0.0f, distance(bounds.center, camera.eye) - bounds.radius);
    const std::uint32_t stop = prefix_end(tree, begin, end, r_lo * epsilon);
    for (std::uint32_t b = begin; b < stop; b += kBlock) blocks.push_back({b, std::min(stop, b + kBlock)});
  };
  // The top list's sphere: the first chunk's bounds do not cover it; use the whole model's.
  const Sphere model_sphere{tree.view_sphere.center,
                            tree.view_sphere.radius + (tree.node_count() ? tree.diameter[0] : 0)};
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
    run_block(tree, blocks[b], v, shader, tree.has_colors, stream.chunks[b], counters[b]);
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
  using clock = std::chrono::steady_clock;
  auto ms = [](clock::time_point a, clock::time_point b) {
    return std::chrono::duration<double, std::milli>(b - a).count();
  };
  const auto start = clock::now();
  const CameraFrame cam = make_camera_frame(camera);
  const std::size_t pixels = static_cast<std::size_t>(cam.width) * static_cast<std::size_t>(cam.height);
  frame.width = cam.width;
  frame.height = cam.height;
  frame.color.resize(pixels);
  frame.depth.resize(pixels);
  SptSelectionStats selection;
  select_splats_spt(tree, cam, settings, options, pool, frame.splats, selection);
  const auto selected = clock::now();
  rasterize_splats(frame.splats, cam, settings, pool, frame.scratch, frame.color, frame.depth);
  const auto done = clock::now();
  RenderStats& s = frame.stats;
  s = {};
  s.splats = selection.splats;
  s.nodes_visited = selection.entries_scanned;
  s.culled_frustum = selection.chunks_culled + selection.culled_frustum;
  s.culled_backface = selection.culled_backface;
  s.width = cam.width;
  s.height = cam.height;
  s.threads = pool.thread_count();
  s.ms_select = ms(start, selected);
  s.ms_raster = ms(selected, done);
  s.ms_total = ms(start, done);
  if (details) *details = selection;
}

}  // namespace pointillist
