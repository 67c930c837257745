// Hybrid point/polygon rendering (lod/hybrid_lod.hpp): the rule against its definition computed
// by brute force, the selection against a brute-force scan of every triangle, no suppressed
// vertex without its triangles, and images on a zoom into a tessellated sphere against the mesh
// reference (no holes, at least the pure points' PSNR).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <set>

#include "pointillist/core/error.hpp"
#include "pointillist/eval/image_compare.hpp"
#include "pointillist/lod/hybrid_lod.hpp"
#include "pointillist/lod/sequential_point_tree.hpp"
#include "pointillist/lod/sphere_tree.hpp"
#include "pointillist/prep/normals.hpp"
#include "pointillist/prep/radii.hpp"
#include "pointillist/render/mesh_reference.hpp"
#include "pointillist/render/renderer.hpp"
#include "pointillist/render/spt_render.hpp"
#include "pointillist/io/ply.hpp"
#include "pointillist/pipeline/convert.hpp"
#include "pointillist/pipeline/model.hpp"
#include "raster/triangle_draw.hpp"
#include "testing/testing.hpp"

using namespace pointillist;

namespace {

// A UV sphere of radius 1 about the origin with `stacks` × `slices` quads (two triangles each,
// one at the poles), counter-clockwise from outside; vertex colours in bands of latitude.
PointSet uv_sphere(int stacks, int slices) {
  PointSet m;
  const float pi = 3.14159265f;
  m.positions.push_back({0, 1, 0});
  for (int i = 1; i < stacks; ++i) {
    const float theta = pi * float(i) / float(stacks);
    for (int j = 0; j < slices; ++j) {
      const float phi = 2 * pi * float(j) / float(slices);
      m.positions.push_back({std::sin(theta) * std::cos(phi), std::cos(theta),
                             -std::sin(theta) * std::sin(phi)});
    }
  }
  m.positions.push_back({0, -1, 0});
  const auto ring = [&](int i, int j) {
    return static_cast<std::uint32_t>(1 + (i - 1) * slices + (j % slices));
  };
  const std::uint32_t south = static_cast<std::uint32_t>(m.positions.size() - 1);
  for (int j = 0; j < slices; ++j) {
    m.triangles.push_back({0, ring(1, j), ring(1, j + 1)});
    for (int i = 1; i + 1 < stacks; ++i) {
      m.triangles.push_back({ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)});
      m.triangles.push_back({ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)});
    }
    m.triangles.push_back({ring(stacks - 1, j), south, ring(stacks - 1, j + 1)});
  }
  for (const Vec3f& p : m.positions) {
    const auto band = static_cast<std::uint8_t>(p.y > 0.3f ? 200 : p.y > -0.3f ? 120 : 60);
    m.colors.push_back({band, 180, static_cast<std::uint8_t>(255 - band)});
  }
  return m;
}

// The mesh prepared as the converter prepares meshes: area-weighted normals, QSplat's radii.
PointSet prepared(PointSet m, ThreadPool& pool) {
  m.normals = mesh_vertex_normals(m.positions, m.triangles, pool);
  m.radii = mesh_radii(m.positions, m.triangles, 1.0f, pool);
  return m;
}

struct Built {
  SphereTree tree;
  PointSet leaves;
  std::vector<std::array<std::uint32_t, 3>> triangles;  // over the leaves
  SequentialPointTree spt;
  HybridLod hybrid;
};

Built build(const PointSet& mesh, ThreadPool& pool, float ratio = 4.0f) {
  Built b;
  std::vector<std::uint32_t> order;
  b.tree = build_sphere_tree(mesh, pool, Progress::none(), {}, &order);
  b.leaves = sphere_tree_leaves(b.tree.view());
  b.triangles = leaf_triangles(b.tree.view(), order, mesh.triangles);
  b.spt = build_sequential_point_tree(b.leaves, pool);
  b.hybrid = build_hybrid_lod(b.spt, b.leaves, b.triangles, {.triangle_px_per_epsilon = ratio});
  return b;
}

ImageRgb8View view_of(const Frame& f) { return {f.width, f.height, f.color}; }

}  // namespace

TEST(HybridLod, LeafTrianglesAreTheMeshFacesOnTheLeaves) {
  ThreadPool pool(2);
  const PointSet mesh = prepared(uv_sphere(12, 20), pool);
  const Built b = build(mesh, pool);
  ASSERT_EQ(b.triangles.size(), mesh.triangles.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      // Positions are unique on this mesh, so equal positions mean the same vertex.
      ASSERT_EQ(b.leaves.positions[b.triangles[t][k]], mesh.positions[mesh.triangles[t][k]])
          << "face " << t << " corner " << k;
    }
  }
}

// The leaves under every entry, by walking up from each leaf.
std::vector<std::vector<std::uint32_t>> leaves_under(const SequentialPointTree& spt) {
  std::vector<std::vector<std::uint32_t>> under(spt.node_count());
  for (std::uint32_t e = 0; e < spt.node_count(); ++e) {
    if (!spt.is_leaf[e]) continue;
    for (std::uint32_t a = e; a != kSptNoParent; a = spt.parent[a]) under[a].push_back(spt.source[e]);
  }
  return under;
}

TEST(HybridLod, SuppressionBoundsAndTriangleErrorsFollowTheRule) {
  ThreadPool pool(2);
  const PointSet mesh = prepared(uv_sphere(16, 24), pool);
  const float ratio = 3.0f;
  const Built b = build(mesh, pool, ratio);
  const std::size_t n = b.leaves.size();
  // e_t, the triangles touching each leaf, m_N and s_N from their definitions.
  std::vector<float> own(b.triangles.size());
  std::vector<std::vector<std::uint32_t>> around(n);
  for (std::uint32_t t = 0; t < b.triangles.size(); ++t) {
    const auto& tri = b.triangles[t];
    const Vec3f p0 = b.leaves.positions[tri[0]], p1 = b.leaves.positions[tri[1]],
                p2 = b.leaves.positions[tri[2]];
    own[t] = std::max({length(p1 - p0), length(p2 - p1), length(p0 - p2)}) / ratio;
    for (int k = 0; k < 3; ++k) around[tri[k]].push_back(t);
  }
  const auto under = leaves_under(b.spt);
  std::vector<float> s(b.spt.node_count(), 0.0f);
  int interior_suppressible = 0;
  for (std::uint32_t e = 0; e < b.spt.node_count(); ++e) {
    float m = std::numeric_limits<float>::infinity();
    for (const std::uint32_t v : under[e]) {
      for (const std::uint32_t t : around[v]) m = std::min(m, own[t]);
    }
    if (std::isinf(m)) continue;
    const float bound = std::min(std::max(b.spt.error[e], m), b.spt.parent_error[e]);
    s[e] = bound > b.spt.error[e] ? bound : 0.0f;
    interior_suppressible += !b.spt.is_leaf[e] && s[e] > 0;
    EXPECT_NEAR(b.hybrid.suppress_below[e], s[e], 1e-6f * s[e]) << "entry " << e;
  }
  EXPECT_GT(interior_suppressible, 0);  // the extension is exercised
  // E_t: the largest s on the paths from its corners to the root.
  std::vector<float> path_max(n, 0.0f);
  for (std::uint32_t e = 0; e < b.spt.node_count(); ++e) {
    if (!b.spt.is_leaf[e]) continue;
    for (std::uint32_t a = e; a != kSptNoParent; a = b.spt.parent[a]) {
      path_max[b.spt.source[e]] = std::max(path_max[b.spt.source[e]], s[a]);
    }
  }
  using Faces = std::multiset<std::array<std::uint32_t, 3>>;
  const Faces listed(b.hybrid.triangles.begin(), b.hybrid.triangles.end());
  const Faces given(b.triangles.begin(), b.triangles.end());
  EXPECT_EQ(listed, given);
  for (std::size_t t = 0; t < b.hybrid.triangles.size(); ++t) {
    const auto& tri = b.hybrid.triangles[t];
    const float big = std::max({path_max[tri[0]], path_max[tri[1]], path_max[tri[2]]});
    EXPECT_GE(b.hybrid.triangle_error[t], big);
    EXPECT_NEAR(b.hybrid.triangle_error[t], big, 1e-5f * big);
  }
}

TEST(HybridLod, RefusesFacesOfOtherPoints) {
  ThreadPool pool(2);
  const PointSet mesh = prepared(uv_sphere(6, 8), pool);
  Built b = build(mesh, pool);
  std::vector<std::array<std::uint32_t, 3>> bad = b.triangles;
  bad[3][1] = static_cast<std::uint32_t>(b.leaves.size());
  EXPECT_THROW(build_hybrid_lod(b.spt, b.leaves, bad), Error);
  EXPECT_THROW(build_hybrid_lod(b.spt, b.leaves, b.triangles, {.triangle_px_per_epsilon = 0}),
               OptionError);
}

// For random cameras: the triangles selected are exactly those the rule draws (brute force over
// every triangle with E_t from the definition), and every vertex the points leave out (in its
// interval but suppressed) has all its triangles drawn.
TEST(HybridSelection, MatchesBruteForceAndCoversEverySuppressedVertex) {
  ThreadPool pool(2);
  const PointSet mesh = prepared(uv_sphere(24, 40), pool);
  const Built b = build(mesh, pool);
  std::vector<std::vector<std::uint32_t>> around(b.leaves.size());
  for (std::uint32_t t = 0; t < b.hybrid.triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) around[b.hybrid.triangles[t][k]].push_back(t);
  }
  const auto under = leaves_under(b.spt);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> az(0, 360), el(-80, 80), dist(1.2f, 6.0f), eps(0.5f, 3);
  std::uint64_t suppressed_total = 0, drawn_total = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const float epsilon_px = eps(rng);
    Camera cam = orbit_camera({{0, 0, 0}, 1.0f},
                              {.azimuth_deg = az(rng), .elevation_deg = el(rng), .width = 160,
                               .height = 120});
    cam.eye = cam.target + normalized(cam.eye - cam.target) * dist(rng);
    const CameraFrame cf = make_camera_frame(cam);
    std::vector<std::uint32_t> selected;
    render_detail::TriangleSelectionStats stats;
    render_detail::select_triangles(b.hybrid, cf, RenderSettings{}, epsilon_px, pool, selected,
                                    stats);
    const std::set<std::uint32_t> got(selected.begin(), selected.end());
    ASSERT_EQ(got.size(), selected.size()) << "a triangle selected twice";
    const float epsilon = epsilon_px / cf.focal_px;
    std::set<std::uint32_t> want, dropped;
    for (std::uint32_t t = 0; t < b.hybrid.triangles.size(); ++t) {
      const auto& tri = b.hybrid.triangles[t];
      double r = 1e30;
      bool all_outside_one = false;
      for (const Plane& pl : cf.planes) {
        bool all = true;
        for (int k = 0; k < 3; ++k) all = all && pl.distance(b.leaves.positions[tri[k]]) < 0;
        all_outside_one = all_outside_one || all;
      }
      bool away = true;
      Vec3f sum{0, 0, 0};
      for (int k = 0; k < 3; ++k) {
        r = std::min(r, double(distance(b.leaves.positions[tri[k]], cf.eye)));
        away = away && dot(b.leaves.normals[tri[k]], cf.eye - b.leaves.positions[tri[k]]) < 0;
        sum = sum + b.leaves.normals[tri[k]];
      }
      const Vec3f p0 = b.leaves.positions[tri[0]];
      Vec3f face = cross(b.leaves.positions[tri[1]] - p0, b.leaves.positions[tri[2]] - p0);
      if (dot(face, sum) < 0) face = -face;
      away = away && dot(face, cf.eye - p0) < 0;
      // Away from the boundary of the test (rounding), the rule decides.
      const double lhs = r * epsilon, rhs = b.hybrid.triangle_error[t];
      if (std::abs(lhs - rhs) < 1e-5 * rhs) {
        if (got.count(t)) want.insert(t);
        continue;
      }
      if (all_outside_one || away) dropped.insert(t);
      if (lhs < rhs && !all_outside_one && !away) want.insert(t);
    }
    ASSERT_EQ(got, want) << "trial " << trial;
    drawn_total += got.size();
    // Every entry left out for its triangles (facing the eye, in its interval, (r + ρ)·ε < s,
    // not edge-on): all triangles touching its leaves are drawn, but for those the frustum or
    // backface rule dropped.
    for (std::uint32_t e = 0; e < b.spt.node_count(); ++e) {
      const Vec3f c{b.spt.center_x[e], b.spt.center_y[e], b.spt.center_z[e]};
      const Vec3f nrm{b.spt.normal_x[e], b.spt.normal_y[e], b.spt.normal_z[e]};
      const float r = distance(c, cf.eye);
      const float rho = b.spt.is_leaf[e] ? 0.0f : 0.5f * b.spt.diameter[e];
      const bool in_interval =
          b.spt.error[e] <= r * epsilon && r * epsilon < b.spt.parent_error[e];
      const float cosine = dot(nrm, normalized(cf.eye - c));
      const bool suppressed = (r + rho) * epsilon < b.hybrid.suppress_below[e];
      if (!in_interval || !suppressed || cosine < 0.05f) continue;
      ++suppressed_total;
      for (const std::uint32_t v : under[e]) {
        for (const std::uint32_t t : around[v]) {
          ASSERT_TRUE(got.count(t) || dropped.count(t))
              << "trial " << trial << ": entry " << e << " left out but triangle " << t
              << " not drawn";
        }
      }
    }
  }
  EXPECT_GT(suppressed_total, 1000u);  // the cameras came near enough to exercise the rule
  EXPECT_GT(drawn_total, 1000u);
}

// A zoom from 5 to 0.3 radii into a tessellated sphere: the hybrid image has no holes inside the
// mesh reference's silhouette, and its PSNR against the reference is at least the pure points'.
TEST(HybridRender, ZoomHasNoHolesAndAtLeastThePointsQuality) {
  ThreadPool pool(2);
  const PointSet mesh = prepared(uv_sphere(60, 120), pool);
  std::vector<std::uint32_t> order;
  const SphereTree tree = build_sphere_tree(mesh, pool, Progress::none(), {}, &order);
  const auto triangles = leaf_triangles(tree.view(), order, mesh.triangles);
  const RenderModel model{.tree = tree.view(), .triangles = triangles, .name = "uv sphere"};
  const SceneInstance scene[] = {{&model, {}}};
  Renderer renderer;
  std::uint64_t triangles_drawn = 0, splats_near = 0;
  for (const float d : {5.0f, 2.0f, 1.2f, 0.6f, 0.3f}) {
    Camera cam = orbit_camera({{0, 0, 0}, 1.0f}, {.azimuth_deg = 20, .elevation_deg = 25,
                                                   .width = 320, .height = 240});
    // From outside the sphere: d radii from its surface along the orbit direction.
    cam.eye = normalized(cam.eye - cam.target) * (1.0f + d);
    cam.target = {0, 0, 0};
    Frame ref, points, hybrid;
    render_mesh_reference(mesh, cam, RenderSettings{}, ref);
    FrameSettings fs{.lod = LodScheme::Spt};
    renderer.render(scene, cam, RenderSettings{}, fs, pool, points);
    fs.hybrid = true;
    renderer.render(scene, cam, RenderSettings{}, fs, pool, hybrid);
    const ImageCompareOptions opt{.background = RenderSettings{}.background};
    const ImageComparison p = compare_images(view_of(ref), view_of(points), opt);
    const ImageComparison h = compare_images(view_of(ref), view_of(hybrid), opt);
    EXPECT_EQ(h.hole_count, 0u) << "distance " << d;
    EXPECT_GE(h.psnr_db, p.psnr_db) << "distance " << d;
    triangles_drawn += hybrid.stats.triangles;
    if (d <= 0.6f) splats_near += hybrid.stats.splats;
  }
  EXPECT_GT(triangles_drawn, 0u);
}

TEST(HybridRender, RefusesWhatItCannotDraw) {
  ThreadPool pool(2);
  const PointSet mesh = prepared(uv_sphere(6, 8), pool);
  const SphereTree tree = build_sphere_tree(mesh, pool);
  const RenderModel cloud{.tree = tree.view(), .name = "cloud.ply"};
  const SceneInstance scene[] = {{&cloud, {}}};
  const Camera cam = orbit_camera({{0, 0, 0}, 1.0f}, {.width = 64, .height = 48});
  Renderer renderer;
  Frame f;
  FrameSettings fs{.lod = LodScheme::Spt, .hybrid = true};
  try {
    renderer.render(scene, cam, RenderSettings{}, fs, pool, f);
    FAIL() << "a model without triangles was drawn hybrid";
  } catch (const OptionError& e) {
    EXPECT_NE(std::string(e.what()).find("cloud.ply"), std::string::npos) << e.what();
  }
  fs.lod = LodScheme::QSplat;
  EXPECT_THROW(renderer.render(scene, cam, RenderSettings{}, fs, pool, f), OptionError);
}

// A ground quad of two triangles reaching behind the eye, from a .ptl (quantized corners), drawn
// hybrid from eye height along a walk at 1280×720: every pixel whose ray meets the quad is
// covered (no crack along the shared diagonal, which crosses the near plane: before the clipped
// point was the same in both triangles, this walk showed five pixels of it).
TEST(HybridRender, GroundQuadThroughTheNearPlaneHasNoCrack) {
  ThreadPool pool(2);
  pointillist::testing::TempDir dir;
  PointSet quad;
  quad.positions = {{-100, 0, -100}, {100, 0, -100}, {100, 0, 100}, {-100, 0, 100}};
  quad.triangles = {{0, 2, 1}, {0, 3, 2}};
  quad.normals.assign(4, Vec3f{0, 1, 0});
  quad.colors.assign(4, Rgb8{150, 140, 120});
  write_ply(dir.file("ground.ply"), quad);
  const std::string inputs[] = {dir.file("ground.ply")};
  convert(inputs, dir.file("ground.ptl"), ConvertOptions{}, pool, Progress::none());
  OpenModelOptions open;
  open.paging = Paging::Never;
  const Model model = open_model(dir.file("ground.ptl"), open, pool, Progress::none());
  ASSERT_EQ(model.triangles().size(), 2u);
  const SceneInstance scene[] = {{&model.renderable(), {}}};
  Renderer renderer;
  RenderSettings settings;
  settings.background = {0, 0, 0};
  int cracks = 0, checked = 0;
  for (int k = 12; k <= 20; ++k) {
    Camera cam;
    cam.eye = {0.5f, 1.7f, 14 - 0.4f * float(k)};
    cam.target = {0, 1.2f, -0.4f * float(k)};
    cam.width = 1280;
    cam.height = 720;
    Frame f;
    renderer.render(scene, cam, settings, {.lod = LodScheme::Spt, .hybrid = true}, pool, f);
    const CameraFrame cf = make_camera_frame(cam);
    for (int j = 0; j < cam.height; ++j) {
      for (int i = 0; i < cam.width; ++i) {
        const Vec3f d = pixel_ray(cf, i, j);
        if (!(d.y < -1e-3f)) continue;
        const Vec3f p = cam.eye + d * (-cam.eye.y / d.y);
        if (std::abs(p.x) > 99 || std::abs(p.z) > 99) continue;
        ++checked;
        const Rgb8 c = f.color[std::size_t(j) * cam.width + i];
        cracks += c.r == 0 && c.g == 0 && c.b == 0;
      }
    }
  }
  EXPECT_GT(checked, 1000000);
  EXPECT_EQ(cracks, 0);
}
