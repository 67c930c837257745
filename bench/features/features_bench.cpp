// Sharp features (spec §4.7): the neighbour graph beside the dissertation's Table 6.1 and our own
// brute force (P1), the whole preprocessing (P2), and what features cost a quality frame (P3,
// P4). Baseline: a plain pass over the same positions.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <span>

#include "bench_data.hpp"
#include "pointillist/features/features.hpp"
#include "pointillist/features/neighbour_graph.hpp"
#include "pointillist/lod/tree_features.hpp"
#include "pointillist/prep/prepare.hpp"
#include "pointillist/prep/radii.hpp"
#include "pointillist/render/renderer.hpp"
#include "pointillist/scene/csg.hpp"

using namespace pointillist;

namespace {

// A T1 cube sampled near-uniformly (J mode) with exactly n splats (the sizes of Table 6.1), or
// at random with Pointillist's default radii (R mode); normals exact.
struct Cube {
  std::vector<Vec3f> positions, normals;
  std::vector<float> radii;
};
const Cube& cube(std::size_t n, bool random = false) {
  static std::map<std::pair<std::size_t, bool>, std::unique_ptr<Cube>> cache;
  auto& slot = cache[{n, random}];
  if (!slot) {
    CsgScene scene = csg_scene("T1");
    scene.spacing = 2.0f / std::sqrt(static_cast<float>(n) / 6.0f) * 0.99f;
    const CsgSamples s = sample_csg(scene, random ? SamplingMode::Random : SamplingMode::Jittered, 1);
    slot = std::make_unique<Cube>();
    // Exactly n: drop evenly spread extras.
    const std::size_t total = s.labels.size();
    for (std::size_t k = 0; k < n; ++k) {
      const std::size_t i = k * total / n;
      slot->positions.push_back(s.points.positions[i]);
      slot->normals.push_back(s.points.normals[i]);
    }
    ThreadPool pool(2);
    CloudRadiusOptions radius;
    radius.coverage = random ? kDefaultCloudCoverage : 1.0f;
    slot->radii = cloud_radii(slot->positions, pool, Progress::none(), radius);
  }
  return *slot;
}

void BM_FeatureGraph(benchmark::State& state) {
  const Cube& c = cube(static_cast<std::size_t>(state.range(0)));
  ThreadPool pool(1);
  std::size_t edges = 0;
  for (auto _ : state) {
    const NeighbourGraph g = build_neighbour_graph(c.positions, c.radii, pool);
    edges = g.edge_count();
    benchmark::DoNotOptimize(g.neighbours.data());
  }
  state.counters["m"] = 2.0 * double(edges) / double(c.positions.size());
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(c.positions.size()));
}

void BM_FeatureGraphBruteForce(benchmark::State& state) {
  const Cube& c = cube(static_cast<std::size_t>(state.range(0)));
  for (auto _ : state) {
    const NeighbourGraph g = build_neighbour_graph_brute_force(c.positions, c.radii);
    benchmark::DoNotOptimize(g.neighbours.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(c.positions.size()));
}

// Times compute_features on the splats and reports the mean degree, the shares of sharp
// edges and clipped splats and the throughput.
void time_features(benchmark::State& state, std::span<const Vec3f> positions,
                   std::span<const Vec3f> normals, std::span<const float> radii,
                   ThreadPool& pool) {
  FeatureStats stats;
  for (auto _ : state) {
    const FeatureData f = compute_features(positions, normals, radii, pool);
    stats = f.stats;
    benchmark::DoNotOptimize(f.surface_id.data());
  }
  state.counters["m"] = stats.mean_degree();
  state.counters["sharp_share"] = double(stats.sharp_edges) / double(stats.edges);
  state.counters["clipped_share"] = double(stats.clipped) / double(stats.splats);
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(positions.size()));
}

// Whole preprocessing (graph, sharp edges, edge test, disc tests, classification,
// de-duplication, segmentation); range(1): 0 = J mode, 1 = R mode; range(2): threads.
void BM_Features(benchmark::State& state) {
  const Cube& c = cube(static_cast<std::size_t>(state.range(0)), state.range(1) != 0);
  ThreadPool pool(static_cast<unsigned>(state.range(2)));
  time_features(state, c.positions, c.normals, c.radii, pool);
}

// The dragon (T16), prepared as the CLI does (normals from its faces, QSplat radii).
void BM_FeaturesDragon(benchmark::State& state) {
  const PointSet& d = bench::dragon_prepared();
  if (d.positions.empty()) {
    state.SkipWithError("the dragon is not fetched (scripts/fetch-models.sh)");
    return;
  }
  ThreadPool pool(static_cast<unsigned>(state.range(0)));
  time_features(state, d.positions, d.normals, d.radii, pool);
}

// A random cloud of the demo scene with default preparation (PCA normals, cloud radii), at
// 10^5, 10^6 and 10^7 points: the time per splat across sizes (spec P2, T16).
void BM_FeaturesCloud(benchmark::State& state) {
  static PointSet cloud;
  const std::size_t n = static_cast<std::size_t>(state.range(0));
  ThreadPool pool(2);
  if (cloud.size() != n) {
    // The leaves of its hierarchy, in tree order, as the pipeline computes features.
    PointSet prepared = bench::generated_cloud(n);
    prepare_splats(prepared, pool, Progress::none(), {});
    cloud = sphere_tree_leaves(build_sphere_tree(prepared, pool).view());
  }
  time_features(state, cloud.positions, cloud.normals, cloud.radii, pool);
}

// P3/P4: a quality frame of T1 at the corner close-up (V2, 1024×1024), range(0): 0 = without
// features, 1 = features, 2 = surface ids without clip planes (what clipping adds is 1 − 2).
void BM_QualityFrameT1(benchmark::State& state) {
  static std::unique_ptr<SphereTree> tree;
  static std::unique_ptr<TreeFeatures> features, ids_only;
  ThreadPool pool(2);
  if (!tree) {
    CsgSamples s = sample_csg(csg_scene("T1"), SamplingMode::Jittered, 1);
    CloudRadiusOptions radius;
    radius.coverage = 1.0f;
    s.points.radii = cloud_radii(s.points.positions, pool, Progress::none(), radius);
    tree = std::make_unique<SphereTree>(build_sphere_tree(s.points, pool));
    features = std::make_unique<TreeFeatures>(compute_tree_features(tree->view(), pool));
    ids_only = std::make_unique<TreeFeatures>(*features);
    std::fill(ids_only->clip_mode.begin(), ids_only->clip_mode.end(), ClipMode::None);
    std::fill(ids_only->clip_offset.begin(), ids_only->clip_offset.end(), 0u);
    ids_only->clip_planes.clear();
  }
  RenderModel model{.tree = tree->view()};
  model.tree.features = state.range(0) == 2 ? ids_only.get() : features.get();
  Camera cam;
  cam.eye = {2.0f, 2.1f, 1.9f};
  cam.target = {1, 1, 1};
  cam.width = cam.height = bench::smoke_mode() ? 64 : 1024;
  FrameSettings fs;
  fs.rasterizer = Rasterizer::Quality;
  fs.features = state.range(0) != 0;
  Renderer renderer;
  Frame frame;
  const SceneInstance inst{&model, {}};
  for (auto _ : state) {
    renderer.render({&inst, 1}, cam, RenderSettings{}, fs, pool, frame);
    benchmark::DoNotOptimize(frame.color.data());
  }
  state.counters["raster_ms"] = frame.stats.ms_raster;
}

void BM_BaselineTouchPositions(benchmark::State& state) {
  const Cube& c = cube(static_cast<std::size_t>(state.range(0)));
  for (auto _ : state) {
    float s = 0;
    for (Vec3f p : c.positions) s += p.x + p.y + p.z;
    benchmark::DoNotOptimize(s);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(c.positions.size()));
}

}  // namespace

BENCHMARK(BM_FeatureGraph)->Name("BM_FeatureGraph/Small")->Arg(4305)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FeatureGraph)
    ->Arg(4305)->Arg(7478)->Arg(10638)->Arg(15970)->Arg(24785)->Arg(41737)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FeatureGraphBruteForce)->Arg(4305)->Arg(41737)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Features)->Name("BM_Features/Small")->Args({4305, 0, 1})->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Features)
    ->Args({41737, 0, 1})->Args({41737, 1, 1})->Args({41737, 0, 2})
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FeaturesDragon)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FeaturesCloud)->Arg(100'000)->Arg(1'000'000)->Arg(10'000'000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_QualityFrameT1)->Name("BM_QualityFrameT1/Small")->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_QualityFrameT1)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BaselineTouchPositions)->Arg(41737)->Unit(benchmark::kMicrosecond);
