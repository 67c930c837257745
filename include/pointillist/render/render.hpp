// Software splat renderer: QSplat traversal (selection) feeding a z-buffered splat rasterizer.
#pragma once

#include <cstdint>
#include <vector>

#include "pointillist/core/camera.hpp"
#include "pointillist/core/math.hpp"
#include "pointillist/core/thread_pool.hpp"
#include "pointillist/lod/sphere_tree.hpp"

namespace pointillist {

enum class SplatShape {
  Square,   // axis-aligned square of side = projected diameter
  Circle,   // disc of the projected diameter (default)
  Ellipse,  // disc seen at an angle: major axis = projected diameter, minor/major = max(n·v, 0.1)
};

struct RenderSettings {
  // Stop refining when a node's projected diameter 2·r·f/z is at most this many pixels. Larger
  // values draw fewer, bigger splats (faster, coarser).
  float threshold_px = 1.0f;
  SplatShape shape = SplatShape::Circle;
  Rgb8 background{0, 0, 0};
  // Light direction in eye space (toward the light); the default is a headlight at the eye.
  Vec3f light_dir_eye{0, 0, 1};
  bool frustum_culling = true;   // turn off only to check that culling changes nothing
  bool backface_culling = true;  // normal-cone culling of whole subtrees
  // Surface color when the model has no colors (linear 0..1).
  Vec3f base_color{0.8f, 0.8f, 0.8f};
  float ambient = 0.08f;
  float diffuse = 0.85f;
  float specular = 0.25f;   // Blinn-Phong
  float shininess = 32.0f;
};

struct RenderStats {
  std::uint64_t splats = 0;           // splats rasterized
  std::uint64_t nodes_visited = 0;    // nodes whose sphere was tested
  std::uint64_t culled_frustum = 0;   // subtrees skipped outside the frustum
  std::uint64_t culled_backface = 0;  // subtrees (or terminal nodes) skipped facing away
  int width = 0, height = 0;
  unsigned threads = 1;
  double ms_select = 0, ms_raster = 0, ms_total = 0;
};

// The rendered image: 8-bit RGB color, rows top to bottom, and depth along the view direction
// (world units; +infinity where nothing was drawn). Buffers are reused across frames.
struct Frame {
  int width = 0, height = 0;
  std::vector<Rgb8> color;
  std::vector<float> depth;
  RenderStats stats;
};

// Renders the hierarchy seen by `camera` into `frame` (resized as needed). The image bits depend
// only on the arguments, never on pool.thread_count(). Throws OptionError for an invalid camera
// or threshold.
void render(const SphereTreeView& tree, const Camera& camera, const RenderSettings& settings,
            ThreadPool& pool, Frame& frame);

}  // namespace pointillist
