// A mesh prepared by streaming its faces past its vertices' sums on disk (mesh_streamed.hpp)
// against the mesh read whole and prepared in memory (read_point_file + prepare_mesh_vertices,
// which walk the faces per vertex range), and against the torus's analytic normals. The files
// are written byte by byte here, with quads, a two-vertex face, an extra face property, faces in
// random order, big-endian and gzip variants; a cache of a few small pages makes most pages go
// out to disk and come back.
#include <gtest/gtest.h>
#include <zlib.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "mesh_streamed.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/core/thread_pool.hpp"
#include "pointillist/io/ply.hpp"
#include "pointillist/io/point_file.hpp"
#include "pointillist/io/point_stream.hpp"
#include "testing/testing.hpp"
#include "testing/torus_mesh.hpp"

namespace pointillist::chunking {
namespace {

using testing::TempDir;

constexpr std::uint32_t kRows = 60, kColumns = 40;

struct Layout {
  bool big_endian = false;
  bool gzip = false;
  bool shuffle = true;
  bool polygons = true;      // quads and a two-vertex face besides triangles
  bool extra_vertex = true;  // a vertex no face uses
  bool bad_index = false;    // the last face names a vertex that is not there
  bool truncate = false;     // the file stops inside the last face
};

template <class T>
void put(std::string& out, T value, bool big) {
  auto bytes = std::bit_cast<std::array<char, sizeof(T)>>(value);
  if (big) std::reverse(bytes.begin(), bytes.end());
  out.append(bytes.data(), bytes.size());
}

// The torus as a binary PLY: xyz and rgb, then faces as `list uchar int vertex_indices` and a
// `uchar flags` property.
std::string write_torus(const TempDir& dir, const Layout& l) {
  const PointSet m = testing::torus_mesh(kRows, kColumns);
  std::vector<std::vector<std::int32_t>> faces;
  for (std::size_t t = 0; t < m.triangles.size(); t += 2) {
    const auto& a = m.triangles[t];
    const auto& b = m.triangles[t + 1];
    // A grid square's triangles (i,j)(i,j+1)(i+1,j) and (i+1,j)(i,j+1)(i+1,j+1); every fourth
    // square is the quad (i+1,j)(i,j)(i,j+1)(i+1,j+1), which fans into the same two.
    if (l.polygons && t % 8 == 0) {
      faces.push_back({std::int32_t(a[2]), std::int32_t(a[0]), std::int32_t(a[1]),
                       std::int32_t(b[2])});
    } else {
      faces.push_back({std::int32_t(a[0]), std::int32_t(a[1]), std::int32_t(a[2])});
      faces.push_back({std::int32_t(b[0]), std::int32_t(b[1]), std::int32_t(b[2])});
    }
  }
  if (l.polygons) faces.push_back({0, 5});
  if (l.shuffle) std::shuffle(faces.begin(), faces.end(), std::mt19937(7));
  const std::uint32_t vertices = std::uint32_t(m.size()) + (l.extra_vertex ? 1 : 0);
  if (l.bad_index) faces.push_back({0, 1, std::int32_t(vertices)});
  std::string body;
  for (std::uint32_t i = 0; i < vertices; ++i) {
    const Vec3f p = i < m.size() ? m.positions[i] : Vec3f{5, 5, 5};
    const Rgb8 c = i < m.size() ? m.colors[i] : Rgb8{255, 0, 0};
    put(body, p.x, l.big_endian), put(body, p.y, l.big_endian), put(body, p.z, l.big_endian);
    body += char(c.r), body += char(c.g), body += char(c.b);
  }
  for (const auto& f : faces) {
    body += char(f.size());
    for (const std::int32_t v : f) put(body, v, l.big_endian);
    body += char(1);  // flags
  }
  if (l.truncate) body.resize(body.size() - 3);
  const std::string head = std::string("ply\nformat ") +
                           (l.big_endian ? "binary_big_endian" : "binary_little_endian") +
                           " 1.0\nelement vertex " + std::to_string(vertices) +
                           "\nproperty float x\nproperty float y\nproperty float z\n"
                           "property uchar red\nproperty uchar green\nproperty uchar blue\n"
                           "element face " + std::to_string(faces.size()) +
                           "\nproperty list uchar int vertex_indices\nproperty uchar flags\n"
                           "end_header\n";
  const std::string path = dir.file(l.gzip ? "torus.ply.gz" : "torus.ply");
  if (l.gzip) {
    gzFile gz = gzopen(path.c_str(), "wb");
    gzwrite(gz, head.data(), unsigned(head.size()));
    gzwrite(gz, body.data(), unsigned(body.size()));
    gzclose(gz);
  } else {
    std::ofstream(path, std::ios::binary) << head << body;
  }
  return path;
}

PointSet streamed(const TempDir& dir, const std::string& input, const PrepareOptions& prepare,
                  const StreamedMeshOptions& options) {
  const std::string out = dir.file("streamed.ply");
  EXPECT_TRUE(prepare_mesh_streamed(input, out, dir.file("sums"), prepare, Progress::none(),
                                    options));
  return read_point_file(out);
}

PointSet in_memory(const std::string& input, const PrepareOptions& prepare) {
  PointSet m = read_point_file(input);
  ThreadPool pool(2);
  prepare_mesh_vertices(m, pool, Progress::none(), prepare);
  return m;
}

void expect_same(const PointSet& a, const PointSet& b) {
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(a.normals.size(), b.normals.size());
  ASSERT_EQ(a.radii.size(), b.radii.size());
  ASSERT_EQ(a.colors.size(), b.colors.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(std::memcmp(&a.positions[i], &b.positions[i], sizeof(Vec3f)), 0) << i;
    if (!a.normals.empty()) {
      ASSERT_EQ(std::memcmp(&a.normals[i], &b.normals[i], sizeof(Vec3f)), 0) << i;
    }
    if (!a.radii.empty()) {
      ASSERT_EQ(a.radii[i], b.radii[i]) << i;
    }
    if (!a.colors.empty()) {
      ASSERT_EQ(a.colors[i].r, b.colors[i].r) << i;
    }
  }
}

// Small pages and only four of them: the 2,400 vertices fill 150 pages, and shuffled faces touch
// them in any order, so pages are written out and read back all the time.
constexpr StreamedMeshOptions kTinyCache{.cache_bytes = 0, .page_vertices = 16};

TEST(StreamedMesh, GivesTheNormalsAndRadiiOfTheMeshReadWholeBitForBit) {
  for (const Layout l : {Layout{}, Layout{.big_endian = true, .gzip = true},
                         Layout{.shuffle = false, .polygons = false}}) {
    TempDir dir;
    const std::string input = write_torus(dir, l);
    const PointSet whole = in_memory(input, {});
    for (const StreamedMeshOptions& o : {StreamedMeshOptions{}, kTinyCache}) {
      SCOPED_TRACE("big endian " + std::to_string(l.big_endian) + ", shuffled " +
                   std::to_string(l.shuffle) + ", pages of " + std::to_string(o.page_vertices));
      const PointSet s = streamed(dir, input, {}, o);
      EXPECT_EQ(s.size(), std::size_t{kRows} * kColumns);  // the unused vertex is dropped
      expect_same(s, whole);
    }
    // The file's normals kept, or none for PCA: the same choices as in memory.
    const PointSet pca = streamed(dir, input, {.normals = NormalSource::Pca}, kTinyCache);
    EXPECT_TRUE(pca.normals.empty());
    expect_same(pca, in_memory(input, {.normals = NormalSource::Pca}));
  }
}

TEST(StreamedMesh, NormalsFollowTheTorusAndRadiiCoverItsTriangles) {
  TempDir dir;
  const std::string input = write_torus(dir, {.polygons = false});
  const PointSet s = streamed(dir, input, {}, kTinyCache);
  ASSERT_EQ(s.size(), std::size_t{kRows} * kColumns);
  const PointSet m = testing::torus_mesh(kRows, kColumns);
  double worst = 0;
  for (std::uint32_t i = 0; i < kRows; ++i) {
    for (std::uint32_t j = 0; j < kColumns; ++j) {
      const double u = 2 * kPi * i / kRows, v = 2 * kPi * j / kColumns;
      const Vec3f n{float(std::cos(v) * std::cos(u)), float(std::sin(v)),
                    float(std::cos(v) * std::sin(u))};
      const std::size_t k = std::size_t{i} * kColumns + j;
      worst = std::max(worst, std::acos(std::clamp(double(dot(s.normals[k], n)), -1.0, 1.0)));
    }
  }
  EXPECT_LT(worst * 180 / kPi, 5.0);  // a 60 x 40 grid: faces 6 and 9 degrees apart
  // Every corner's radius reaches its triangles' circumcentres (or longest edges' midpoints):
  // at least half of every incident edge.
  for (const auto& t : m.triangles) {
    for (int e = 0; e < 3; ++e) {
      const std::uint32_t a = t[e], b = t[(e + 1) % 3];
      const float half = 0.5f * distance(m.positions[a], m.positions[b]);
      EXPECT_GE(s.radii[a], half * 0.9999f);
      EXPECT_GE(s.radii[b], half * 0.9999f);
    }
  }
}

TEST(StreamedMesh, SmallWindowsCutFacesAndStillGiveEveryTriangle) {
  for (const Layout l : {Layout{}, Layout{.big_endian = true, .gzip = true}}) {
    TempDir dir;
    const std::string input = write_torus(dir, l);
    const PointSet whole = read_point_file(input);
    for (const std::size_t window : {16, 61, 1000}) {
      const auto faces = open_face_stream(input, window);
      ASSERT_NE(faces, nullptr);
      std::vector<std::array<std::uint32_t, 3>> all, part;
      std::size_t reads = 0;
      while (faces->read(part)) {
        all.insert(all.end(), part.begin(), part.end());
        ++reads;
      }
      EXPECT_GT(reads, 10u) << window;
      EXPECT_EQ(faces->faces_done(), faces->face_count());
      EXPECT_TRUE(all == whole.triangles) << "window " << window;
    }
  }
}

TEST(StreamedMesh, BadFacesAreNamedAndNothingIsWritten) {
  for (const Layout l : {Layout{.bad_index = true}, Layout{.truncate = true}}) {
    TempDir dir;
    const std::string input = write_torus(dir, l);
    try {
      (void)prepare_mesh_streamed(input, dir.file("out.ply"), dir.file("sums"), {},
                                  Progress::none(), kTinyCache);
      FAIL() << "a broken face was accepted";
    } catch (const FormatError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(input), std::string::npos) << what;
      EXPECT_NE(what.find(": byte "), std::string::npos) << what;
      EXPECT_NE(what.find(l.bad_index ? "out of range" : "file ends early"), std::string::npos)
          << what;
    }
    EXPECT_FALSE(std::filesystem::exists(dir.file("out.ply")));
    // The same in windows that cut the faces.
    const auto faces = open_face_stream(input, 61);
    std::vector<std::array<std::uint32_t, 3>> part;
    EXPECT_THROW(while (faces->read(part)) {}, FormatError);
  }
}

TEST(StreamedMesh, AsciiPlyStreamsItsFacesToo) {
  TempDir dir;
  PointSet m = testing::torus_mesh(kRows, kColumns);
  m.positions.push_back({5, 5, 5});  // used by no face
  m.colors.push_back({255, 0, 0});
  std::shuffle(m.triangles.begin(), m.triangles.end(), std::mt19937(3));
  const std::string ascii = dir.file("torus.ply");
  write_ply(ascii, m, {.encoding = PlyEncoding::Ascii});
  const PointSet s = streamed(dir, ascii, {}, kTinyCache);
  EXPECT_EQ(s.size(), std::size_t{kRows} * kColumns);
  expect_same(s, in_memory(ascii, {}));
  // A face naming a vertex that is not there, on the file's last line: named by line.
  std::ofstream(ascii, std::ios::app) << "3 0 1 99999\n";
  {
    std::string text;
    std::ifstream in(ascii);
    text.assign(std::istreambuf_iterator<char>(in), {});
    const std::string from = "element face " + std::to_string(m.triangles.size()) + "\n";
    const std::string to = "element face " + std::to_string(m.triangles.size() + 1) + "\n";
    text.replace(text.find(from), from.size(), to);
    std::ofstream(ascii, std::ios::trunc) << text;
  }
  try {
    (void)prepare_mesh_streamed(ascii, dir.file("out.ply"), dir.file("sums"), {},
                                Progress::none(), kTinyCache);
    FAIL() << "a face out of range was accepted";
  } catch (const FormatError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(": line "), std::string::npos) << what;
    EXPECT_NE(what.find("out of range"), std::string::npos) << what;
  }
  EXPECT_FALSE(std::filesystem::exists(dir.file("out.ply")));
}

// The torus as OBJ: a face that names vertices defined after it (first line), v lines with
// colours, vn lines for every third vertex, faces with v, v//vn and v/vt/vn corners, relative
// (negative) indices and quads, and a vertex no face uses.
std::string write_torus_obj(const TempDir& dir, bool normals) {
  const PointSet m = testing::torus_mesh(kRows, kColumns);
  const std::size_t n = m.size();
  std::ostringstream f;
  f.precision(9);
  const auto corner = [&](std::uint32_t v, bool relative) {
    std::string c = relative ? std::to_string(std::int64_t(v) - std::int64_t(n + 1))
                             : std::to_string(v + 1);
    if (normals && v % 3 == 0) c += (v % 2 ? "/1/" : "//") + std::to_string(v / 3 + 1);
    return c;
  };
  const auto face_line = [&](std::size_t t, bool relative) {
    const auto& a = m.triangles[t];
    return "f " + corner(a[0], relative) + " " + corner(a[1], relative) + " " +
           corner(a[2], relative) + "\n";
  };
  f << "# a torus\n" << face_line(1, false);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3f p = m.positions[i];
    f << "v " << p.x << " " << p.y << " " << p.z << " " << m.colors[i].r / 255.0 << " "
      << m.colors[i].g / 255.0 << " " << m.colors[i].b / 255.0 << "\n";
  }
  f << "v 5 5 5 1 0 0\nvt 0.5 0.5\n";
  if (normals) {
    for (std::size_t i = 0; i < n; i += 3) {
      const Vec3f p = m.positions[i];
      f << "vn " << p.x << " " << p.y * 3 << " " << p.z << "\n";  // not unit length
    }
  }
  for (std::size_t t = 0; t < m.triangles.size(); t += 2) {
    if (t % 8 == 4) {  // a quad: the square's two triangles
      const auto& a = m.triangles[t];
      const auto& b = m.triangles[t + 1];
      f << "f " << corner(a[2], false) << " " << corner(a[0], false) << " "
        << corner(a[1], false) << " " << corner(b[2], false) << "\n";
      continue;
    }
    f << face_line(t, t % 6 == 2);
    if (t + 1 != 1) f << face_line(t + 1, false);  // (triangle 1 is the first line)
  }
  const std::string path = dir.file(normals ? "torus-vn.obj" : "torus.obj");
  std::ofstream(path) << f.str();
  return path;
}

TEST(StreamedMesh, ObjStreamsItsFacesAndItsFileNormals) {
  for (const bool normals : {false, true}) {
    SCOPED_TRACE(normals ? "with vn" : "without vn");
    TempDir dir;
    const std::string obj = write_torus_obj(dir, normals);
    const PointSet whole = in_memory(obj, {});
    ASSERT_EQ(whole.normals.size(), whole.size());
    for (const StreamedMeshOptions& o : {StreamedMeshOptions{}, kTinyCache}) {
      const PointSet s = streamed(dir, obj, {}, o);
      EXPECT_EQ(s.size(), std::size_t{kRows} * kColumns);
      expect_same(s, whole);
    }
    expect_same(streamed(dir, obj, {.normals = NormalSource::Mesh}, kTinyCache),
                in_memory(obj, {.normals = NormalSource::Mesh}));
  }
  // A corner naming a vertex the file does not have: named by line.
  TempDir dir;
  const std::string bad = dir.file("bad.obj");
  std::ofstream(bad) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 7\n";
  try {
    (void)prepare_mesh_streamed(bad, dir.file("out.ply"), dir.file("sums"), {},
                                Progress::none(), kTinyCache);
    FAIL() << "a corner out of range was accepted";
  } catch (const FormatError& e) {
    EXPECT_NE(std::string(e.what()).find(bad + ": line 5: f: vertex index 7 out of range"),
              std::string::npos)
        << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(dir.file("out.ply")));
}

TEST(StreamedMesh, FilesWithoutFacesHaveNoFaceStream) {
  TempDir dir;
  const std::string obj = dir.file("points.obj");
  std::ofstream(obj) << "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  EXPECT_EQ(open_face_stream(obj), nullptr);
  PointSet m = testing::torus_mesh(6, 5);
  m.triangles.clear();  // a file without faces has no face stream
  const std::string cloud = dir.file("cloud.ply");
  write_ply(cloud, m);
  EXPECT_EQ(open_face_stream(cloud), nullptr);
}

}  // namespace
}  // namespace pointillist::chunking
