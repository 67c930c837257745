// Quality mode (surface splatting with deferred shading) against the fast mode on the dragon at
// 1280x720: frame time, splat throughput, and image quality (PSNR, SSIM) of each against the
// z-buffered triangles (render_mesh_reference), measured once outside the timed loop. Baseline: a
// plain pass that writes the quality rasterizer's per-pixel accumulators once (36 bytes/pixel).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <vector>

#include "bench_data.hpp"
#include "pointillist/eval/image_compare.hpp"
#include "pointillist/render/mesh_reference.hpp"
#include "pointillist/render/quality.hpp"
#include "pointillist/render/render.hpp"

using namespace pointillist;

namespace {

constexpr int kWidth = 1280, kHeight = 720;

Camera dragon_camera(const SphereTree& tree) {
  return orbit_camera(tree.view_sphere, {.elevation_deg = 10, .width = kWidth, .height = kHeight});
}

// The triangle reference of the bench view, rendered once.
const Frame& dragon_reference() {
  static const Frame frame = [] {
    Frame f;
    if (bench::dragon_prepared().size() > 0) {
      render_mesh_reference(bench::dragon_prepared(), dragon_camera(bench::dragon_tree()),
                            RenderSettings{}, f);
    }
    return f;
  }();
  return frame;
}

void report_quality(benchmark::State& state, const Frame& frame) {
  const Frame& ref = dragon_reference();
  const ImageComparison c = compare_images({ref.width, ref.height, ref.color},
                                           {frame.width, frame.height, frame.color});
  state.counters["psnr_db"] = c.psnr_db;
  state.counters["ssim"] = c.ssim;
  state.counters["holes"] = static_cast<double>(c.hole_count);
  state.counters["iou"] = c.silhouette_iou;
}

void report_frame(benchmark::State& state, const Frame& frame) {
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(frame.stats.splats));
  state.counters["splats"] = static_cast<double>(frame.stats.splats);
  state.counters["ms_select"] = frame.stats.ms_select;
  state.counters["ms_raster"] = frame.stats.ms_raster;
}

// Arguments: threshold in pixels.
void BM_DragonFast(benchmark::State& state) {
  const SphereTree& tree = bench::dragon_tree();
  if (tree.nodes.empty()) return state.SkipWithError("dragon not fetched (scripts/fetch-models.sh)");
  ThreadPool pool;
  RenderSettings settings;
  settings.threshold_px = static_cast<float>(state.range(0));
  Frame frame;
  render(tree.view(), dragon_camera(tree), settings, pool, frame);
  report_quality(state, frame);
  for (auto _ : state) render(tree.view(), dragon_camera(tree), settings, pool, frame);
  report_frame(state, frame);
}

// Arguments: threshold in pixels, reconstruction (0 = Z-range, 1 = Z-threshold), opacity in %.
void BM_DragonQuality(benchmark::State& state) {
  const SphereTree& tree = bench::dragon_tree();
  if (tree.nodes.empty()) return state.SkipWithError("dragon not fetched (scripts/fetch-models.sh)");
  ThreadPool pool;
  RenderSettings settings;
  settings.threshold_px = static_cast<float>(state.range(0));
  QualitySettings quality;
  quality.reconstruction = state.range(1) == 0 ? Reconstruction::ZRange : Reconstruction::ZThreshold;
  quality.opacity = static_cast<float>(state.range(2)) / 100.0f;
  Frame frame;
  QualityScratch scratch;
  render_quality(tree.view(), dragon_camera(tree), settings, quality, pool, frame, scratch);
  if (quality.opacity == 1.0f) report_quality(state, frame);
  for (auto _ : state) {
    render_quality(tree.view(), dragon_camera(tree), settings, quality, pool, frame, scratch);
  }
  report_frame(state, frame);
}

// Writes 9 floats per pixel of the image once per iteration (what clearing the accumulators of
// every band costs), split over the pool's threads.
void BM_BaselineQualityAccumulators(benchmark::State& state) {
  ThreadPool pool;
  const std::size_t pixels = static_cast<std::size_t>(kWidth) * kHeight;
  std::vector<float> acc(pixels * 9);
  const std::size_t parts = pool.thread_count();
  for (auto _ : state) {
    pool.run(parts, [&](std::size_t t) {
      const std::size_t b = acc.size() * t / parts, e = acc.size() * (t + 1) / parts;
      std::fill(acc.begin() + static_cast<std::ptrdiff_t>(b),
                acc.begin() + static_cast<std::ptrdiff_t>(e), 0.0f);
    });
    benchmark::DoNotOptimize(acc.data());
    benchmark::ClobberMemory();
  }
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(acc.size() * sizeof(float)));
}

void BM_RenderQualitySmall(benchmark::State& state) {
  PointSet p = bench::generated_cloud(20'000);
  p.normals.assign(p.size(), Vec3f{0, 0, 1});
  p.radii.assign(p.size(), 0.02f);
  ThreadPool pool;
  const SphereTree tree = build_sphere_tree(p, pool);
  const Camera cam = orbit_camera(tree.view_sphere, {.width = 320, .height = 240});
  Frame frame;
  QualityScratch scratch;
  for (auto _ : state) {
    render_quality(tree.view(), cam, RenderSettings{}, QualitySettings{}, pool, frame, scratch);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(frame.stats.splats));
}

}  // namespace

BENCHMARK(BM_RenderQualitySmall)->Name("BM_RenderQuality/Small")->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DragonFast)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_DragonQuality)
    ->Args({1, 0, 100})
    ->Args({1, 1, 100})
    ->Args({2, 0, 100})
    ->Args({1, 0, 50})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_BaselineQualityAccumulators)->Unit(benchmark::kMillisecond)->UseRealTime();
