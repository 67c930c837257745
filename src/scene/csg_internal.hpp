// Shared by the CSG scene files: face samples before trimming, the jittered or random rectangle
// sampler, and the geometry of the open surfaces (quads and the open crease), which have no
// inside and so no ray interval.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <random>
#include <vector>

#include "pointillist/scene/csg.hpp"

namespace pointillist::csg_detail {

// A face sample before trimming: position and local face.
struct FaceSample {
  Vec3f x;
  std::uint32_t face;
};

// Samples of a w × h rectangle in the plane spanned by axes (u, v): J mode a jittered grid of
// about area/spacing² cells, R mode as many uniform draws.
template <class Emit>
void sample_rectangle(float w, float h, float spacing, SamplingMode mode, std::mt19937_64& rng,
                      Emit&& emit) {
  const int nu = std::max(1, static_cast<int>(std::lround(w / spacing)));
  const int nv = std::max(1, static_cast<int>(std::lround(h / spacing)));
  std::uniform_real_distribution<float> unit(0.0f, 1.0f), jitter(-0.25f, 0.25f);
  const float su = w / nu, sv = h / nv;
  for (int i = 0; i < nu; ++i) {
    for (int j = 0; j < nv; ++j) {
      if (mode == SamplingMode::Jittered) {
        emit((i + 0.5f + jitter(rng)) * su, (j + 0.5f + jitter(rng)) * sv);
      } else {
        emit(unit(rng) * w, unit(rng) * h);
      }
    }
  }
}

// Open surfaces: PrimitiveKind::Quad and PrimitiveKind::Crease.
bool is_open(const Primitive& p);
std::uint32_t open_face_count(const Primitive& p);
void sample_open(const Primitive& p, float spacing, SamplingMode mode, std::mt19937_64& rng,
                 std::vector<FaceSample>& out);
Vec3f open_face_normal(const Primitive& p, std::uint32_t face, Vec3f x);
struct OpenHit {
  double t;
  std::uint32_t face;
};
// The nearest crossing of origin + t·dir with t > 0.
std::optional<OpenHit> ray_open(const Primitive& p, Vec3f origin, Vec3f dir);
void extend_open_bounds(const Primitive& p, Aabb& box);
bool open_face_is_planar(const Primitive& p, std::uint32_t face);
// Whether x (on the face's surface) lies within the face's extent.
bool open_face_contains(const Primitive& p, std::uint32_t face, Vec3f x);

}  // namespace pointillist::csg_detail
