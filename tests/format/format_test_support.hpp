// Helpers of the format tests: file bytes, little-endian fields, and hierarchies of the demo
// scene's samples.
#pragma once

#include <cmath>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "pointillist/core/point_set.hpp"
#include "pointillist/core/progress.hpp"
#include "pointillist/core/thread_pool.hpp"
#include "pointillist/lod/sphere_tree.hpp"
#include "pointillist/prep/prepare.hpp"
#include "pointillist/scene/analytic.hpp"

namespace pointillist::format_test {

using Bytes = std::vector<std::uint8_t>;

inline Bytes read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

inline void write_bytes(const std::string& path, const Bytes& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

inline std::uint32_t get_u32(const Bytes& b, std::size_t at) {
  std::uint32_t v = 0;
  for (std::size_t i = 0; i < 4; ++i) v |= std::uint32_t{b.at(at + i)} << (8 * i);
  return v;
}
inline std::uint64_t get_u64(const Bytes& b, std::size_t at) {
  return get_u32(b, at) | std::uint64_t{get_u32(b, at + 4)} << 32;
}
inline void put_u32(Bytes& b, std::size_t at, std::uint32_t v) {
  for (std::size_t i = 0; i < 4; ++i) b.at(at + i) = std::uint8_t(v >> (8 * i));
}

// Samples of the demo scene (sphere, torus, cube) with exact normals, radii from prepare_splats
// (5-nearest-neighbour spacing), colours from the position when asked.
inline PointSet scene_points(std::size_t count, std::uint64_t seed, bool colors,
                      const AnalyticScene& scene = demo_scene()) {
  SurfaceSamples s = sample_scene(scene, count, seed);
  PointSet p = std::move(s.points);
  p.normals = std::move(s.true_normals);
  if (colors) {
    for (const Vec3f& x : p.positions) {
      p.colors.push_back({std::uint8_t(int(std::abs(x.x) * 97) % 256),
                          std::uint8_t(int(std::abs(x.y) * 131) % 256),
                          std::uint8_t(int(std::abs(x.z) * 53) % 256)});
    }
  }
  ThreadPool pool(2);
  prepare_splats(p, pool, Progress::none(), {.normals = NormalSource::Keep});
  return p;
}

inline SphereTree scene_tree(std::size_t count, std::uint64_t seed, bool colors) {
  ThreadPool pool(2);
  return build_sphere_tree(scene_points(count, seed, colors), pool);
}

}  // namespace pointillist::format_test
