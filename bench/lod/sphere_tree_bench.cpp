// Hierarchy build throughput, against sorting the same number of floats.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <vector>

#include "bench_data.hpp"
#include "pointillist/lod/sphere_tree.hpp"

using namespace pointillist;

namespace {

PointSet with_splats(const PointSet& p) {
  PointSet q = p;
  q.normals.assign(q.size(), Vec3f{0, 0, 1});
  q.radii.assign(q.size(), 0.01f);
  return q;
}

void BM_BuildSphereTree(benchmark::State& state) {
  const PointSet p = with_splats(bench::generated_cloud(std::size_t(state.range(0))));
  ThreadPool pool;
  for (auto _ : state) benchmark::DoNotOptimize(build_sphere_tree(p, pool));
  state.SetItemsProcessed(state.iterations() * state.range(0));
}

void BM_BuildSphereTreeDragon(benchmark::State& state) {
  const PointSet& p = bench::dragon_prepared();
  if (p.size() == 0) return state.SkipWithError("dragon not fetched (scripts/fetch-models.sh)");
  ThreadPool pool;
  for (auto _ : state) benchmark::DoNotOptimize(build_sphere_tree(p, pool));
  state.SetItemsProcessed(state.iterations() * std::int64_t(p.size()));
}

// Baseline: std::sort of one coordinate of the same points (single thread).
void BM_BaselineSortFloats(benchmark::State& state) {
  const PointSet& p = bench::generated_cloud(std::size_t(state.range(0)));
  std::vector<float> xs(p.size());
  for (auto _ : state) {
    state.PauseTiming();
    for (std::size_t i = 0; i < p.size(); ++i) xs[i] = p.positions[i].x;
    state.ResumeTiming();
    std::sort(xs.begin(), xs.end());
    benchmark::DoNotOptimize(xs.data());
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}

}  // namespace

BENCHMARK(BM_BuildSphereTree)->Name("BM_BuildSphereTree/Small")->Arg(10'000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BuildSphereTree)->Arg(437'645)->Arg(10'000'000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BuildSphereTreeDragon)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BaselineSortFloats)->Arg(437'645)->Arg(10'000'000)->Unit(benchmark::kMillisecond);
