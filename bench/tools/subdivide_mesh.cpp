// subdivide_mesh IN OUT.ply LEVELS: each triangle of a mesh split into four at its edges'
// midpoints (a midpoint shared by the two triangles of an edge), LEVELS times; new vertices
// follow the old ones in order of first use. Written as binary big-endian PLY, which QSplat 1.0's
// qsplat_make reads. Two levels of the Stanford dragon (437,645 vertices) give the
// 7-million-vertex mesh of the conversion benchmark (bench/qsplat.sh); not part of the program.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <unordered_map>
#include <vector>

#include "pointillist/core/error.hpp"
#include "pointillist/io/ply.hpp"
#include "pointillist/io/point_file.hpp"

namespace {

using pointillist::PointSet;
using Triangle = std::array<std::uint32_t, 3>;

void subdivide(PointSet& mesh) {
  std::unordered_map<std::uint64_t, std::uint32_t> midpoint;
  midpoint.reserve(mesh.triangles.size() * 2);
  const auto middle = [&](std::uint32_t a, std::uint32_t b) {
    const std::uint64_t key = a < b ? std::uint64_t{a} << 32 | b : std::uint64_t{b} << 32 | a;
    const auto [at, added] = midpoint.try_emplace(key, std::uint32_t(mesh.positions.size()));
    if (added) {
      const auto& p = mesh.positions[a];
      const auto& q = mesh.positions[b];
      mesh.positions.push_back({(p.x + q.x) / 2, (p.y + q.y) / 2, (p.z + q.z) / 2});
      if (!mesh.colors.empty()) {
        const auto& c = mesh.colors[a];
        const auto& d = mesh.colors[b];
        mesh.colors.push_back({std::uint8_t((c.r + d.r) / 2), std::uint8_t((c.g + d.g) / 2),
                               std::uint8_t((c.b + d.b) / 2)});
      }
    }
    return at->second;
  };
  std::vector<Triangle> out;
  out.reserve(mesh.triangles.size() * 4);
  for (const Triangle& t : mesh.triangles) {
    const std::uint32_t ab = middle(t[0], t[1]), bc = middle(t[1], t[2]), ca = middle(t[2], t[0]);
    out.push_back({t[0], ab, ca});
    out.push_back({ab, t[1], bc});
    out.push_back({ca, bc, t[2]});
    out.push_back({ab, bc, ca});
  }
  mesh.triangles = std::move(out);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: subdivide_mesh IN OUT.ply LEVELS\n");
    return 2;
  }
  try {
    PointSet mesh = pointillist::read_point_file(argv[1]);
    if (mesh.triangles.empty()) {
      std::fprintf(stderr, "subdivide_mesh: %s has no faces\n", argv[1]);
      return 1;
    }
    mesh.normals.clear();
    mesh.radii.clear();
    for (int level = std::atoi(argv[3]); level > 0; --level) subdivide(mesh);
    for (auto& p : mesh.positions) {  // back to the file's own coordinates
      p = {float(p.x + mesh.origin[0]), float(p.y + mesh.origin[1]), float(p.z + mesh.origin[2])};
    }
    mesh.origin = {};
    pointillist::write_ply(argv[2], mesh, {.encoding = pointillist::PlyEncoding::BinaryBigEndian});
    std::printf("%zu vertices, %zu faces -> %s\n", mesh.positions.size(), mesh.triangles.size(),
                argv[2]);
  } catch (const pointillist::Error& e) {
    std::fprintf(stderr, "subdivide_mesh: %s\n", e.what());
    return 1;
  }
  return 0;
}
