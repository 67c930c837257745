// Frame time and splat throughput on the dragon at 1280x720, against a plain single-threaded loop
// that projects every leaf point once into a depth buffer.
#include <benchmark/benchmark.h>

#include <malloc.h>

#include <vector>

#include "bench_data.hpp"
#include "render/point_baseline.hpp"
#include "pointillist/render/render.hpp"

using namespace pointillist;

namespace {

void BM_RenderDragon(benchmark::State& state) {
  const SphereTree& tree = bench::dragon_tree();
  if (tree.nodes.empty()) return state.SkipWithError("dragon not fetched (scripts/fetch-models.sh)");
  ThreadPool pool;
  const Camera cam = orbit_camera(tree.view_sphere, {.elevation_deg = 10, .width = 1280, .height = 720});
  RenderSettings settings;
  settings.threshold_px = float(state.range(0));
  Frame frame;
  render(tree.view(), cam, settings, pool, frame);
  for (auto _ : state) render(tree.view(), cam, settings, pool, frame);
  state.SetItemsProcessed(state.iterations() * std::int64_t(frame.stats.splats));
  state.counters["splats"] = double(frame.stats.splats);
  state.counters["ms_select"] = frame.stats.ms_select;
  state.counters["ms_raster"] = frame.stats.ms_raster;
}

// A one-shot frame, as `pointillist render` draws it: a new Frame whose buffers have never been
// touched (the memory freed after each frame goes back to the system, as at a process's end).
// Against BM_RenderDragon at threshold 1 (a steady frame of a camera path), same run.
void BM_RenderDragonOneShot(benchmark::State& state) {
  const SphereTree& tree = bench::dragon_tree();
  if (tree.nodes.empty()) return state.SkipWithError("dragon not fetched (scripts/fetch-models.sh)");
  ThreadPool pool;
  const Camera cam = orbit_camera(tree.view_sphere, {.elevation_deg = 10, .width = 1280, .height = 720});
  RenderSettings settings;
  RenderStats stats;
  double select = 0, raster = 0;
  for (auto _ : state) {
    {
      Frame frame;
      render(tree.view(), cam, settings, pool, frame);
      stats = frame.stats;
    }
    state.PauseTiming();
    malloc_trim(0);
    select += stats.ms_select;
    raster += stats.ms_raster;
    state.ResumeTiming();
  }
  state.SetItemsProcessed(state.iterations() * std::int64_t(stats.splats));
  state.counters["splats"] = double(stats.splats);
  state.counters["ms_select"] = select / double(state.iterations());
  state.counters["ms_raster"] = raster / double(state.iterations());
}

void BM_BaselineProjectDragonPoints(benchmark::State& state) {
  const PointSet& points = bench::dragon_prepared();
  if (points.size() == 0) return state.SkipWithError("dragon not fetched (scripts/fetch-models.sh)");
  const SphereTree& tree = bench::dragon_tree();
  const Camera cam = orbit_camera(tree.view_sphere, {.elevation_deg = 10, .width = 1280, .height = 720});
  const CameraFrame frame = make_camera_frame(cam);
  std::vector<float> depth(std::size_t(1280) * 720);
  for (auto _ : state) benchmark::DoNotOptimize(project_points_baseline(points.positions, frame, depth));
  state.SetItemsProcessed(state.iterations() * std::int64_t(points.size()));
}

void BM_RenderSmall(benchmark::State& state) {
  PointSet p = bench::generated_cloud(20'000);
  p.normals.assign(p.size(), Vec3f{0, 0, 1});
  p.radii.assign(p.size(), 0.02f);
  ThreadPool pool;
  const SphereTree tree = build_sphere_tree(p, pool);
  const Camera cam = orbit_camera(tree.view_sphere, {.width = 320, .height = 240});
  Frame frame;
  for (auto _ : state) render(tree.view(), cam, RenderSettings{}, pool, frame);
  state.SetItemsProcessed(state.iterations() * std::int64_t(frame.stats.splats));
}

}  // namespace

BENCHMARK(BM_RenderSmall)->Name("BM_Render/Small")->Unit(benchmark::kMillisecond);
BENCHMARK(BM_RenderDragon)->Arg(1)->Arg(2)->Arg(4)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_RenderDragonOneShot)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_BaselineProjectDragonPoints)->Unit(benchmark::kMillisecond);
