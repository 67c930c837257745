// Mesh vertex normals and mesh radii against analytic normals and hand-computed values.
#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "pointillist/prep/normals.hpp"
#include "pointillist/prep/radii.hpp"

using namespace pointillist;

namespace {

using Triangle = std::array<std::uint32_t, 3>;

struct Mesh {
  std::vector<Vec3f> positions;
  std::vector<Triangle> triangles;
};

// Icosahedron subdivided `levels` times, vertices pushed onto the unit sphere; faces wound
// counter-clockwise seen from outside.
Mesh icosphere(int levels) {
  const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
  Mesh m;
  for (Vec3f v : {Vec3f{-1, t, 0}, Vec3f{1, t, 0}, Vec3f{-1, -t, 0}, Vec3f{1, -t, 0},
                  Vec3f{0, -1, t}, Vec3f{0, 1, t}, Vec3f{0, -1, -t}, Vec3f{0, 1, -t},
                  Vec3f{t, 0, -1}, Vec3f{t, 0, 1}, Vec3f{-t, 0, -1}, Vec3f{-t, 0, 1}}) {
    m.positions.push_back(normalized(v));
  }
  m.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                 {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                 {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                 {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> midpoint;
    const auto mid = [&](std::uint32_t a, std::uint32_t b) {
      const auto key = std::minmax(a, b);
      auto it = midpoint.find(key);
      if (it != midpoint.end()) return it->second;
      m.positions.push_back(normalized(m.positions[a] + m.positions[b]));
      const auto index = static_cast<std::uint32_t>(m.positions.size() - 1);
      midpoint.emplace(key, index);
      return index;
    };
    std::vector<Triangle> finer;
    for (const Triangle& f : m.triangles) {
      const std::uint32_t a = mid(f[0], f[1]), b = mid(f[1], f[2]), c = mid(f[2], f[0]);
      finer.insert(finer.end(), {{f[0], a, c}, {f[1], b, a}, {f[2], c, b}, {a, b, c}});
    }
    m.triangles = std::move(finer);
  }
  return m;
}

double angle_deg(Vec3f a, Vec3f b) {
  return std::acos(std::clamp(double(dot(normalized(a), normalized(b))), -1.0, 1.0)) * 180.0 /
         3.14159265358979323846;
}

}  // namespace

TEST(MeshVertexNormals, IcosphereNormalsAreRadial) {
  const Mesh m = icosphere(4);  // 2562 vertices, 5120 faces
  ThreadPool pool(2);
  const std::vector<Vec3f> n = mesh_vertex_normals(m.positions, m.triangles, pool);
  ASSERT_EQ(n.size(), m.positions.size());
  double worst = 0;
  for (std::size_t i = 0; i < n.size(); ++i) {
    EXPECT_NEAR(length(n[i]), 1.0f, 1e-5f);
    worst = std::max(worst, angle_deg(n[i], m.positions[i]));  // unit sphere: normal = position
  }
  // Faces of this mesh span about 4°; the irregular rings around the 12 original vertices
  // tilt the area-weighted sum by a fraction of that.
  EXPECT_LT(worst, 0.5);
}

TEST(MeshVertexNormals, WeightsFacesByArea) {
  // Vertex 0 is shared by a triangle of doubled area 4 facing +z and one of doubled area 1
  // facing +x: the normal is (1, 0, 4)/√17, not the unweighted (1, 0, 1)/√2.
  const std::vector<Vec3f> p = {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {0, 1, 0}, {0, 0, 1}, {9, 9, 9}};
  const std::vector<Triangle> t = {{0, 1, 2}, {0, 3, 4}};
  ThreadPool pool(1);
  const std::vector<Vec3f> n = mesh_vertex_normals(p, t, pool);
  const float s = 1.0f / std::sqrt(17.0f);
  EXPECT_NEAR(n[0].x, s, 1e-6f);
  EXPECT_NEAR(n[0].y, 0.0f, 1e-6f);
  EXPECT_NEAR(n[0].z, 4 * s, 1e-6f);
  EXPECT_TRUE((n[1] == Vec3f{0, 0, 1}));
  EXPECT_TRUE((n[3] == Vec3f{1, 0, 0}));
  // Vertex 5 is in no face.
  EXPECT_TRUE((n[5] == Vec3f{0, 0, 1}));
}

TEST(MeshVertexNormals, FollowTheWinding) {
  const std::vector<Vec3f> p = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  const std::vector<Triangle> clockwise = {{0, 2, 1}};
  ThreadPool pool(1);
  for (const Vec3f& v : mesh_vertex_normals(p, clockwise, pool)) {
    EXPECT_TRUE((v == Vec3f{0, 0, -1}));
  }
}

TEST(MeshVertexNormals, SameBitsForAnyThreadCount) {
  Mesh m = icosphere(5);
  // Perturb so sums depend on their order.
  for (std::size_t i = 0; i < m.positions.size(); ++i) {
    m.positions[i] *= 1.0f + 0.01f * std::sin(float(i) * 12.9898f);
  }
  ThreadPool one(1), three(3);
  const auto a = mesh_vertex_normals(m.positions, m.triangles, one);
  const auto b = mesh_vertex_normals(m.positions, m.triangles, three);
  for (std::size_t i = 0; i < a.size(); ++i) ASSERT_TRUE(a[i] == b[i]) << "vertex " << i;
}

TEST(MeshRadii, SmallestEnclosingCircleOfIncidentTrianglesTimesScale) {
  // A 3 × 4 rectangle split along its diagonal (two right triangles: radius = half the diagonal,
  // 2.5), an equilateral triangle of side 2 sharing vertex 3 (circumradius 2/√3), an obtuse
  // triangle (half its longest edge, 5) and an unused vertex.
  const float s3 = std::sqrt(3.0f);
  const std::vector<Vec3f> p = {{0, 0, 0},  {3, 0, 0},           {0, 4, 0},   {3, 4, 0},
                                {5, 4, 0},  {4, 4 + s3, 0},      {7, 7, 7},   {20, 0, 0},
                                {30, 0, 0}, {25, 1, 0}};
  const std::vector<Triangle> t = {{0, 1, 2}, {1, 3, 2}, {3, 4, 5}, {7, 8, 9}};
  ThreadPool pool(2);
  const std::vector<float> r1 = mesh_radii(p, t, 1.0f, pool);
  const std::vector<float> expected = {2.5f, 2.5f, 2.5f, 2.5f, 2 / s3, 2 / s3, 0.0f, 5.0f, 5.0f, 5.0f};
  ASSERT_EQ(r1.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) EXPECT_NEAR(r1[i], expected[i], 1e-5f) << i;
  const std::vector<float> r2 = mesh_radii(p, t, 2.0f, pool);
  for (std::size_t i = 0; i < expected.size(); ++i) EXPECT_NEAR(r2[i], 2 * expected[i], 2e-5f) << i;
}

TEST(MeshRadii, DiscsAtTheCornersCoverEveryTriangle) {
  // The property the rule exists for: every point of every triangle lies within the radius of at
  // least one of its corners. Checked on a perturbed icosphere by sampling each triangle densely.
  Mesh m = icosphere(3);
  for (std::size_t i = 0; i < m.positions.size(); ++i) {
    m.positions[i] *= 1.0f + 0.05f * std::sin(float(i) * 12.9898f);
  }
  ThreadPool pool(2);
  const std::vector<float> r = mesh_radii(m.positions, m.triangles, 1.0f, pool);
  for (const Triangle& f : m.triangles) {
    const Vec3f a = m.positions[f[0]], b = m.positions[f[1]], c = m.positions[f[2]];
    for (int i = 0; i <= 20; ++i) {
      for (int j = 0; i + j <= 20; ++j) {
        const float u = float(i) / 20, v = float(j) / 20;
        const Vec3f q = a + (b - a) * u + (c - a) * v;
        const bool covered = distance(q, a) <= r[f[0]] * 1.0001f ||
                             distance(q, b) <= r[f[1]] * 1.0001f ||
                             distance(q, c) <= r[f[2]] * 1.0001f;
        ASSERT_TRUE(covered) << "triangle " << f[0] << "," << f[1] << "," << f[2];
      }
    }
  }
}
