// The per-node tests and the splat output shared by the QSplat traversals (the in-memory
// hierarchy in sphere_tree_traversal.cpp, the paged one in paged_render.cpp). Internal to render.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <span>

#include "pointillist/core/camera.hpp"
#include "pointillist/lod/sphere_tree.hpp"
#include "pointillist/render/selection.hpp"
#include "pointillist/render/settings.hpp"
#include "pointillist/render/splat_stream.hpp"
#include "shading.hpp"

namespace pointillist::render_detail {
constexpr std::uint8_t kTestFrustum = 1;
constexpr std::uint8_t kTestBackface = 2;
constexpr std::uint8_t kDecidedDraw = 4;  // top-level item already visited: just draw it
constexpr std::size_t kTargetTasks = 128;
// A task for about this many expected splats at least: a small model (an instance among
// thousands in a scene) is walked by a few tasks, not kTargetTasks chunks' worth of buffers.
constexpr std::uint64_t kSplatsPerTask = 2048;
inline std::size_t target_tasks(std::uint64_t expected) {
  return static_cast<std::size_t>(
      std::clamp<std::uint64_t>(expected / kSplatsPerTask, 1, kTargetTasks));
}
constexpr std::size_t kInitialChunkCapacity = 128;
// A chunk's first capacity: an even share of `expected` splats (Buffer memory that is never
// written is never touched, so a first frame sized generously costs no page faults for what it
// does not draw, and no regrowth copies).
inline std::size_t first_chunk_capacity(std::uint64_t expected, std::size_t chunks) {
  return std::max<std::size_t>(kInitialChunkCapacity,
                               static_cast<std::size_t>(expected / std::max<std::size_t>(chunks, 1)));
}
// The splats a view is expected to draw at most, for sizing a first frame: no more than the
// model's leaves, and no more than a few per pixel.
// `bound`, when given, is the model's bounding sphere: a model far away covers few pixels, and
// draws at most a few splats per pixel it covers (a scene of thousands of instances then sizes
// its chunks by what each instance can draw, not by its points).
inline std::uint64_t expected_splats(std::uint64_t leaves, const CameraFrame& camera,
                                     const Sphere* bound = nullptr, float threshold_px = 1.0f) {
  const std::uint64_t pixels = static_cast<std::uint64_t>(camera.width) * camera.height;
  std::uint64_t expected = std::min(leaves, 2 * pixels);
  if (bound) {
    const float z = dot(bound->center - camera.eye, camera.forward) - bound->radius;
    if (z > 0) {
      const double rho = double(bound->radius) * camera.focal_px * camera.projection(z);  // px
      const double t = std::max(0.25, double(threshold_px));
      const double covered = 4.0 * 3.14159265 * (rho + 1) * (rho + 1) / (t * t);
      if (covered < double(expected)) expected = static_cast<std::uint64_t>(covered) + 1;
    }
  }
  return expected;
}
constexpr float kMaxCoordinate = 1e9f;  // pixels; larger (or NaN) splat coordinates are dropped

struct Pending {
  std::uint32_t node;
  std::uint8_t tests;
};

struct Counters {
  std::uint64_t visited = 0, culled_frustum = 0, culled_backface = 0, culled_occluded = 0;
};



struct ViewConstants {
  const Shader* shader;
  Vec3f base_color;
  Vec3f eye, right, up, forward;
  float focal_px, half_w, half_h;
  float size_per_radius;  // 2·f: projected diameter = r · size_per_radius / z (orthographic: · 1)
  float threshold_px;
  bool ortho;             // orthographic camera (CameraFrame::ortho)
  std::array<Plane, 4> planes;
  bool with_discs;  // finish_chunk writes the discs (SplatStream::with_discs)
  bool cull_facing;  // splats facing away are dropped (not with two-sided lighting)
  // Paged selection under occlusion culling: subtrees in other pages are tested first.
  const SubtreeOcclusion* occlusion = nullptr;
};

enum class Decision { Cull, Draw, Refine };

// One node's tests (section 9.2 of the spec). Updates `tests` for the subtree; returns the
// offset d = c − eye and the depth z for the caller to reuse.
inline Decision visit(const SphereNode& n, const ViewConstants& v, std::uint8_t& tests,
                      Counters& counters, Vec3f& d, float& z) {
  ++counters.visited;
  d = n.center - v.eye;
  z = dot(d, v.forward);
  const float r = n.radius;
  if (tests & kTestFrustum) {
    bool inside = z > r;
    if (z <= -r) {
      ++counters.culled_frustum;
      return Decision::Cull;
    }
    for (const Plane& p : v.planes) {
      const float dist = p.distance(n.center);
      if (dist <= -r) {
        ++counters.culled_frustum;
        return Decision::Cull;
      }
      inside &= dist >= r;
    }
    if (inside) tests &= static_cast<std::uint8_t>(~kTestFrustum);
  }
  if ((tests & kTestBackface) && n.cone_sin < 1.0f && v.ortho) {
    // Parallel rays: every normal of the cone faces away when n·forward > sin(cone), every one
    // faces the eye when −n·forward > sin(cone).
    const float k = -dot(v.forward, n.normal);
    if (k < -n.cone_sin) {
      ++counters.culled_backface;
      return Decision::Cull;
    }
    if (k > n.cone_sin) tests &= static_cast<std::uint8_t>(~kTestBackface);
  } else if ((tests & kTestBackface) && n.cone_sin < 1.0f) {
    const float k = -dot(d, n.normal);
    // Only a sphere entirely on one side of its normal's plane can pass either test.
    if (k + r < 0.0f || k - r > 0.0f) {
      const float bound = n.cone_sin > 0.0f ? n.cone_sin * (std::sqrt(dot(d, d)) + r) : 0.0f;
      if (k + r < -bound) {
        ++counters.culled_backface;
        return Decision::Cull;
      }
      if (k - r > bound) tests &= static_cast<std::uint8_t>(~kTestBackface);
    }
  }
  if (n.child_count == 0 ||
      (z > 0 && r * v.size_per_radius <= v.threshold_px * (v.ortho ? 1.0f : z))) {
    return Decision::Draw;
  }
  return Decision::Refine;
}

// Appends splats to a chunk through raw pointers, refreshed when the chunk grows. Only what the
// traversal has at hand is written; finish_chunk fills in the rest.
class Emitter {
 public:
  Emitter(SplatChunk& out, bool with_colors, bool with_discs)
      : out_(out), with_colors_(with_colors), with_discs_(with_discs) {
    refresh();
  }
  ~Emitter() { out_.count = count_; }
  Emitter(const Emitter&) = delete;
  Emitter& operator=(const Emitter&) = delete;

  // Node `index` with offset d = c − eye and depth z, unless it is behind the eye or faces away
  // (see the header).
  // `check_facing` off: drawn even when its normal faces away (a node standing in for a subtree
  // that is not loaded, whose cone may still hold normals facing the eye).
  void emit(const SphereNode& n, std::uint32_t index, Vec3f d, float z, const ViewConstants& v,
            Counters& counters, bool check_facing = true) {
    if (!(z > 0)) {
      ++counters.culled_frustum;
      return;
    }
    if (check_facing && v.cull_facing && n.cone_sin < 1.0f &&
        dot(v.ortho ? v.forward : d, n.normal) > 0) {
      ++counters.culled_backface;
      return;
    }
    const float inv_z = v.ortho ? 1.0f : 1.0f / z;
    const float x = v.half_w + v.focal_px * dot(d, v.right) * inv_z;
    const float y = v.half_h - v.focal_px * dot(d, v.up) * inv_z;
    const float size = n.radius * v.size_per_radius * inv_z;
    // Centres a hair in front of the eye overflow; such splats cannot be drawn.
    if (!(std::abs(x) < kMaxCoordinate && std::abs(y) < kMaxCoordinate && size < kMaxCoordinate)) {
      ++counters.culled_frustum;
      return;
    }
    if (count_ == capacity_) grow();
    const std::size_t i = count_++;
    x_[i] = x;
    y_[i] = y;
    depth_[i] = z;
    size_[i] = size;
    node_[i] = index;
  }

 private:
  void grow() {
    out_.count = count_;
    out_.reserve(count_ + 1, with_colors_, with_discs_);
    refresh();
  }
  void refresh() {
    count_ = out_.count;
    capacity_ = out_.capacity();
    x_ = out_.x_px.data();
    y_ = out_.y_px.data();
    depth_ = out_.depth.data();
    size_ = out_.size_px.data();
    node_ = out_.node.data();
  }

  SplatChunk& out_;
  bool with_colors_, with_discs_;
  std::size_t count_ = 0, capacity_ = 0;
  float *x_ = nullptr, *y_ = nullptr, *depth_ = nullptr, *size_ = nullptr;
  std::uint32_t* node_ = nullptr;
};

// Copies the discs (centre, radius, normal) and colors of the chunk's nodes and shades them, four at a time (a second pass
// keeps the traversal loop small; the nodes are still in cache). A last partial group repeats
// its last splat in the unused lanes.
// `node_at(i)` gives the node of the chunk's node index i (a const SphereNode&).
template <class NodeAt>
void finish_chunk(const NodeAt& node_at, const ViewConstants& v, bool with_colors,
                  SplatChunk& out) {
  const Shader& shader = *v.shader;
  const std::size_t count = out.count;
  for (std::size_t i = 0; i < count; i += render_detail::kLanes) {
    const std::size_t lanes = std::min<std::size_t>(render_detail::kLanes, count - i);
    const SphereNode* n[render_detail::kLanes];
    for (std::size_t k = 0; k < render_detail::kLanes; ++k) {
      n[k] = &node_at(out.node[i + std::min(k, lanes - 1)]);
    }
    for (std::size_t k = 0; k < lanes; ++k) {
      out.normal[i + k] = n[k]->normal;
      if (with_colors) out.color[i + k] = n[k]->color;
    }
    if (v.with_discs) {
      for (std::size_t k = 0; k < lanes; ++k) {
        out.center[i + k] = n[k]->center;
        out.radius[i + k] = n[k]->radius;
      }
    }
    Float4 normal[3], to_eye[3], base[3];
    for (int c = 0; c < 3; ++c) {
      normal[c] = Float4{n[0]->normal[c], n[1]->normal[c], n[2]->normal[c], n[3]->normal[c]};
      to_eye[c] = v.eye[c] - Float4{n[0]->center[c], n[1]->center[c], n[2]->center[c],
                                    n[3]->center[c]};
    }
    if (v.ortho) {
      for (int c = 0; c < 3; ++c) to_eye[c] = splat4(-v.forward[c]);
    } else {
      const Float4 inv_len = 1.0f / render_detail::sqrt4(
          to_eye[0] * to_eye[0] + to_eye[1] * to_eye[1] + to_eye[2] * to_eye[2]);
      for (Float4& t : to_eye) t *= inv_len;
    }
    if (with_colors) {
      constexpr float kScale = 1.0f / 255.0f;
      base[0] = Float4{float(n[0]->color.r), float(n[1]->color.r), float(n[2]->color.r),
                       float(n[3]->color.r)} * kScale;
      base[1] = Float4{float(n[0]->color.g), float(n[1]->color.g), float(n[2]->color.g),
                       float(n[3]->color.g)} * kScale;
      base[2] = Float4{float(n[0]->color.b), float(n[1]->color.b), float(n[2]->color.b),
                       float(n[3]->color.b)} * kScale;
    } else {
      for (int c = 0; c < 3; ++c) base[c] = splat4(v.base_color[c]);
    }
    Int4 rgb[3];
    shader.shade4(normal, to_eye, base, rgb);
    const Int4 packed = rgb[0] | rgb[1] << 8 | rgb[2] << 16;
    if (lanes == render_detail::kLanes) {
      std::memcpy(&out.shaded[i], &packed, sizeof packed);
    } else {
      for (std::size_t k = 0; k < lanes; ++k) {
        out.shaded[i + k] = static_cast<std::uint32_t>(packed[k]);
      }
    }
  }
}

// The constants of one view (the shader must outlive them).
inline ViewConstants make_view_constants(const Shader& shader, const CameraFrame& camera,
                                         const RenderSettings& settings, bool with_discs) {
  ViewConstants v;
  v.shader = &shader;
  v.base_color = shader.base_color();
  v.eye = camera.eye;
  v.right = camera.right;
  v.up = camera.up;
  v.forward = camera.forward;
  v.focal_px = camera.focal_px;
  v.half_w = 0.5f * static_cast<float>(camera.width);
  v.half_h = 0.5f * static_cast<float>(camera.height);
  v.size_per_radius = 2.0f * camera.focal_px;
  v.threshold_px = settings.threshold_px;
  v.planes = camera.planes;
  v.with_discs = with_discs;
  v.cull_facing = !settings.two_sided;
  v.ortho = camera.ortho;
  return v;
}

}  // namespace pointillist::render_detail
