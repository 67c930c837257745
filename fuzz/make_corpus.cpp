// Writes the fuzzers' seed corpora: a few tiny valid files per reader, made with the project's
// own writers (PLY, .ptl v1 and v2, .qs) or written here by hand (LAS, OBJ, XYZ, and PLY headers
// the writer never produces). Usage: make_corpus <folder>; files go to <folder>/<harness>/.
// Deterministic (fixed seeds), so the corpora are the same on every build.
#include <zlib.h>

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "pointillist/core/progress.hpp"
#include "pointillist/core/thread_pool.hpp"
#include "pointillist/format/ptl.hpp"
#include "pointillist/format/ptl_v2.hpp"
#include "pointillist/lod/tree_features.hpp"
#include "pointillist/prep/radii.hpp"
#include "pointillist/scene/csg.hpp"
#include "pointillist/format/qs.hpp"
#include "pointillist/io/pfm.hpp"
#include "pointillist/io/ply.hpp"
#include "pointillist/lod/sphere_tree.hpp"
#include "pointillist/prep/prepare.hpp"
#include "pointillist/scene/analytic.hpp"

using namespace pointillist;
namespace fs = std::filesystem;

namespace {

void write_file(const fs::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out) throw std::runtime_error("cannot write " + path.string());
}

std::string read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_gzip(const fs::path& path, const std::string& bytes) {
  gzFile out = gzopen(path.c_str(), "wb9");
  if (!out || gzwrite(out, bytes.data(), static_cast<unsigned>(bytes.size())) !=
                  static_cast<int>(bytes.size()) ||
      gzclose(out) != Z_OK)
    throw std::runtime_error("cannot write " + path.string());
}

// Little-endian fields.
template <class T>
void put(std::string& out, T value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  out.append(bytes, sizeof(T));
}

void put_text(std::string& out, const std::string& text, std::size_t size) {
  std::string field = text.substr(0, size);
  field.resize(size, '\0');
  out += field;
}

// `count` samples of a sphere with exact normals, radii from prepare_splats and, when asked,
// colours from the position.
PointSet sphere_points(std::size_t count, bool colors, ThreadPool& pool) {
  SurfaceSamples s = sample_scene(sphere_scene(), count, 7);
  PointSet p = std::move(s.points);
  p.normals = std::move(s.true_normals);
  if (colors) {
    for (const Vec3f& x : p.positions)
      p.colors.push_back({static_cast<std::uint8_t>(128 + 120 * x.x),
                          static_cast<std::uint8_t>(128 + 120 * x.y),
                          static_cast<std::uint8_t>(128 + 120 * x.z)});
  }
  prepare_splats(p, pool, Progress::none(), {.normals = NormalSource::Keep});
  p.comments = {"made by fuzz/make_corpus"};
  return p;
}

// A 5x5-vertex grid of 32 triangles in the plane z = 0.
PointSet grid_mesh() {
  PointSet m;
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 5; ++x) m.positions.push_back({x * 0.25f, y * 0.25f, 0.1f * (x % 2)});
  for (std::uint32_t y = 0; y < 4; ++y) {
    for (std::uint32_t x = 0; x < 4; ++x) {
      const std::uint32_t i = y * 5 + x;
      m.triangles.push_back({i, i + 1, i + 6});
      m.triangles.push_back({i, i + 6, i + 5});
    }
  }
  m.comments = {"grid mesh"};
  return m;
}

void make_ply(const fs::path& dir, ThreadPool& pool) {
  PointSet p = sphere_points(24, true, pool);
  const PointSet mesh = grid_mesh();
  write_ply(dir / "ascii.ply", p, {.encoding = PlyEncoding::Ascii});
  write_ply(dir / "binary_le.ply", p, {.encoding = PlyEncoding::BinaryLittleEndian});
  write_ply(dir / "binary_be.ply", p, {.encoding = PlyEncoding::BinaryBigEndian});
  write_ply(dir / "mesh_le.ply", mesh, {.encoding = PlyEncoding::BinaryLittleEndian});
  write_ply(dir / "mesh_ascii.ply", mesh, {.encoding = PlyEncoding::Ascii});
  write_gzip(dir / "ascii.ply.gz", read_file(dir / "ascii.ply"));

  // What the writer never produces: other scalar types, diffuse colours, an unknown element,
  // a list with a ushort count, vertex_index, and comments between the elements.
  write_file(dir / "types_ascii.ply",
             "ply\nformat ascii 1.0\ncomment hand-written\nobj_info generator\n"
             "element vertex 4\nproperty double x\nproperty double y\nproperty double z\n"
             "property ushort diffuse_red\nproperty ushort diffuse_green\n"
             "property ushort diffuse_blue\nproperty float scale\n"
             "element face 2\nproperty list ushort uint vertex_index\nproperty uchar flags\n"
             "element edge 1\nproperty int vertex1\nproperty int vertex2\nend_header\n"
             "0 0 0 65535 0 0 0.1\n1 0 0 0 65535 0 0.1\n\n1 1 0 0 0 65535 0.1\n"
             "0 1 0 1000 2000 3000 0.1\n3 0 1 2 7\n4 0 1 2 3 1\n0 1\n");
  // Binary with a generic face element (two properties) and an unknown list element.
  std::string b =
      "ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\n"
      "property float y\nproperty float z\nproperty uchar red\nproperty uchar green\n"
      "property uchar blue\nproperty uchar alpha\nelement face 1\n"
      "property list uchar int vertex_indices\nproperty float quality\n"
      "element material 1\nproperty list int short values\nend_header\n";
  const float xyz[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  for (int i = 0; i < 4; ++i) {
    for (float v : xyz[i]) put(b, v);
    for (int c = 0; c < 4; ++c) put(b, static_cast<std::uint8_t>(60 * i + c));
  }
  put(b, std::uint8_t{4});
  for (std::int32_t i = 0; i < 4; ++i) put(b, i);
  put(b, 0.5f);
  put(b, std::int32_t{2});
  put(b, std::int16_t{-1});
  put(b, std::int16_t{1});
  write_file(dir / "generic_le.ply", b);
}

// LAS 1.2, point format 2 (colours), one variable-length record; and LAS 1.4, point format 7,
// with georeferenced coordinates (the reader moves them to a local origin) and the 64-bit count.
std::string las_file(int minor, int format, std::size_t count, double offset, bool vlr) {
  const int record_size = format == 2 ? 26 : 36;
  const int header_size = minor >= 4 ? 375 : 227;
  const std::string vlr_bytes = [&] {
    if (!vlr) return std::string();
    std::string v;
    put(v, std::uint16_t{0});
    put_text(v, "fuzz", 16);
    put(v, std::uint16_t{1234});
    put(v, std::uint16_t{8});
    put_text(v, "an opaque record", 32);
    v += "8 bytes!";
    return v;
  }();
  std::string h = "LASF";
  put(h, std::uint16_t{1});  // file source ID
  put(h, std::uint16_t{0});  // global encoding
  h.append(16, '\0');        // GUID
  put(h, std::uint8_t{1});
  put(h, static_cast<std::uint8_t>(minor));
  put_text(h, "FUZZ", 32);
  put_text(h, "make_corpus", 32);
  put(h, std::uint16_t{1});
  put(h, std::uint16_t{2025});
  put(h, static_cast<std::uint16_t>(header_size));
  put(h, static_cast<std::uint32_t>(header_size + vlr_bytes.size()));
  put(h, std::uint32_t{vlr ? 1u : 0u});
  put(h, static_cast<std::uint8_t>(format));
  put(h, static_cast<std::uint16_t>(record_size));
  put(h, static_cast<std::uint32_t>(count));
  for (int i = 0; i < 5; ++i) put(h, std::uint32_t{i == 0 ? static_cast<std::uint32_t>(count) : 0});
  for (double s : {0.01, 0.01, 0.001}) put(h, s);
  for (double o : {offset, offset * 2, 0.0}) put(h, o);
  for (double m : {offset + 10, offset, offset * 2 + 10, offset * 2, 1.0, 0.0}) put(h, m);
  if (minor >= 3) put(h, std::uint64_t{0});  // waveform data
  if (minor >= 4) {
    put(h, std::uint64_t{0});  // first extended VLR
    put(h, std::uint32_t{0});
    put(h, static_cast<std::uint64_t>(count));
    for (int i = 0; i < 15; ++i) put(h, std::uint64_t{i == 0 ? count : 0});
  }
  h += vlr_bytes;
  for (std::size_t i = 0; i < count; ++i) {
    const auto k = static_cast<std::int32_t>(i);
    put(h, k * 37 % 1000);
    put(h, k * 53 % 1000);
    put(h, k * 11 % 500);
    put(h, std::uint16_t{100});  // intensity
    if (format == 2) {
      put(h, std::uint8_t{0x11});  // return number, returns, flags
      put(h, std::uint8_t{2});     // classification
      put(h, std::int8_t{-5});     // scan angle rank
      put(h, std::uint8_t{0});     // user data
      put(h, std::uint16_t{1});    // point source
    } else {
      put(h, std::uint8_t{0x11});
      put(h, std::uint8_t{0});
      put(h, std::uint8_t{2});
      put(h, std::uint8_t{0});
      put(h, std::int16_t{-5});
      put(h, std::uint16_t{1});
      put(h, 1.5 * k);  // GPS time
    }
    put(h, static_cast<std::uint16_t>(k * 1800));
    put(h, static_cast<std::uint16_t>(65535 - k * 1800));
    put(h, static_cast<std::uint16_t>(k % 2 ? 255 : 0));
  }
  return h;
}

void make_las(const fs::path& dir) {
  write_file(dir / "v12_format2.las", las_file(2, 2, 32, 0.0, true));
  write_file(dir / "v14_format7.las", las_file(4, 7, 32, 512000.0, false));
}

void make_obj(const fs::path& dir) {
  write_file(dir / "cube.obj",
             "# a cube with every corner form\nmtllib cube.mtl\no cube\ng side\n"
             "v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 1 1 0 0 0 1\nv 0 1 0 1 1 0\n"
             "v 0 0 1 0 1 1\nv 1 0 1 1 0 1\nv 1 1 1 0.5 0.5 0.5\nv 0 1 1 0.2 0.4 0.6\n"
             "vt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 -1\nvn 0 0 1\nvn 0 -1 0\nusemtl grey\ns off\n"
             "f 1//1 4//1 3//1 2//1\nf 5/1/2 6/2/2 7/3/2 8/1/2\nf 1/1 2/2 6/3\nf -7 -6 -2\n"
             "f 4 3 7 8\nf 1 5 8 4\nl 1 2\np 3\n");
  write_file(dir / "points.obj",
             "v 1.5 2.5 -3 1.0\nv 100000.25 2 3\nv 4 5 6\nvn 0 1 0\nf 1//1 2//1 3//1\n"
             "f 3 2\n");
}

void make_xyz(const fs::path& dir) {
  std::string blank = "x y z r g b\n", csv = "//X,Y,Z,R,G,B\n", pts = "24\n",
              normals, large = "# large coordinates\n// and a C++ comment\n";
  for (int i = 0; i < 24; ++i) {
    const double x = i * 0.1, y = (i % 5) * 0.2, z = (i % 3) * 0.3;
    const std::string p = std::to_string(x) + " " + std::to_string(y) + " " + std::to_string(z);
    blank += p + " " + std::to_string(i * 10) + " 20 " + std::to_string(255 - i) + "\n";
    csv += std::to_string(x) + "," + std::to_string(y) + "," + std::to_string(z) + ",0.5," +
           std::to_string(i / 24.0) + ",1e-1\n";
    pts += p + " -1200 " + std::to_string(i) + " 100 200\n";
    normals += std::to_string(x) + ";" + std::to_string(y) + ";" + std::to_string(z) +
               ";0;-0.6;0.8\n";
    large += std::to_string(512000.5 + x) + "\t" + std::to_string(5403000.25 + y) + "\t" +
             std::to_string(z) + "\n";
  }
  write_file(dir / "colors.xyz", blank);
  write_file(dir / "cloudcompare.csv", csv);
  write_file(dir / "intensity.pts", pts);
  write_file(dir / "normals.txt", normals);
  write_file(dir / "large.xyz", large);
  write_gzip(dir / "colors.xyz.gz", blank);
}

void make_path(const fs::path& dir) {
  write_file(dir / "walk.path",
             "# a walk toward the wall, then past its end\nfov 40\n0 0.6 4   0 0.6 0\n"
             "0.5 0.6 2   0.5 0.6 -1\n3 1 1   -1 0.5 -2   0 1 0\n");
  write_file(dir / "close.path", "0 0.5 0.05  0 0.5 -3\n0 10 0.01  0 0 0  0 0 -1\n");
}

void make_models(const fs::path& root, ThreadPool& pool) {
  const PointSet small = sphere_points(40, true, pool);
  const PointSet plain = sphere_points(40, false, pool);
  const PointSet paged = sphere_points(600, false, pool);
  const SphereTree small_tree = build_sphere_tree(small, pool);
  const SphereTree plain_tree = build_sphere_tree(plain, pool);
  const SphereTree paged_tree = build_sphere_tree(paged, pool);

  write_ptl((root / "ptl_v1" / "colors.ptl").string(), small_tree, "seed: colors");
  write_ptl((root / "ptl_v1" / "plain.ptl").string(), plain_tree, "seed: plain");

  const fs::path v2 = root / "ptl_v2";
  write_ptl_v2((v2 / "colors.ptl").string(), small_tree, "seed: colors");
  write_ptl_v2((v2 / "eighths.ptl").string(), plain_tree, "seed: eighths",
               {.leaf_trim = quant::LeafTrim::Eighths});
  // About 900 nodes in 1 KiB pages: page 0 and a few child pages.
  write_ptl_v2((v2 / "pages.ptl").string(), paged_tree, "seed: pages", {.page_bytes = 1024});
  {
    // A small cube with its sharp features stored (surface ids, clipped leaves and planes).
    CsgScene cube = csg_scene("T1");
    cube.spacing = 0.3f;
    CsgSamples s = sample_csg(cube, SamplingMode::Jittered, 1);
    CloudRadiusOptions radius;
    radius.coverage = 1.0f;
    s.points.radii = cloud_radii(s.points.positions, pool, Progress::none(), radius);
    const SphereTree tree = build_sphere_tree(s.points, pool);
    const TreeFeatures features = compute_tree_features(tree.view(), pool);
    write_ptl_v2((v2 / "features.ptl").string(), tree, "seed: features", {.features = &features});
  }

  {
    // A small mesh with its faces kept (the hybrid mode's section).
    PointSet mesh = grid_mesh();
    prepare_splats(mesh, pool, Progress::none());
    std::vector<std::uint32_t> order;
    const SphereTree tree = build_sphere_tree(mesh, pool, Progress::none(), {}, &order);
    const auto faces = leaf_triangles(tree.view(), order, mesh.triangles);
    write_ptl_v2((v2 / "faces.ptl").string(), tree, "seed: faces",
                 {.page_bytes = 1024, .triangles = faces});
  }

  write_qs((root / "qs" / "colors.qs").string(), small);
  write_qs((root / "qs" / "mesh.qs").string(), grid_mesh(), {.write_comments = true});
  write_qs((root / "qs" / "plain.qs").string(), plain, {.write_comments = false});
}

// Depth images: a small one with the background's infinities, and a single pixel.
void make_pfm(const fs::path& dir) {
  const float inf = std::numeric_limits<float>::infinity();
  write_pfm((dir / "depth.pfm").string(), 3, 2, std::vector<float>{1.5f, 2.0f, inf, 0.25f, inf, 7.0f});
  write_pfm((dir / "one.pfm").string(), 1, 1, std::vector<float>{3.0f});
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: make_corpus <folder>\n");
    return 2;
  }
  try {
    const fs::path root = argv[1];
    for (const char* harness :
         {"ply", "las", "obj", "xyz", "qs", "ptl_v1", "ptl_v2", "path", "pfm"})
      fs::create_directories(root / harness);
    ThreadPool pool(1);
    make_ply(root / "ply", pool);
    make_las(root / "las");
    make_obj(root / "obj");
    make_xyz(root / "xyz");
    make_path(root / "path");
    make_pfm(root / "pfm");
    make_models(root, pool);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "make_corpus: %s\n", e.what());
    return 1;
  }
  return 0;
}
