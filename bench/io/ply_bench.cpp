// PLY loading throughput against a plain bulk read of the same bytes.
#include <benchmark/benchmark.h>
#include <fcntl.h>
#include <unistd.h>
#include <zlib.h>

#include <filesystem>
#include <map>
#include <vector>

#include "bench_data.hpp"
#include "pointillist/io/ply.hpp"

using namespace pointillist;

namespace {

// A binary little-endian PLY with positions, normals and faces-free, written once.
const std::string& binary_ply(std::size_t points) {
  static std::map<std::size_t, std::string> files;
  auto it = files.find(points);
  if (it == files.end()) {
    PointSet p = bench::generated_cloud(points);
    p.normals.assign(p.size(), Vec3f{0, 0, 1});
    p.radii.assign(p.size(), 0.01f);
    const auto path = (std::filesystem::temp_directory_path() /
                       ("pointillist-bench-" + std::to_string(points) + ".ply"))
                          .string();
    write_ply(path, p);
    it = files.emplace(points, path).first;
  }
  return it->second;
}

std::size_t bulk_read(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY);
  std::vector<char> buf(1 << 22);
  std::size_t total = 0;
  for (ssize_t n; (n = ::read(fd, buf.data(), buf.size())) > 0;) total += std::size_t(n);
  ::close(fd);
  return total;
}

void BM_PlyLoadBinary(benchmark::State& state) {
  const std::string& path = binary_ply(std::size_t(state.range(0)));
  const auto bytes = std::filesystem::file_size(path);
  for (auto _ : state) benchmark::DoNotOptimize(read_ply(path));
  state.SetBytesProcessed(state.iterations() * std::int64_t(bytes));
  state.SetItemsProcessed(state.iterations() * state.range(0));
}

void BM_BaselineBulkReadBinary(benchmark::State& state) {
  const std::string& path = binary_ply(std::size_t(state.range(0)));
  const auto bytes = std::filesystem::file_size(path);
  for (auto _ : state) benchmark::DoNotOptimize(bulk_read(path));
  state.SetBytesProcessed(state.iterations() * std::int64_t(bytes));
  state.SetItemsProcessed(state.iterations() * state.range(0));
}

void BM_PlyLoadDragonGz(benchmark::State& state) {
  const std::string path = bench::dragon_path();
  if (path.empty()) return state.SkipWithError("dragon not fetched (scripts/fetch-models.sh)");
  for (auto _ : state) benchmark::DoNotOptimize(read_ply(path));
  state.SetItemsProcessed(state.iterations() * 437645);
}

// Baseline: only inflating the same file (zlib), which any reader of the .gz must do.
void BM_BaselineGunzipDragon(benchmark::State& state) {
  const std::string path = bench::dragon_path();
  if (path.empty()) return state.SkipWithError("dragon not fetched (scripts/fetch-models.sh)");
  std::vector<char> buf(1 << 22);
  for (auto _ : state) {
    gzFile f = gzopen(path.c_str(), "rb");
    gzbuffer(f, 1 << 20);
    std::size_t total = 0;
    for (int n; (n = gzread(f, buf.data(), unsigned(buf.size()))) > 0;) total += std::size_t(n);
    gzclose(f);
    benchmark::DoNotOptimize(total);
  }
  state.SetItemsProcessed(state.iterations() * 437645);
}

}  // namespace

BENCHMARK(BM_PlyLoadBinary)->Name("BM_PlyLoadBinary/Small")->Arg(10'000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BaselineBulkReadBinary)->Name("BM_BaselineBulkReadBinary/Small")->Arg(10'000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PlyLoadBinary)->Arg(10'000'000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BaselineBulkReadBinary)->Arg(10'000'000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PlyLoadDragonGz)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BaselineGunzipDragon)->Unit(benchmark::kMillisecond);
