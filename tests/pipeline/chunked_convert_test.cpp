// The chunked conversion: a cloud forced into many small chunks gives the model the conversion in
// one piece gives (the one-piece file is the oracle: its decoded hierarchy, its renders, its
// normals), leaves nothing behind, and says what it cannot do.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>

#include "pointillist/core/error.hpp"
#include "pointillist/eval/image_compare.hpp"
#include "pointillist/format/ptl_v2.hpp"
#include "pointillist/io/ply.hpp"
#include "pointillist/pipeline/convert.hpp"
#include "pointillist/render/render.hpp"
#include "pointillist/scene/analytic.hpp"
#include "io/io_test_support.hpp"
#include "io/las_builder.hpp"
#include "testing/testing.hpp"
#include "testing/torus_mesh.hpp"

namespace pointillist {
namespace {

using testing::TempDir;
using testing::torus_mesh;

// The demo scene (sphere, torus, cube) sampled without normals or radii, with smooth colours.
std::string write_cloud(const TempDir& dir, std::size_t count, const std::string& name) {
  PointSet p = sample_scene(demo_scene(), count, 11).points;
  for (const Vec3f& x : p.positions) {
    p.colors.push_back({std::uint8_t(128 + 60 * x.x), std::uint8_t(128 + 60 * x.y),
                        std::uint8_t(128 + 60 * x.z)});
  }
  const std::string path = dir.file(name);
  write_ply(path, p);
  return path;
}

struct Converted {
  SphereTree whole, parts;
  ConvertResult parts_result;
};

Converted convert_both(const TempDir& dir, const std::string& input,
                       const ConvertOptions& parts_options) {
  ThreadPool pool(2);
  const std::string whole = dir.file("whole.ptl"), parts = dir.file("parts.ptl");
  const std::vector<std::string> inputs{input};
  const ConvertResult w = convert(inputs, whole, {}, pool, Progress::none());
  EXPECT_EQ(w.chunks, 0u);
  Converted c;
  c.parts_result = convert(inputs, parts, parts_options, pool, Progress::none());
  c.whole = PtlV2File::open(whole)->decode_all();
  c.parts = PtlV2File::open(parts)->decode_all();
  return c;
}

// Nodes of the chunked conversion's hierarchy that differ from the one-piece one's (same count).
std::size_t differing_nodes(const Converted& c) {
  std::size_t differing = 0;
  for (std::size_t i = 0; i < c.whole.nodes.size(); ++i) {
    differing += std::memcmp(&c.whole.nodes[i], &c.parts.nodes[i], sizeof(SphereNode)) != 0;
  }
  return differing;
}

// The renders at three views: at least 40 dB apart, splat counts within 1%.
void expect_renders_alike(const Converted& c) {
  ThreadPool pool(2);
  for (const float az : {0.0f, 120.0f, 240.0f}) {
    const Camera cam = orbit_camera(c.whole.view_sphere,
                                    {.azimuth_deg = az, .elevation_deg = 25, .width = 400,
                                     .height = 300});
    Frame fa, fb;
    render(c.whole.view(), cam, {}, pool, fa);
    render(c.parts.view(), cam, {}, pool, fb);
    EXPECT_GE(psnr_rgb({fa.width, fa.height, fa.color}, {fb.width, fb.height, fb.color}), 40.0)
        << "azimuth " << az;
    EXPECT_NEAR(double(fb.stats.splats), double(fa.stats.splats), 0.01 * double(fa.stats.splats));
  }
}

TEST(ChunkedConvert, ManySmallChunksGiveTheOnePieceHierarchy) {
  TempDir dir;
  const std::string input = write_cloud(dir, 60000, "scene.ply");
  const Converted c = convert_both(dir, input, {.chunk_points = 2000});
  EXPECT_GE(c.parts_result.chunks, 16u);
  EXPECT_GT(c.parts_result.halo_points, 0u);
  ASSERT_EQ(c.parts.nodes.size(), c.whole.nodes.size());
  EXPECT_EQ(c.parts.leaf_count, c.whole.leaf_count);
  EXPECT_EQ(c.parts.depth, c.whole.depth);
  EXPECT_EQ(std::memcmp(&c.parts.bounds, &c.whole.bounds, sizeof(Aabb)), 0);
  std::size_t differing = 0, normals_apart = 0;
  double worst_deg = 0;
  for (std::size_t i = 0; i < c.whole.nodes.size(); ++i) {
    const SphereNode& a = c.whole.nodes[i];
    const SphereNode& b = c.parts.nodes[i];
    if (std::memcmp(&a, &b, sizeof(SphereNode)) != 0) ++differing;
    if (a.child_count == 0) {
      const double deg = std::acos(std::clamp(double(dot(a.normal, b.normal)), -1.0, 1.0)) *
                         180.0 / 3.14159265358979;
      worst_deg = std::max(worst_deg, deg);
      if (deg > 1.0) ++normals_apart;
    }
  }
  std::printf("[chunked] %zu chunks, %llu halo points, %zu of %zu nodes differ, worst leaf "
              "normal %.3f deg\n",
              c.parts_result.chunks, (unsigned long long)c.parts_result.halo_points, differing,
              c.whole.nodes.size(), worst_deg);
  // The chunks are subtrees of the one-piece hierarchy, prepared with enough halo: the same
  // nodes, bit for bit.
  EXPECT_EQ(differing, 0u);
  EXPECT_EQ(normals_apart, 0u);
  expect_renders_alike(c);
}

// A budget too small for the plan's positions: the plan works from a file of them (radix
// selection, here with a few digits per split) and still cuts the one-piece hierarchy's subtrees.
TEST(ChunkedConvert, APlanOnDiskGivesTheOnePieceHierarchy) {
  TempDir dir;
  const std::string input = write_cloud(dir, 30000, "scene.ply");
  const Converted c = convert_both(dir, input, {.memory_budget = 100000, .chunk_points = 2000});
  EXPECT_GE(c.parts_result.chunks, 8u);
  ASSERT_EQ(c.parts.nodes.size(), c.whole.nodes.size());
  EXPECT_EQ(differing_nodes(c), 0u);
  EXPECT_FALSE(std::filesystem::exists(dir.file("parts.ptl.chunks")));
}

// A text file (gzip, georeferenced coordinates, colours) is streamed in chunks: the same
// hierarchy as the conversion in one piece.
TEST(ChunkedConvert, AGzipTextFileGivesTheOnePieceHierarchy) {
  TempDir dir;
  const PointSet p = sample_scene(demo_scene(), 20000, 5).points;
  std::string text = "// X Y Z R G B\n";
  char line[160];
  for (const Vec3f& x : p.positions) {
    std::snprintf(line, sizeof line, "%.4f %.4f %.4f %d %d %d\n", 651000.0 + x.x * 10,
                  5400000.0 + x.y * 10, 100.0 + x.z * 10, int(128 + 60 * x.x),
                  int(128 + 60 * x.y), int(128 + 60 * x.z));
    text += line;
  }
  const std::string input = dir.file("scan.xyz.gz");
  testing::write_file(input, testing::gzip(text));
  const Converted c = convert_both(dir, input, {.chunk_points = 1500});
  EXPECT_GE(c.parts_result.chunks, 8u);
  ASSERT_EQ(c.parts.nodes.size(), c.whole.nodes.size());
  EXPECT_EQ(differing_nodes(c), 0u);
  EXPECT_TRUE(c.parts.has_colors);
}

// A point cloud written as OBJ (`v x y z r g b` lines) streams into chunks and gives the
// hierarchy of the conversion in one piece (which reads the file whole).
TEST(ChunkedConvert, AnObjPointCloudGivesTheOnePieceHierarchy) {
  TempDir dir;
  const PointSet p = sample_scene(demo_scene(), 20000, 6).points;
  std::string text = "# a scan\n";
  char line[160];
  for (const Vec3f& x : p.positions) {
    std::snprintf(line, sizeof line, "v %.5f %.5f %.5f %.3f %.3f %.3f\n", x.x, x.y, x.z,
                  0.5 + 0.2 * x.x, 0.5 + 0.2 * x.y, 0.5 + 0.2 * x.z);
    text += line;
  }
  const std::string input = dir.file("scan.obj");
  testing::write_file(input, text);
  const Converted c = convert_both(dir, input, {.chunk_points = 1500});
  EXPECT_GE(c.parts_result.chunks, 8u);
  ASSERT_EQ(c.parts.nodes.size(), c.whole.nodes.size());
  EXPECT_EQ(differing_nodes(c), 0u);
  EXPECT_TRUE(c.parts.has_colors);
}

// gzip ASCII and gzip binary PLY inputs stream into chunks (a window of lines; decompressed as
// read) and give the hierarchy of the conversion in one piece, node for node.
TEST(ChunkedConvert, GzipAsciiAndBinaryPlyGiveTheOnePieceHierarchy) {
  TempDir dir;
  PointSet p = sample_scene(demo_scene(), 20000, 6).points;
  for (const Vec3f& x : p.positions) {
    p.colors.push_back({std::uint8_t(128 + 60 * x.x), std::uint8_t(128 + 60 * x.y),
                        std::uint8_t(128 + 60 * x.z)});
  }
  for (const PlyEncoding encoding : {PlyEncoding::Ascii, PlyEncoding::BinaryBigEndian}) {
    const std::string plain = dir.file("scan.ply"), input = dir.file("scan.ply.gz");
    write_ply(plain, p, {.encoding = encoding});
    testing::write_file(input, testing::gzip(testing::read_file(plain)));
    const Converted c = convert_both(dir, input, {.chunk_points = 1500});
    EXPECT_GE(c.parts_result.chunks, 8u);
    ASSERT_EQ(c.parts.nodes.size(), c.whole.nodes.size());
    EXPECT_EQ(differing_nodes(c), 0u);
    EXPECT_TRUE(c.parts.has_colors);
  }
}

// Two georeferenced LAS tiles of one survey, side by side, one without colours: merged by the
// same rules in chunks as in one piece.
TEST(ChunkedConvert, MergesTilesAsTheConversionInOnePieceDoes) {
  TempDir dir;
  testing::LasSpec spec{.format = 3, .scale = {0.001, 0.001, 0.001},
                        .offset = {500000, 5400000, 10}};
  std::vector<testing::LasPoint> a, b;
  for (std::int32_t i = 0; i < 15000; ++i) {
    const double t = i * 0.013;
    const auto x = std::int32_t(20000 * std::cos(t) + (i % 97) * 3);
    const auto y = std::int32_t(20000 * std::sin(t) + (i % 89) * 3);
    a.push_back({x, y, (i * 37) % 5000, std::uint16_t(i * 5), std::uint16_t(i * 3), 900});
    b.push_back({x + 45000, y + 12000, (i * 41) % 5000, 0, 0, 0});
  }
  const std::string la = dir.file("a.las"), lb = dir.file("b.las");
  testing::write_file(la, testing::build_las(spec, a));
  spec.format = 1;  // no colours
  testing::write_file(lb, testing::build_las(spec, b));
  const std::vector<std::string> inputs{la, lb};
  ThreadPool pool(2);
  const std::string whole = dir.file("whole.ptl"), parts = dir.file("parts.ptl");
  const ConvertResult w = convert(inputs, whole, {}, pool, Progress::none());
  const ConvertResult p = convert(inputs, parts, {.chunk_points = 3000}, pool, Progress::none());
  EXPECT_EQ(w.chunks, 0u);
  EXPECT_GE(p.chunks, 8u);
  ASSERT_EQ(w.warnings.size(), 1u);  // b.las has no colours
  EXPECT_EQ(p.warnings, w.warnings);
  const auto fw = PtlV2File::open(whole), fp = PtlV2File::open(parts);
  EXPECT_EQ(fp->origin(), fw->origin());
  EXPECT_EQ(fp->up(), fw->up());
  EXPECT_EQ(fp->metadata(), fw->metadata());
  const SphereTree tw = fw->decode_all(), tp = fp->decode_all();
  ASSERT_EQ(tp.nodes.size(), tw.nodes.size());
  EXPECT_EQ(std::memcmp(tp.nodes.data(), tw.nodes.data(), tw.nodes.size() * sizeof(SphereNode)), 0);
}

TEST(ChunkedConvert, ABadPointStopsItWithoutLeavingAnything) {
  TempDir dir;
  PointSet p = sample_scene(demo_scene(), 5000, 3).points;
  p.positions[4321].z = std::numeric_limits<float>::infinity();
  const std::string input = dir.file("bad.ply");
  write_ply(input, p);
  ThreadPool pool(2);
  const std::vector<std::string> inputs{input};
  try {
    convert(inputs, dir.file("out.ptl"), {.chunk_points = 1000}, pool, Progress::none());
    FAIL() << "converted a file with an infinite coordinate";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("bad.ply"), std::string::npos) << m;
    EXPECT_NE(m.find("4321"), std::string::npos) << m;
  }
  EXPECT_FALSE(std::filesystem::exists(dir.file("out.ptl")));
  EXPECT_FALSE(std::filesystem::exists(dir.file("out.ptl.chunks")));
}

TEST(ChunkedConvert, LeavesNoChunkFolderAndReplacesALeftOverOne) {
  TempDir dir;
  const std::string input = write_cloud(dir, 8000, "scene.ply");
  const std::string out = dir.file("out.ptl");
  // A folder left by a conversion that was killed.
  std::filesystem::create_directory(out + ".chunks");
  std::ofstream(out + ".chunks/chunk-00000.pts") << "stale";
  ThreadPool pool(2);
  const std::vector<std::string> inputs{input};
  convert(inputs, out, {.chunk_points = 1000}, pool, Progress::none());
  EXPECT_TRUE(std::filesystem::exists(out));
  EXPECT_FALSE(std::filesystem::exists(out + ".chunks"));
  std::size_t files = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir.path())) {
    (void)e;
    ++files;
  }
  EXPECT_EQ(files, 2u);  // the input and the output
}

TEST(ChunkedConvert, DropsTheOutliersTheConversionInOnePieceDrops) {
  // The demo scene and 40 strays 0.02 to 0.04 scene diagonals above its surfaces (along the
  // exact normal), spread over the scene and so over many chunks: each chunk judges its points
  // with a wider halo, and the conversion then plans its chunks without them, so it drops what
  // the one-piece conversion drops and builds its hierarchy.
  TempDir dir;
  const SurfaceSamples samples = sample_scene(demo_scene(), 60000, 12);
  PointSet p = samples.points;
  Aabb box;
  for (const Vec3f& x : p.positions) box.extend(x);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const std::size_t surface = p.size();
  for (std::size_t i = 0; i < 40; ++i) {
    const std::size_t at = i * (surface / 40);
    const float height = (0.2f + 0.2f * u(rng)) * length(box.hi - box.lo) / 10.0f;
    p.positions.push_back(p.positions[at] + samples.true_normals[at] * height);
  }
  p.normals.clear();
  p.radii.clear();
  const std::string input = dir.file("strays.ply");
  write_ply(input, p);
  ConvertOptions whole_options, parts_options{.chunk_points = 2000};
  whole_options.prepare.drop_outliers = parts_options.prepare.drop_outliers = true;
  ThreadPool pool(2);
  const std::vector<std::string> inputs{input};
  const ConvertResult w =
      convert(inputs, dir.file("whole.ptl"), whole_options, pool, Progress::none());
  const ConvertResult c =
      convert(inputs, dir.file("parts.ptl"), parts_options, pool, Progress::none());
  ASSERT_EQ(w.chunks, 0u);
  ASSERT_GE(c.chunks, 16u);
  std::printf("[chunked outliers] one piece dropped %zu, %zu chunks dropped %zu of %zu points\n",
              w.input_points - w.output_points, c.chunks, c.input_points - c.output_points,
              c.input_points);
  EXPECT_GE(w.input_points - w.output_points, 40u);  // the strays, and maybe a few more
  EXPECT_LE(w.input_points - w.output_points, 40u + surface / 200);
  EXPECT_EQ(c.output_points, w.output_points);
  const SphereTree whole = PtlV2File::open(dir.file("whole.ptl"))->decode_all();
  const SphereTree parts = PtlV2File::open(dir.file("parts.ptl"))->decode_all();
  EXPECT_EQ(parts.leaf_count, whole.leaf_count);
  // The same points planned alike: the one-piece hierarchy, bit for bit.
  ASSERT_EQ(parts.nodes.size(), whole.nodes.size());
  EXPECT_EQ(differing_nodes({whole, parts, c}), 0u);
  for (const float az : {0.0f, 120.0f, 240.0f}) {
    const Camera cam = orbit_camera(whole.view_sphere, {.azimuth_deg = az, .elevation_deg = 25,
                                                        .width = 400, .height = 300});
    Frame fa, fb;
    render(whole.view(), cam, {}, pool, fa);
    render(parts.view(), cam, {}, pool, fb);
    EXPECT_GE(psnr_rgb({fa.width, fa.height, fa.color}, {fb.width, fb.height, fb.color}), 40.0)
        << "azimuth " << az;
    EXPECT_NEAR(double(fb.stats.splats), double(fa.stats.splats), 0.01 * double(fa.stats.splats));
  }
}

TEST(ChunkedConvert, AMeshInManySmallChunksGivesTheOnePieceModel) {
  TempDir dir;
  PointSet mesh = torus_mesh(240, 120);
  mesh.positions.push_back({5, 5, 5});  // used by no face: dropped, as in one piece
  mesh.colors.push_back({255, 0, 0});
  const std::string input = dir.file("torus.ply");
  write_ply(input, mesh);
  const Converted c = convert_both(dir, input, {.chunk_points = 2000});
  EXPECT_GE(c.parts_result.chunks, 8u);
  EXPECT_EQ(c.parts_result.output_points, 240u * 120u);
  ASSERT_EQ(c.parts.leaf_count, c.whole.leaf_count);
  ASSERT_EQ(c.parts.nodes.size(), c.whole.nodes.size());
  // Normals and radii come from the faces as in one piece (the normals normalized once more);
  // the chunks are subtrees of the one-piece hierarchy.
  double worst_deg = 0;
  for (std::size_t i = 0; i < c.whole.nodes.size(); ++i) {
    const SphereNode& a = c.whole.nodes[i];
    const SphereNode& b = c.parts.nodes[i];
    EXPECT_EQ(a.radius, b.radius) << i;
    EXPECT_EQ(std::memcmp(&a.center, &b.center, sizeof a.center), 0) << i;
    if (a.child_count == 0) {
      worst_deg = std::max(worst_deg, std::acos(std::clamp(double(dot(a.normal, b.normal)),
                                                           -1.0, 1.0)) * 180.0 / kPi);
    }
  }
  EXPECT_LT(worst_deg, 1.0);
  std::printf("[chunked mesh] %zu chunks, %zu of %zu nodes differ, worst leaf normal %.4f deg\n",
              c.parts_result.chunks, differing_nodes(c), c.whole.nodes.size(), worst_deg);
  expect_renders_alike(c);
  // The faces are not kept, and the result says so.
  ASSERT_FALSE(c.parts_result.warnings.empty());
  EXPECT_NE(c.parts_result.warnings[0].find("faces are not kept"), std::string::npos);
}

TEST(ChunkedConvert, AMeshLargerThanTheBudgetStreamsItsFacesAndABrokenOneLeavesNothing) {
  TempDir dir;
  PointSet mesh = torus_mesh(60, 40);
  const std::string input = dir.file("torus.ply");
  write_ply(input, mesh);
  ThreadPool pool(1);
  const std::vector<std::string> inputs{input};
  // A budget under what reading the mesh whole takes (about 56 bytes a vertex and the file): a
  // binary PLY streams its faces, and gives the one-piece model's splats.
  {
    const Converted c = convert_both(dir, input, {.memory_budget = 60 * 40 * 30});
    EXPECT_GE(c.parts_result.chunks, 2u);
    EXPECT_EQ(c.parts.leaf_count, c.whole.leaf_count);
    expect_renders_alike(c);
    EXPECT_FALSE(std::filesystem::exists(dir.file("parts.ptl.chunks")));
  }
  // An OBJ mesh streams its faces too.
  const std::string obj = dir.file("torus.obj");
  {
    std::ofstream f(obj);
    f.precision(9);
    for (const Vec3f& p : mesh.positions) f << "v " << p.x << " " << p.y << " " << p.z << "\n";
    for (const auto& t : mesh.triangles) {
      f << "f " << t[0] + 1 << " " << t[1] + 1 << " " << t[2] + 1 << "\n";
    }
  }
  const ConvertResult r = convert(std::vector<std::string>{obj}, dir.file("a.ptl"),
                                  {.memory_budget = 60 * 40 * 30}, pool, Progress::none());
  EXPECT_GE(r.chunks, 2u);
  EXPECT_EQ(PtlV2File::open(dir.file("a.ptl"))->decode_all().leaf_count, 60u * 40u);
  std::filesystem::remove(dir.file("a.ptl"));
  EXPECT_FALSE(std::filesystem::exists(dir.file("a.ptl")));
  EXPECT_FALSE(std::filesystem::exists(dir.file("a.ptl.chunks")));
  // A face naming a vertex that is not there (written by hand: write_ply refuses it).
  {
    std::ofstream f(input, std::ios::binary | std::ios::trunc);
    f << "ply\nformat ascii 1.0\nelement vertex " << mesh.size()
      << "\nproperty float x\nproperty float y\nproperty float z\nelement face "
      << mesh.triangles.size() + 1 << "\nproperty list uchar int vertex_indices\nend_header\n";
    for (const Vec3f& p : mesh.positions) f << p.x << " " << p.y << " " << p.z << "\n";
    for (const auto& t : mesh.triangles) f << "3 " << t[0] << " " << t[1] << " " << t[2] << "\n";
    f << "3 0 1 99999\n";
  }
  EXPECT_THROW(convert(inputs, dir.file("a.ptl"), {.chunk_points = 500}, pool, Progress::none()),
               Error);
  EXPECT_FALSE(std::filesystem::exists(dir.file("a.ptl")));
  EXPECT_FALSE(std::filesystem::exists(dir.file("a.ptl.chunks")));
}

TEST(ChunkedConvert, SaysWhatItCannotDoYet) {
  TempDir dir;
  const std::string input = write_cloud(dir, 4000, "scene.ply");
  ThreadPool pool(1);
  const std::vector<std::string> inputs{input};
  // A budget too small for the input in one piece, for an output that is only written whole.
  try {
    convert(inputs, dir.file("a.ply"), {.memory_budget = 100000}, pool, Progress::none());
    FAIL() << "a .ply over the budget was written";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("--memory"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(dir.file("a.ptl")));
  EXPECT_FALSE(std::filesystem::exists(dir.file("a.ply")));
  // The same budget for .ptl converts in chunks.
  const ConvertResult r =
      convert(inputs, dir.file("b.ptl"), {.memory_budget = 500000}, pool, Progress::none());
  EXPECT_GT(r.chunks, 1u);
}

}  // namespace
}  // namespace pointillist
