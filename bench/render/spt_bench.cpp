// Sequential Point Tree selection versus QSplat traversal on the dragon at 1280x720: selection
// time per frame and per drawn splat, whole frames, and the share of the list scanned.
#include <benchmark/benchmark.h>

#include "bench_data.hpp"
#include "pointillist/lod/sequential_point_tree.hpp"
#include "pointillist/render/render.hpp"
#include "pointillist/render/spt_render.hpp"

using namespace pointillist;

namespace {

const SequentialPointTree& dragon_spt(std::uint32_t chunk_level) {
  static SequentialPointTree trees[2];
  static bool built[2] = {false, false};
  const int k = chunk_level == 0 ? 0 : 1;
  if (!built[k]) {
    const SphereTree& tree = bench::dragon_tree();
    if (!tree.nodes.empty()) {
      ThreadPool pool;
      trees[k] = build_sequential_point_tree(sphere_tree_leaves(tree.view()), pool,
                                             Progress::none(), {.chunk_level = chunk_level});
    }
    built[k] = true;
  }
  return trees[k];
}

Camera dragon_camera(const Sphere& view_sphere, float distance = 0) {
  return orbit_camera(view_sphere, {.elevation_deg = 10, .distance = distance, .width = 1280, .height = 720});
}

// Selection only (traversal or list pass, projection and shading; no rasterization).
void BM_SelectQsplat(benchmark::State& state) {
  const SphereTree& tree = bench::dragon_tree();
  if (tree.nodes.empty()) return state.SkipWithError("dragon not fetched (scripts/fetch-models.sh)");
  ThreadPool pool;
  const CameraFrame cam = make_camera_frame(dragon_camera(tree.view_sphere, float(state.range(0)) / 10));
  SplatStream stream;
  stream.with_discs = false;  // as fast frames select (the quality rasterizer needs the discs)
  SelectionStats stats;
  RenderSettings settings;
  for (auto _ : state) select_splats(tree.view(), cam, settings, pool, stream, stats);
  state.SetItemsProcessed(state.iterations() * std::int64_t(stats.splats));
  state.counters["splats"] = double(stats.splats);
  state.counters["visited"] = double(stats.nodes_visited);
}

void BM_SelectSpt(benchmark::State& state) {
  const SphereTree& tree = bench::dragon_tree();
  if (tree.nodes.empty()) return state.SkipWithError("dragon not fetched (scripts/fetch-models.sh)");
  const SequentialPointTree& spt = dragon_spt(std::uint32_t(state.range(1)));
  ThreadPool pool;
  const CameraFrame cam = make_camera_frame(dragon_camera(tree.view_sphere, float(state.range(0)) / 10));
  SplatStream stream;
  stream.with_discs = false;  // as fast frames select
  SptSelectionStats stats;
  for (auto _ : state) select_splats_spt(spt, cam, RenderSettings{}, {.epsilon_px = 1}, pool, stream, stats);
  state.SetItemsProcessed(state.iterations() * std::int64_t(stats.splats));
  state.counters["splats"] = double(stats.splats);
  state.counters["scanned_pct"] = 100.0 * double(stats.entries_scanned) / double(stats.entries_total);
  state.counters["chunks_culled"] = double(stats.chunks_culled);
}

void BM_FrameSpt(benchmark::State& state) {
  const SphereTree& tree = bench::dragon_tree();
  if (tree.nodes.empty()) return state.SkipWithError("dragon not fetched (scripts/fetch-models.sh)");
  const SequentialPointTree& spt = dragon_spt(3);
  ThreadPool pool;
  const Camera cam = dragon_camera(tree.view_sphere);
  Frame frame;
  for (auto _ : state) render_spt(spt, cam, RenderSettings{}, {.epsilon_px = float(state.range(0))}, pool, frame);
  state.SetItemsProcessed(state.iterations() * std::int64_t(frame.stats.splats));
  state.counters["splats"] = double(frame.stats.splats);
  state.counters["ms_select"] = frame.stats.ms_select;
  state.counters["ms_raster"] = frame.stats.ms_raster;
}

}  // namespace

// Arguments: eye distance in tenths of the default framing distance (0 = default), chunk level.
BENCHMARK(BM_SelectQsplat)->Arg(0)->Arg(15)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SelectSpt)->Args({0, 0})->Args({0, 3})->Args({15, 0})->Args({15, 3})
    ->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_FrameSpt)->Arg(1)->Arg(2)->Arg(4)->Unit(benchmark::kMillisecond)->UseRealTime();
