// Selection and drawing of the hybrid mode's triangles (see triangle_draw.hpp).
#include "raster/triangle_draw.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "pointillist/render/renderer.hpp"
#include "raster/unpack_rgb.hpp"
#include "select/subtree_selection.hpp"

namespace pointillist::render_detail {
namespace {

constexpr int kBandRows = 32;
constexpr std::uint32_t kScreenBlock = 4096;  // selected triangles per projection task


// Whether a triangle is dropped by backface culling: every corner's normal faces away from the
// eye (as the splats are dropped), and so does its plane (oriented by the corners' normals), so
// that at a silhouette, where smoothed normals turn away before the surface does, the triangle
// is still drawn as the reference draws it.
bool faces_away(const HybridLod& lod, const std::array<std::uint32_t, 3>& tri,
                const CameraFrame& cam) {
  const Vec3f a = lod.positions[tri[0]];
  const auto to_eye = [&](Vec3f p) { return cam.ortho ? -cam.forward : cam.eye - p; };
  Vec3f sum{0, 0, 0};
  for (int k = 0; k < 3; ++k) {
    const Vec3f n = lod.normals[tri[k]];
    if (!(dot(n, to_eye(lod.positions[tri[k]])) < 0.0f)) return false;
    sum = sum + n;
  }
  Vec3f face = cross(lod.positions[tri[1]] - a, lod.positions[tri[2]] - a);
  if (dot(face, sum) < 0.0f) face = -face;
  return dot(face, to_eye(a)) < 0.0f;
}

// Scans one group's prefix into `out`.
void select_group(const HybridLod& lod, const HybridTriangleGroup& g, const CameraFrame& cam,
                  float epsilon, bool backface_culling, std::vector<std::uint32_t>& out,
                  std::uint64_t& scanned) {
  const float r_lo =
      cam.ortho ? 1.0f : std::max(0.0f, distance(g.bounds.center, cam.eye) - g.bounds.radius);
  const float limit = r_lo * epsilon;
  const auto first = lod.triangle_error.begin() + g.begin;
  const auto stop = std::partition_point(first, lod.triangle_error.begin() + g.end,
                                         [limit](float e) { return e > limit; });
  const std::uint32_t end = static_cast<std::uint32_t>(stop - lod.triangle_error.begin());
  scanned += end - g.begin;
  const float eps2 = epsilon * epsilon;
  const Vec3f eye = cam.eye;
  for (std::uint32_t t = g.begin; t < end; ++t) {
    const auto& tri = lod.triangles[t];
    float r2 = 1.0f;
    if (!cam.ortho) {
      r2 = std::numeric_limits<float>::infinity();
      for (int k = 0; k < 3; ++k) {
        const Vec3f p = lod.positions[tri[k]];
        const float dx = p.x - eye.x, dy = p.y - eye.y, dz = p.z - eye.z;
        r2 = std::min(r2, dx * dx + dy * dy + dz * dz);
      }
    }
    const float e = lod.triangle_error[t];
    if (!(r2 * eps2 < e * e)) continue;
    if (backface_culling && faces_away(lod, tri, cam)) continue;
    bool outside = false;
    for (const Plane& pl : cam.planes) {
      outside = outside || (pl.distance(lod.positions[tri[0]]) < 0 &&
                            pl.distance(lod.positions[tri[1]]) < 0 &&
                            pl.distance(lod.positions[tri[2]]) < 0);
    }
    if (!outside) out.push_back(t);
  }
}

// The screen triangles of one batch's selected triangles [begin, end) (near-clipped: 0 to 2
// each), appended to `out`.
void project_block(const TriangleBatch& b, std::size_t begin, std::size_t end,
                   const CameraFrame& cam, Vec3f base_color, std::vector<ScreenTriangle>& out) {
  const HybridLod& lod = *b.lod;
  const bool colors = !lod.colors.empty();
  // One near plane for all the model's triangles (1e-5 × the depth of its farthest point, as the
  // mesh reference's), so that two triangles sharing an edge are clipped at the same points and
  // leave no crack between them.
  Sphere bounds = lod.view_sphere;
  if (b.transform) {
    bounds = {b.transform->apply(bounds.center), bounds.radius * b.transform->scale};
  }
  const float far = cam.depth(bounds.center) + bounds.radius;
  if (!(far > 0.0f)) return;
  const float near = 1e-5f * far;
  for (std::size_t s = begin; s < end; ++s) {
    const auto& tri = lod.triangles[b.selected[s]];
    std::array<EyeVertex, 3> v;
    for (int k = 0; k < 3; ++k) {
      Vec3f p = lod.positions[tri[k]], n = lod.normals[tri[k]];
      if (b.transform) {
        p = b.transform->apply(p);
        n = b.transform->rotate(n);
      }
      Vec3f c = base_color;
      if (colors) {
        const Rgb8 rgb = lod.colors[tri[k]];
        c = Vec3f{float(rgb.r), float(rgb.g), float(rgb.b)} * (1.0f / 255.0f);
      }
      v[k] = {eye_space(cam, p), n, c};
    }
    std::array<EyeVertex, 4> clipped;
    const int count = clip_near(v, near, clipped);
    if (count < 3) continue;
    const ScreenVertex s0 = project_vertex(cam, clipped[0]);
    for (int k = 1; k + 1 < count; ++k) {
      ScreenTriangle st{{s0, project_vertex(cam, clipped[k]), project_vertex(cam, clipped[k + 1])},
                        0, 0};
      const double lo = std::min({st.v[0].y, st.v[1].y, st.v[2].y});
      const double hi = std::max({st.v[0].y, st.v[1].y, st.v[2].y});
      const double lx = std::min({st.v[0].x, st.v[1].x, st.v[2].x});
      const double hx = std::max({st.v[0].x, st.v[1].x, st.v[2].x});
      if (!(hi >= 0 && lo <= cam.height && hx >= 0 && lx <= cam.width)) continue;
      st.y_lo = static_cast<float>(std::max(lo, 0.0));
      st.y_hi = static_cast<float>(std::min(hi, double(cam.height)));
      out.push_back(st);
    }
  }
}

}  // namespace

void select_triangles(const HybridLod& lod, const CameraFrame& camera,
                      const RenderSettings& settings, float epsilon_px, ThreadPool& pool,
                      std::vector<std::uint32_t>& out, TriangleSelectionStats& stats) {
  const float epsilon = epsilon_px / camera.focal_px;
  std::vector<std::uint32_t> visible;
  for (std::uint32_t g = 0; g < lod.groups.size(); ++g) {
    if (lod.groups[g].begin == lod.groups[g].end) continue;
    if (settings.frustum_culling && spt_chunk_outside(camera, lod.groups[g].bounds)) {
      ++stats.groups_culled;
      continue;
    }
    visible.push_back(g);
  }
  std::vector<std::vector<std::uint32_t>> parts(visible.size());
  std::vector<std::uint64_t> scanned(visible.size(), 0);
  pool.run(visible.size(), [&](std::size_t k) {
    select_group(lod, lod.groups[visible[k]], camera, epsilon, settings.culls_backfaces(),
                 parts[k], scanned[k]);
  });
  const std::size_t before = out.size();
  for (std::size_t k = 0; k < parts.size(); ++k) {
    out.insert(out.end(), parts[k].begin(), parts[k].end());
    stats.scanned += scanned[k];
  }
  stats.triangles += out.size() - before;
}

std::uint64_t draw_triangles(std::span<const TriangleBatch> batches, const CameraFrame& cam,
                             const RenderSettings& settings, ThreadPool& pool,
                             TriangleScratch& scratch, std::span<Rgb8> color,
                             std::span<float> depth) {
  // Projection, in blocks of selected triangles (block order = batch order, then list order).
  struct Block {
    std::size_t batch, begin, end;
  };
  std::vector<Block> blocks;
  for (std::size_t b = 0; b < batches.size(); ++b) {
    for (std::size_t s = 0; s < batches[b].selected.size(); s += kScreenBlock) {
      blocks.push_back({b, s, std::min(batches[b].selected.size(), s + kScreenBlock)});
    }
  }
  if (blocks.empty()) return 0;
  if (scratch.parts.size() < blocks.size()) scratch.parts.resize(blocks.size());
  pool.run(blocks.size(), [&](std::size_t k) {
    scratch.parts[k].clear();
    project_block(batches[blocks[k].batch], blocks[k].begin, blocks[k].end, cam,
                  settings.base_color, scratch.parts[k]);
  });
  scratch.screen.clear();
  for (std::size_t k = 0; k < blocks.size(); ++k) {
    scratch.screen.insert(scratch.screen.end(), scratch.parts[k].begin(), scratch.parts[k].end());
  }

  // Bands of kBandRows rows, each drawing the triangles that reach it.
  const int band_count = (cam.height + kBandRows - 1) / kBandRows;
  std::vector<std::uint32_t> band_begin(band_count + 1, 0);
  const auto band_range = [&](const ScreenTriangle& t) {
    const int lo = std::clamp(static_cast<int>(t.y_lo) / kBandRows, 0, band_count - 1);
    const int hi = std::clamp(static_cast<int>(t.y_hi) / kBandRows, 0, band_count - 1);
    return std::pair{lo, hi};
  };
  for (const ScreenTriangle& t : scratch.screen) {
    const auto [lo, hi] = band_range(t);
    for (int b = lo; b <= hi; ++b) ++band_begin[b + 1];
  }
  for (int b = 0; b < band_count; ++b) band_begin[b + 1] += band_begin[b];
  std::vector<std::uint32_t> in_band(band_begin.back());
  {
    std::vector<std::uint32_t> next(band_begin.begin(), band_begin.end() - 1);
    for (std::uint32_t i = 0; i < scratch.screen.size(); ++i) {
      const auto [lo, hi] = band_range(scratch.screen[i]);
      for (int b = lo; b <= hi; ++b) in_band[next[b]++] = i;
    }
  }
  const Shader shader(settings, cam);
  const auto test = [&](std::size_t idx, float z) { return z <= depth[idx]; };
  const auto write = [&](std::size_t idx, float z, Rgb8 c) {
    if (z < depth[idx] || pack_rgb(c) < pack_rgb(color[idx])) {
      depth[idx] = z;
      color[idx] = c;
    }
  };
  pool.run(static_cast<std::size_t>(band_count), [&](std::size_t b) {
    const int row_begin = static_cast<int>(b) * kBandRows;
    const int row_end = std::min(cam.height, row_begin + kBandRows);
    for (std::uint32_t k = band_begin[b]; k < band_begin[b + 1]; ++k) {
      const ScreenTriangle& t = scratch.screen[in_band[k]];
      raster_triangle(cam, shader, t.v[0], t.v[1], t.v[2], row_begin, row_end, test, write);
    }
  });
  return scratch.screen.size();
}

}  // namespace pointillist::render_detail
