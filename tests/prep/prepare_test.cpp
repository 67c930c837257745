// prepare_splats: choice of sources, mesh clean-up, radii rules and error messages.
#include "pointillist/prep/prepare.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "pointillist/core/error.hpp"
#include "pointillist/core/morton.hpp"
#include "pointillist/scene/analytic.hpp"

using namespace pointillist;

namespace {

// A 3 × 4 rectangle in the z = 0 plane as two counter-clockwise triangles, with two vertices no
// face uses (1 and 4 of the 6), each vertex with its own color.
PointSet rectangle_with_strays() {
  PointSet p;
  p.positions = {{0, 0, 0}, {50, 50, 50}, {3, 0, 0}, {0, 4, 0}, {-9, 0, 1}, {3, 4, 0}};
  p.colors = {{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {3, 3, 3}, {4, 4, 4}, {5, 5, 5}};
  p.triangles = {{0, 2, 3}, {2, 5, 3}};
  p.comments = {"made by hand"};
  return p;
}

// The message of the Error `fn` throws (fails the test when it throws nothing).
template <class Fn>
std::string error_message(Fn&& fn) {
  try {
    fn();
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected an Error";
  return {};
}

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

}  // namespace

TEST(PrepareSplats, DropsUnreferencedMeshVerticesAndRemapsFaces) {
  PointSet p = rectangle_with_strays();
  ThreadPool pool(2);
  prepare_splats(p, pool, Progress::none());
  EXPECT_EQ(p.positions, (std::vector<Vec3f>{{0, 0, 0}, {3, 0, 0}, {0, 4, 0}, {3, 4, 0}}));
  ASSERT_EQ(p.colors.size(), 4u);
  EXPECT_EQ(p.colors[1], (Rgb8{2, 2, 2}));
  EXPECT_EQ(p.colors[3], (Rgb8{5, 5, 5}));
  EXPECT_EQ(p.triangles, (std::vector<std::array<std::uint32_t, 3>>{{0, 1, 2}, {1, 3, 2}}));
  // Auto on a mesh without normals: face normals (+z) and QSplat radii (the smallest circle around
  // each incident triangle: both are right triangles with hypotenuse 5).
  ASSERT_EQ(p.normals.size(), 4u);
  for (const Vec3f& n : p.normals) EXPECT_TRUE((n == Vec3f{0, 0, 1}));
  EXPECT_EQ(p.radii, (std::vector<float>{2.5f, 2.5f, 2.5f, 2.5f}));
  EXPECT_EQ(p.comments, (std::vector<std::string>{"made by hand"}));
}

TEST(PrepareSplats, KeepsFileNormalsNormalizedAndFileRadiiScaled) {
  PointSet p = rectangle_with_strays();
  p.normals = {{0, 0, 2}, {1, 0, 0}, {0, 3, 0}, {0, 0, 5}, {1, 0, 0}, {0, 0, 0}};
  p.radii = {1, 2, 3, 4, 5, 6};
  ThreadPool pool(1);
  prepare_splats(p, pool, Progress::none(), {.radius_scale = 0.5f});
  // Vertices 1 and 4 are dropped; a zero normal becomes (0, 0, 1).
  EXPECT_EQ(p.normals, (std::vector<Vec3f>{{0, 0, 1}, {0, 1, 0}, {0, 0, 1}, {0, 0, 1}}));
  EXPECT_EQ(p.radii, (std::vector<float>{0.5f, 1.5f, 2.0f, 3.0f}));
}

TEST(PrepareSplats, MeshSourceOverridesFileNormals) {
  PointSet p = rectangle_with_strays();
  p.normals.assign(6, Vec3f{1, 0, 0});
  ThreadPool pool(1);
  prepare_splats(p, pool, Progress::none(), {.normals = NormalSource::Mesh});
  for (const Vec3f& n : p.normals) EXPECT_TRUE((n == Vec3f{0, 0, 1}));
}

TEST(PrepareSplats, PointCloudKeepsEveryPointAndGetsPcaNormalsAndCloudRadii) {
  const SurfaceSamples s = sample_scene(sphere_scene(2.0f), 3000, 31);
  PointSet p = s.points;
  ThreadPool pool(2);
  prepare_splats(p, pool, Progress::none(), {.radius_scale = 2.0f, .coverage = 1.5f});
  ASSERT_EQ(p.size(), 3000u);
  EXPECT_EQ(p.positions, s.points.positions);
  ASSERT_EQ(p.normals.size(), 3000u);
  ASSERT_EQ(p.radii.size(), 3000u);
  for (std::size_t i = 0; i < p.size(); ++i) {
    EXPECT_GT(dot(p.normals[i], s.true_normals[i]), 0.99f) << "point " << i;
  }
  // Radii: brute-force mean distance to the 5 nearest, × coverage × scale.
  for (std::size_t i = 0; i < p.size(); i += 97) {
    std::vector<float> d;
    for (std::size_t j = 0; j < p.size(); ++j) {
      if (j != i) d.push_back(distance(p.positions[i], p.positions[j]));
    }
    std::partial_sort(d.begin(), d.begin() + 5, d.end());
    const float mean = (d[0] + d[1] + d[2] + d[3] + d[4]) / 5.0f;
    EXPECT_NEAR(p.radii[i], mean * 1.5f * 2.0f, 1e-5f) << "point " << i;
  }
}

TEST(PrepareSplats, HandsOverTheMortonOrderOfItsNeighbourSearch) {
  // A cloud (PCA normals and radii), also after outliers are dropped: the Morton order of the
  // points it returns. A mesh (no neighbour search): none.
  const SurfaceSamples s = sample_scene(sphere_scene(2.0f), 3000, 32);
  ThreadPool pool(2);
  for (const bool drop : {false, true}) {
    PointSet p = s.points;
    p.positions.push_back({40, 40, 40});  // far from the sphere: an outlier
    std::vector<std::uint32_t> morton{7};
    prepare_splats(p, pool, Progress::none(), {.drop_outliers = drop, .morton_order = &morton});
    ASSERT_EQ(p.size(), drop ? 3000u : 3001u);
    EXPECT_EQ(morton, morton_order(p.positions, pool)) << (drop ? "outliers dropped" : "kept");
  }
  PointSet mesh = rectangle_with_strays();
  std::vector<std::uint32_t> morton{7};
  prepare_splats(mesh, pool, Progress::none(), {.morton_order = &morton});
  EXPECT_EQ(morton, std::vector<std::uint32_t>{7});
}

TEST(PrepareSplats, PcaOnAMeshKeepsMeshRadii) {
  // A finely triangulated flat grid: PCA normals are ±z, radii still come from the edges.
  PointSet p;
  for (int y = 0; y < 10; ++y) {
    for (int x = 0; x < 10; ++x) p.positions.push_back({float(x), float(y), 0});
  }
  for (std::uint32_t y = 0; y < 9; ++y) {
    for (std::uint32_t x = 0; x < 9; ++x) {
      const std::uint32_t i = y * 10 + x;
      p.triangles.push_back({i, i + 1, i + 10});
      p.triangles.push_back({i + 1, i + 11, i + 10});
    }
  }
  ThreadPool pool(1);
  prepare_splats(p, pool, Progress::none(), {.normals = NormalSource::Pca});
  for (const Vec3f& n : p.normals) EXPECT_NEAR(std::abs(n.z), 1.0f, 1e-6f);
  // Every triangle is a right isosceles one with a √2 hypotenuse: its smallest enclosing circle
  // has radius √2/2, and every vertex is in at least one triangle.
  for (std::size_t i = 0; i < 100; ++i) {
    EXPECT_FLOAT_EQ(p.radii[i], 0.5f * std::sqrt(2.0f)) << "vertex " << i;
  }
}

TEST(PrepareSplats, ExplainsImpossibleNormalSources) {
  ThreadPool pool(1);
  PointSet cloud;
  cloud.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
  std::string m = error_message([&] {
    PointSet p = cloud;
    prepare_splats(p, pool, Progress::none(),
                   {.normals = NormalSource::Keep, .input_name = "scan.ply"});
  });
  EXPECT_TRUE(contains(m, "--normals keep: scan.ply has no normals")) << m;
  EXPECT_TRUE(contains(m, "nx/ny/nz")) << m;
  EXPECT_TRUE(contains(m, "use --normals auto or pca")) << m;

  m = error_message([&] {
    PointSet p = cloud;
    prepare_splats(p, pool, Progress::none(),
                   {.normals = NormalSource::Mesh, .input_name = "scan.ply"});
  });
  EXPECT_TRUE(contains(m, "--normals mesh: scan.ply has no faces")) << m;

  m = error_message([&] {
    PointSet p;
    p.positions = {{0, 0, 0}, {1, 0, 0}};
    prepare_splats(p, pool, Progress::none(), {.input_name = "two.ply"});
  });
  EXPECT_TRUE(contains(m, "two.ply: 2 points are too few")) << m;
  EXPECT_TRUE(contains(m, "at least 3")) << m;
}

TEST(PrepareSplats, ExplainsBrokenInput) {
  ThreadPool pool(1);
  std::string m = error_message([&] {
    PointSet p;
    prepare_splats(p, pool, Progress::none(), {.input_name = "empty.ply"});
  });
  EXPECT_TRUE(contains(m, "empty.ply: has no points")) << m;

  m = error_message([&] {
    PointSet p = rectangle_with_strays();
    p.triangles.push_back({0, 2, 6});
    prepare_splats(p, pool, Progress::none(), {.input_name = "bad.ply"});
  });
  EXPECT_TRUE(contains(m, "bad.ply: face 2 refers to vertex 6, but there are only 6 vertices"))
      << m;

  m = error_message([&] {
    PointSet p = rectangle_with_strays();
    p.positions[3].y = std::nanf("");
    prepare_splats(p, pool, Progress::none(), {.input_name = "nan.ply"});
  });
  EXPECT_TRUE(contains(m, "nan.ply: vertex 3 has a non-finite position")) << m;

  m = error_message([&] {
    PointSet p = rectangle_with_strays();
    p.radii = {1, 2};
    prepare_splats(p, pool, Progress::none(), {.input_name = "short.ply"});
  });
  EXPECT_TRUE(contains(m, "short.ply: 2 radii for 6 points")) << m;
}

TEST(PrepareSplats, RejectsBadOptions) {
  ThreadPool pool(1);
  PointSet p = rectangle_with_strays();
  EXPECT_THROW(prepare_splats(p, pool, Progress::none(), {.k = 2}), OptionError);
  EXPECT_THROW(prepare_splats(p, pool, Progress::none(), {.radius_scale = 0.0f}), OptionError);
  EXPECT_THROW(prepare_splats(p, pool, Progress::none(), {.coverage = -1.0f}), OptionError);
  EXPECT_THROW(prepare_splats(p, pool, Progress::none(), {.radius_scale = std::nanf("")}),
               OptionError);
}

TEST(PrepareSplats, ReportsProgressPhases) {
  struct Recorder final : Progress {
    std::vector<std::string> phases;
    void begin_phase(std::string_view name, std::uint64_t) override { phases.emplace_back(name); }
    void advance(std::uint64_t) override {}
    void end_phase() override {}
  };
  ThreadPool pool(1);
  Recorder mesh_progress;
  PointSet mesh = rectangle_with_strays();
  prepare_splats(mesh, pool, mesh_progress);
  EXPECT_EQ(mesh_progress.phases, (std::vector<std::string>{"normals", "radii"}));
  Recorder cloud_progress;
  PointSet cloud = sample_scene(sphere_scene(), 500, 3).points;
  prepare_splats(cloud, pool, cloud_progress);
  EXPECT_EQ(cloud_progress.phases,
            (std::vector<std::string>{"neighbours", "normals", "orientation", "radii"}));
}
