// .ptl version 2 encode (quantize, page, write) and decode_all, on the dragon and on a small
// generated cloud, against version 1 (the raw node array) written and read back the same way.
// Counters: file bytes per leaf.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "bench_data.hpp"
#include "pointillist/format/ptl.hpp"
#include "pointillist/format/ptl_v2.hpp"
#include "pointillist/format/ptl_v2_pages.hpp"
#include "pointillist/render/paged.hpp"

using namespace pointillist;

namespace {

// A file in the system's temporary folder, removed at exit.
struct TempPath {
  std::string path;
  explicit TempPath(const std::string& name)
      : path((std::filesystem::temp_directory_path() /
              ("pointillist-bench-" + std::to_string(::getpid()) + "-" + name))
                 .string()) {}
  ~TempPath() { std::filesystem::remove(path); }
};

const SphereTree& small_tree() {
  static const SphereTree tree = [] {
    PointSet p = bench::generated_cloud(10'000);
    p.normals.assign(p.size(), Vec3f{0, 0, 1});
    p.radii.assign(p.size(), 0.01f);
    ThreadPool pool;
    return build_sphere_tree(p, pool);
  }();
  return tree;
}

// The dragon has no colours; this copy claims some (all black) so records carry RGB 565.
const SphereTree& dragon_with_colors() {
  static const SphereTree tree = [] {
    SphereTree t = bench::dragon_tree();
    t.has_colors = !t.nodes.empty();
    return t;
  }();
  return tree;
}

const SphereTree* input(bool dragon, benchmark::State& state, bool colors = false) {
  if (!dragon) return &small_tree();
  const SphereTree& t = colors ? dragon_with_colors() : bench::dragon_tree();
  if (t.nodes.empty()) {
    state.SkipWithError("dragon not fetched (scripts/fetch-models.sh)");
    return nullptr;
  }
  return &t;
}

void BM_EncodePtlV2(benchmark::State& state, bool dragon, bool colors, unsigned threads = 1) {
  const SphereTree* tree = input(dragon, state, colors);
  if (!tree) return;
  TempPath file("encode.ptl");
  PtlV2WriteReport r;
  ThreadPool pool(threads);
  for (auto _ : state) {
    r = write_ptl_v2(file.path, *tree, "", {.write_colors = colors}, pool);
    benchmark::DoNotOptimize(r);
  }
  state.SetItemsProcessed(state.iterations() * std::int64_t(tree->leaf_count));
  state.SetBytesProcessed(state.iterations() * std::int64_t(r.file_size));
  state.counters["bytes_per_leaf"] = r.bytes_per_leaf;
  state.counters["pages"] = r.page_count;
  state.counters["leaf_radius_ratio"] = r.mean_leaf_radius_ratio;
}

// Loading every page in the packed form the paged renderer keeps (validation, records copied,
// links), against decode_all in the same run.
void BM_PackAllPagesPtlV2(benchmark::State& state, bool dragon) {
  const SphereTree* tree = input(dragon, state);
  if (!tree) return;
  TempPath file("pack.ptl");
  const PtlV2WriteReport r = write_ptl_v2(file.path, *tree, "");
  const auto f = PtlV2File::open(file.path);
  const auto source = ptl_v2_page_source(*f);
  HierarchyPage page;
  std::uint64_t resident = 0;
  for (auto _ : state) {
    resident = 0;
    for (std::uint32_t p = 0; p < source->page_count(); ++p) {
      source->load(p, page);
      resident += page.memory_bytes();
    }
    benchmark::DoNotOptimize(resident);
  }
  state.SetItemsProcessed(state.iterations() * std::int64_t(tree->leaf_count));
  state.SetBytesProcessed(state.iterations() * std::int64_t(r.file_size));
  state.counters["resident_bytes_per_node"] = double(resident) / double(f->node_count());
}

void BM_DecodeAllPtlV2(benchmark::State& state, bool dragon) {
  const SphereTree* tree = input(dragon, state);
  if (!tree) return;
  TempPath file("decode.ptl");
  const PtlV2WriteReport r = write_ptl_v2(file.path, *tree, "");
  for (auto _ : state) {
    const auto f = PtlV2File::open(file.path);
    benchmark::DoNotOptimize(f->decode_all());
  }
  state.SetItemsProcessed(state.iterations() * std::int64_t(tree->leaf_count));
  state.SetBytesProcessed(state.iterations() * std::int64_t(r.file_size));
  state.counters["bytes_per_leaf"] = r.bytes_per_leaf;
}

// Baselines: version 1 writes the node array as it is (40 bytes a node) and reads it back
// through the validating mapped reader, copied into a SphereTree like decode_all returns.
void BM_BaselineWritePtlV1(benchmark::State& state, bool dragon) {
  const SphereTree* tree = input(dragon, state);
  if (!tree) return;
  TempPath file("v1.ptl");
  for (auto _ : state) write_ptl(file.path, *tree, "");
  state.SetItemsProcessed(state.iterations() * std::int64_t(tree->leaf_count));
  state.counters["bytes_per_leaf"] =
      double(std::filesystem::file_size(file.path)) / double(tree->leaf_count);
}

void BM_BaselineReadPtlV1(benchmark::State& state, bool dragon) {
  const SphereTree* tree = input(dragon, state);
  if (!tree) return;
  TempPath file("v1r.ptl");
  write_ptl(file.path, *tree, "");
  for (auto _ : state) benchmark::DoNotOptimize(read_ptl(file.path));
  state.SetItemsProcessed(state.iterations() * std::int64_t(tree->leaf_count));
}

}  // namespace

BENCHMARK_CAPTURE(BM_EncodePtlV2, Small, false, false)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_DecodeAllPtlV2, Small, false)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_EncodePtlV2, Dragon, true, false)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_EncodePtlV2, DragonColor, true, true)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_EncodePtlV2, Dragon2Threads, true, false, 2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_DecodeAllPtlV2, Dragon, true)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_PackAllPagesPtlV2, Dragon, true)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_BaselineWritePtlV1, Dragon, true)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_BaselineReadPtlV1, Dragon, true)->Unit(benchmark::kMillisecond);
