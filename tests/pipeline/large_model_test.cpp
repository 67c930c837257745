// A model larger than the memory it may use: 20 million generated samples written as a paged
// .ptl version 2 file, rendered page by page under a cap of a tenth of the file's size.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "pointillist/format/ptl_v2.hpp"
#include "pointillist/format/ptl_v2_pages.hpp"
#include "pointillist/lod/sphere_tree.hpp"
#include "pointillist/eval/image_compare.hpp"
#include "pointillist/render/paged.hpp"
#include "pointillist/render/render.hpp"
#include "pointillist/scene/analytic.hpp"
#include "testing/testing.hpp"

using namespace pointillist;

namespace {

#if defined(__SANITIZE_ADDRESS__)
// Under AddressSanitizer (about 3× the memory and 10× the time) the same test on fewer points.
constexpr std::size_t kSamples = 2'000'000;
#else
constexpr std::size_t kSamples = 20'000'000;
#endif

// The demo scene's samples with exact normals and radii from the sample density (discs cover
// the surface about 4 times over), built into a hierarchy and written as .ptl v2.
std::uint64_t write_model(const std::string& path, ThreadPool& pool) {
  SphereTree tree;
  {
    const AnalyticScene scene = demo_scene();
    SurfaceSamples s = sample_scene(scene, kSamples, 11);
    PointSet p = std::move(s.points);
    p.normals = std::move(s.true_normals);
    const float r = 2.0f * static_cast<float>(std::sqrt(surface_area(scene) /
                                                        (3.14159265358979 * double(kSamples))));
    p.radii.assign(p.positions.size(), r);
    tree = build_sphere_tree(p, pool);
  }
  return write_ptl_v2(path, tree, "generated: demo scene").file_size;
}

}  // namespace

TEST(LargeModel, RendersUnderATenthOfItsFileAndShowsAFirstFrameAfterUnderOnePercent) {
  ThreadPool pool(2);
  pointillist::testing::TempDir dir;
  const std::string path = dir.file("large.ptl");
  const std::uint64_t file_size = write_model(path, pool);
  std::printf("%zu samples: %.1f MB file\n", kSamples, double(file_size) / 1e6);

  const auto file = PtlV2File::open(path);
  const auto source = ptl_v2_page_source(*file);
  const std::uint64_t cap = file_size / 10;
  PagedRenderer paged(*source, cap, pool);
  const Camera cam = orbit_camera(file->view_sphere(), {.azimuth_deg = 30, .elevation_deg = 20,
                                                        .width = 640, .height = 480});
  Frame first, frame;
  paged.render(cam, RenderSettings{}, pool, first);
  const double first_share = double(paged.stats().bytes_read) / double(file_size);
  std::printf("first frame after reading %llu bytes (%.3f%% of the file), %llu splats\n",
              static_cast<unsigned long long>(paged.stats().bytes_read), 100 * first_share,
              static_cast<unsigned long long>(first.stats.splats));
  EXPECT_LT(first_share, 0.01);
  EXPECT_GT(first.stats.splats, 100u);

  int rounds = 0;
  for (; rounds < 500; ++rounds) {
    if (paged.load_requested(pool) == 0) break;
    paged.render(cam, RenderSettings{}, pool, frame);
    if (paged.complete()) break;
  }
  const PagedRenderStats& s = paged.stats();
  std::printf("after %d rounds: %llu splats, read %.1f MB, resident peak %.1f MB (cap %.1f MB), "
              "%llu pages loaded, %llu evicted\n",
              rounds, static_cast<unsigned long long>(frame.stats.splats),
              double(s.bytes_read) / 1e6, double(s.resident_bytes_peak) / 1e6, double(cap) / 1e6,
              static_cast<unsigned long long>(s.pages_loaded),
              static_cast<unsigned long long>(s.pages_evicted));
  EXPECT_LE(s.resident_bytes_peak, cap);
  EXPECT_GT(frame.stats.splats, first.stats.splats);
  // The coarse first frame covers the refined surface: its stand-ins enclose their subtrees.
  const ImageComparison c = compare_images({frame.width, frame.height, frame.color},
                                           {first.width, first.height, first.color},
                                           {.background = RenderSettings{}.background});
  EXPECT_EQ(c.hole_count, 0u);
  EXPECT_GT(c.interior_count, 10000u);
}
