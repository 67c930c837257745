// Normal estimation and radii throughput, against a plain pass over the same points.
#include <benchmark/benchmark.h>

#include "bench_data.hpp"
#include "pointillist/prep/normals.hpp"
#include "pointillist/prep/prepare.hpp"
#include "pointillist/prep/radii.hpp"
#include "pointillist/spatial/knn.hpp"

using namespace pointillist;

namespace {

void BM_PcaNormals(benchmark::State& state) {
  const PointSet& p = bench::generated_cloud(std::size_t(state.range(0)));
  ThreadPool pool;
  for (auto _ : state) benchmark::DoNotOptimize(pca_normals(p.positions, pool));
  state.SetItemsProcessed(state.iterations() * state.range(0));
}

void BM_Knn16(benchmark::State& state) {
  const PointSet& p = bench::generated_cloud(std::size_t(state.range(0)));
  ThreadPool pool;
  for (auto _ : state) benchmark::DoNotOptimize(k_nearest_neighbours(p.positions, pool, {.k = 16}));
  state.SetItemsProcessed(state.iterations() * state.range(0));
}

void BM_CloudRadii(benchmark::State& state) {
  const PointSet& p = bench::generated_cloud(std::size_t(state.range(0)));
  ThreadPool pool;
  for (auto _ : state) benchmark::DoNotOptimize(cloud_radii(p.positions, pool));
  state.SetItemsProcessed(state.iterations() * state.range(0));
}

void BM_PrepareDragonMesh(benchmark::State& state) {
  const PointSet& raw = bench::dragon_raw();
  if (raw.size() == 0) return state.SkipWithError("dragon not fetched (scripts/fetch-models.sh)");
  ThreadPool pool;
  for (auto _ : state) {
    state.PauseTiming();
    PointSet p = raw;
    state.ResumeTiming();
    prepare_splats(p, pool, Progress::none());
    benchmark::DoNotOptimize(p.radii.data());
  }
  state.SetItemsProcessed(state.iterations() * std::int64_t(raw.size()));
}

// Baseline: one pass computing the bounding box of the same points.
void BM_BaselineBoundingBox(benchmark::State& state) {
  const PointSet& p = bench::generated_cloud(std::size_t(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(bounding_box(p.positions));
  state.SetItemsProcessed(state.iterations() * state.range(0));
}

}  // namespace

BENCHMARK(BM_PcaNormals)->Name("BM_PcaNormals/Small")->Arg(5'000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PcaNormals)->Arg(1'000'000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Knn16)->Arg(1'000'000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CloudRadii)->Arg(1'000'000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PrepareDragonMesh)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BaselineBoundingBox)->Arg(1'000'000)->Unit(benchmark::kMillisecond);
