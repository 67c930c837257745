// Test inputs for the lod and format suites, made in code with fixed seeds.
#pragma once

#include <cmath>
#include <cstdint>
#include <random>

#include "pointillist/core/point_set.hpp"

namespace pointillist::testing {

// `count` points uniformly on a sphere (centre `center`, radius `sphere_radius`) with exact
// outward normals and every splat radius equal to `splat_radius`; colors from the position when
// `with_colors`.
inline PointSet sphere_points(std::size_t count, std::uint64_t seed, bool with_colors = false,
                              float sphere_radius = 1.0f, float splat_radius = 0.01f,
                              Vec3f center = {0, 0, 0}) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<float> gauss(0.0f, 1.0f);
  PointSet s;
  s.positions.reserve(count);
  for (std::size_t i = 0; i < count; ++i) {
    Vec3f d;
    do {
      d = {gauss(rng), gauss(rng), gauss(rng)};
    } while (length(d) < 1e-3f);
    const Vec3f n = d / length(d);
    s.positions.push_back(center + n * sphere_radius);
    s.normals.push_back(n);
    s.radii.push_back(splat_radius);
    if (with_colors) {
      s.colors.push_back({static_cast<std::uint8_t>(127.5f + 127.0f * n.x),
                          static_cast<std::uint8_t>(127.5f + 127.0f * n.y),
                          static_cast<std::uint8_t>(rng() & 0xff)});
    }
  }
  return s;
}

// `count` points uniformly in the box [0, size.x] x [0, size.y] x [0, size.z], random unit
// normals, random radii in [0.001, 0.01].
inline PointSet box_points(std::size_t count, std::uint64_t seed, Vec3f size) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::normal_distribution<float> gauss(0.0f, 1.0f);
  PointSet s;
  for (std::size_t i = 0; i < count; ++i) {
    s.positions.push_back({u(rng) * size.x, u(rng) * size.y, u(rng) * size.z});
    Vec3f d{gauss(rng), gauss(rng), gauss(rng)};
    s.normals.push_back(d / std::max(length(d), 1e-6f));
    s.radii.push_back(0.001f + 0.009f * u(rng));
  }
  return s;
}

}  // namespace pointillist::testing
