// ground_plane OUT.ply SIZE SPACING [--mesh]: the ground of the hybrid benchmark (bench/hybrid.sh,
// spec §3.3): a SIZE × SIZE square on y = 0 centred on the origin, either sampled on a grid of
// SPACING (points with normal +y) or, with --mesh, as its
// two triangles (four vertices, same colours at the corners). Binary PLY; not part of the program.
#include <cstdio>
#include <cstdlib>
#include <string>

#include "pointillist/io/ply.hpp"

int main(int argc, char** argv) {
  using namespace pointillist;
  if (argc < 4) {
    std::fprintf(stderr, "usage: ground_plane OUT.ply SIZE SPACING [--mesh]\n");
    return 2;
  }
  const float size = std::strtof(argv[2], nullptr), spacing = std::strtof(argv[3], nullptr);
  const bool mesh = argc > 4 && std::string(argv[4]) == "--mesh";
  PointSet p;
  const float h = 0.5f * size;
  if (mesh) {
    p.positions = {{-h, 0, -h}, {h, 0, -h}, {h, 0, h}, {-h, 0, h}};
    p.triangles = {{0, 2, 1}, {0, 3, 2}};  // counter-clockwise seen from above (+y)
    p.normals.assign(4, Vec3f{0, 1, 0});
    p.colors.assign(4, Rgb8{150, 140, 120});
  } else {
    const auto n = static_cast<std::size_t>(size / spacing);
    p.positions.reserve(n * n);
    for (std::size_t j = 0; j < n; ++j) {
      for (std::size_t i = 0; i < n; ++i) {
        const float x = -h + (static_cast<float>(i) + 0.5f) * spacing;
        const float z = -h + (static_cast<float>(j) + 0.5f) * spacing;
        p.positions.push_back({x, 0, z});
      }
    }
    p.normals.assign(p.positions.size(), Vec3f{0, 1, 0});
    p.colors.assign(p.positions.size(), Rgb8{150, 140, 120});  // one colour: splats vs triangles differ only in shape
  }
  write_ply(argv[1], p, {.encoding = PlyEncoding::BinaryLittleEndian});
  return 0;
}
