// QSplat .qs files: writing and decoding the dragon, bytes per point, against writing and
// opening the float .ptl v1 of the same model.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <string>

#include "bench_data.hpp"
#include "pointillist/format/ptl.hpp"
#include "pointillist/format/qs.hpp"
#include "pointillist/core/thread_pool.hpp"
#include "pointillist/prep/prepare.hpp"

using namespace pointillist;

namespace {

std::string temp_file(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("pointillist-bench-" + name)).string();
}

// A small generated cloud with normals and radii: CTest's smoke pass.
void BM_QsRoundTrip(benchmark::State& state) {
  PointSet cloud = bench::generated_cloud(2000);
  ThreadPool pool(1);
  prepare_splats(cloud, pool, Progress::none());
  const std::string path = temp_file("small.qs");
  for (auto _ : state) {
    write_qs(path, cloud);
    benchmark::DoNotOptimize(read_qs(path));
  }
}

void BM_WriteQsDragon(benchmark::State& state) {
  if (bench::dragon_path().empty())
    return state.SkipWithError("dragon not fetched (scripts/fetch-models.sh)");
  const PointSet& mesh = bench::dragon_raw();
  const std::string path = temp_file("dragon.qs");
  QsWriteReport report;
  for (auto _ : state) report = write_qs(path, mesh);
  state.counters["bytes_per_point"] = double(report.file_size) / double(report.input_points);
  state.SetItemsProcessed(state.iterations() * std::int64_t(report.input_points));
}

void BM_ReadQsDragon(benchmark::State& state) {
  if (bench::dragon_path().empty())
    return state.SkipWithError("dragon not fetched (scripts/fetch-models.sh)");
  const std::string path = temp_file("dragon-read.qs");
  const QsWriteReport report = write_qs(path, bench::dragon_raw());
  for (auto _ : state) benchmark::DoNotOptimize(read_qs(path));
  state.counters["bytes_per_point"] = double(report.file_size) / double(report.input_points);
  state.SetItemsProcessed(state.iterations() * std::int64_t(report.record_count));
}

// Baseline: the float hierarchy as .ptl v1 (40 bytes a node), written and opened (mmap).
void BM_BaselineWritePtlDragon(benchmark::State& state) {
  if (bench::dragon_path().empty())
    return state.SkipWithError("dragon not fetched (scripts/fetch-models.sh)");
  const SphereTree& tree = bench::dragon_tree();
  const std::string path = temp_file("dragon.ptl");
  for (auto _ : state) write_ptl(path, tree, "");
  state.counters["bytes_per_point"] =
      double(std::filesystem::file_size(path)) / double(tree.leaf_count);
  state.SetItemsProcessed(state.iterations() * std::int64_t(tree.nodes.size()));
}

}  // namespace

BENCHMARK(BM_QsRoundTrip)->Name("BM_QsRoundTrip/Small")->Unit(benchmark::kMillisecond);
BENCHMARK(BM_WriteQsDragon)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ReadQsDragon)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BaselineWritePtlDragon)->Unit(benchmark::kMillisecond);
