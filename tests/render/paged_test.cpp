// Paged (out-of-core, progressive) rendering against the in-memory renderer: with every page
// resident the image is render()'s bit for bit; with fewer pages it has no holes where render()
// has none; the memory cap holds; progressive frames converge.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <set>
#include <vector>

#include "pointillist/core/error.hpp"
#include "pointillist/lod/sphere_tree.hpp"
#include "pointillist/eval/image_compare.hpp"
#include "pointillist/render/paged.hpp"
#include "pointillist/render/quality.hpp"
#include "pointillist/render/render.hpp"
#include "pointillist/scene/analytic.hpp"
#include "render_test_util.hpp"

using namespace pointillist;
using namespace pointillist::render_test;

namespace {

const SphereTree& demo_tree() {
  static const SphereTree tree = [] {
    ThreadPool pool(2);
    return build_sphere_tree(splat_samples(demo_scene(), 60000, 3), pool);
  }();
  return tree;
}

Camera view(float azimuth, float distance = 0.0f) {
  return orbit_camera(demo_tree().view_sphere, {.azimuth_deg = azimuth, .elevation_deg = 20,
                                                .distance = distance, .width = 240,
                                                .height = 180});
}

// Renders, loading what was requested, until nothing more is wanted or can be loaded.
void render_until_settled(PagedRenderer& r, const Camera& cam, ThreadPool& pool, Frame& frame,
                          int max_rounds = 200) {
  for (int i = 0; i < max_rounds; ++i) {
    r.render(cam, RenderSettings{}, pool, frame);
    if (r.complete() || r.load_requested(pool) == 0) return;
  }
  FAIL() << "did not settle in " << max_rounds << " rounds";
}

// Memory of every page of `source` when resident.
std::uint64_t all_pages_memory(const PageSource& source) {
  std::uint64_t total = 0;
  for (std::uint32_t p = 0; p < source.page_count(); ++p) total += source.page_memory_bytes(p);
  return total;
}

ImageComparison compare(const Frame& reference, const Frame& test) {
  return compare_images({reference.width, reference.height, reference.color},
                        {test.width, test.height, test.color},
                        {.background = RenderSettings{}.background});
}

}  // namespace

TEST(Paginate, EveryNodeIsInExactlyOnePageAndPagesRespectTheirSize) {
  const SphereTree& tree = demo_tree();
  const std::uint64_t page_bytes = 4096;
  const auto source = paginate(tree.view(), page_bytes);
  ASSERT_GT(source->page_count(), 10u);
  // Walk the pages from the root, as the renderer does, matching nodes with the tree's.
  std::uint64_t nodes = 0;
  std::set<std::uint32_t> seen_pages;
  struct Item {
    std::uint32_t page, local, global;
  };
  std::vector<HierarchyPage> pages(source->page_count());
  for (std::uint32_t p = 0; p < source->page_count(); ++p) {
    source->load(p, pages[p]);
    EXPECT_LE(pages[p].nodes.size() * sizeof(SphereNode), page_bytes) << "page " << p;
    EXPECT_EQ(pages[p].nodes.size(), source->page_node_count(p));
    nodes += pages[p].nodes.size();
  }
  EXPECT_EQ(nodes, tree.nodes.size());
  std::vector<Item> stack{{0, 0, 0}};
  std::uint64_t visited = 0;
  while (!stack.empty()) {
    const Item it = stack.back();
    stack.pop_back();
    ++visited;
    const SphereNode& a = pages[it.page].nodes[it.local];
    const SphereNode& b = tree.nodes[it.global];
    ASSERT_EQ(a.center, b.center);
    ASSERT_EQ(a.radius, b.radius);
    ASSERT_EQ(a.child_count, b.child_count);
    const std::uint32_t cp = pages[it.page].child_page[it.local];
    for (std::uint32_t c = 0; c < a.child_count; ++c) {
      if (cp == kNoPage) {
        stack.push_back({it.page, a.first_child + c, b.first_child + c});
      } else {
        EXPECT_TRUE(seen_pages.insert(cp).second || c > 0) << "page " << cp << " has two anchors";
        EXPECT_EQ(a.first_child, 0u);  // paginate gives each page one anchor
        stack.push_back({cp, a.first_child + c, b.first_child + c});
      }
    }
  }
  EXPECT_EQ(visited, tree.nodes.size());
  EXPECT_EQ(seen_pages.size() + 1, source->page_count());
}

TEST(PagedRender, WithEveryPageResidentTheImageIsRendersBitForBit) {
  ThreadPool pool(2);
  const SphereTree& tree = demo_tree();
  const auto source = paginate(tree.view(), 8192);
  PagedRenderer paged(*source, UINT64_MAX, pool);
  for (float az : {0.0f, 130.0f}) {
    const Camera cam = view(az);
    Frame expected, frame;
    render(tree.view(), cam, RenderSettings{}, pool, expected);
    render_until_settled(paged, cam, pool, frame);
    EXPECT_TRUE(paged.complete());
    EXPECT_EQ(frame.stats.splats, expected.stats.splats) << "azimuth " << az;
    EXPECT_EQ(frame.color, expected.color) << "azimuth " << az;
    EXPECT_EQ(frame.depth, expected.depth) << "azimuth " << az;
  }
}

TEST(PagedRender, QualityModeWithEveryPageResidentIsRenderQualityBitForBit) {
  ThreadPool pool(2);
  const SphereTree& tree = demo_tree();
  const auto source = paginate(tree.view(), 8192);
  PagedRenderer paged(*source, UINT64_MAX, pool);
  QualityScratch scratch;
  for (const Reconstruction rule : {Reconstruction::ZRange, Reconstruction::ZThreshold}) {
    const QualitySettings quality{.reconstruction = rule};
    const Camera cam = view(70);
    Frame expected, frame;
    render_quality(tree.view(), cam, RenderSettings{}, quality, pool, expected);
    render_until_settled(paged, cam, pool, frame);  // loads the pages in the fast mode
    ASSERT_TRUE(paged.complete());
    paged.render_quality(cam, RenderSettings{}, quality, pool, frame, scratch);
    EXPECT_EQ(frame.stats.splats, expected.stats.splats);
    EXPECT_EQ(frame.color, expected.color);
    EXPECT_EQ(frame.depth, expected.depth);
  }
}

TEST(PagedRender, QualityModeUnderACapDrawsItsStandInsWithoutHoles) {
  // A cap that holds only the top pages: stand-ins enclose their subtrees, so the quality image
  // covers what the full quality image covers.
  ThreadPool pool(2);
  const SphereTree& tree = demo_tree();
  const auto source = paginate(tree.view(), 4096);
  const std::uint64_t total = all_pages_memory(*source);
  PagedRenderer capped(*source, total / 6, pool);
  const Camera cam = view(20);
  Frame full, frame;
  render_quality(tree.view(), cam, RenderSettings{}, QualitySettings{}, pool, full);
  render_until_settled(capped, cam, pool, frame);
  QualityScratch scratch;
  capped.render_quality(cam, RenderSettings{}, QualitySettings{}, pool, frame, scratch);
  EXPECT_LE(capped.stats().resident_bytes_peak, total / 6);
  EXPECT_LT(frame.stats.splats, full.stats.splats);
  const ImageComparison c = compare(full, frame);
  EXPECT_GT(c.interior_count, 1000u);
  EXPECT_EQ(c.hole_count, 0u);
}

TEST(PagedRender, FirstFrameFromTheFirstPageAloneHasNoHoles) {
  // Only page 0 is resident: its deepest nodes stand in for their subtrees as splats of their
  // bounding spheres, which enclose everything below, so the silhouette can only grow.
  ThreadPool pool(2);
  const SphereTree& tree = demo_tree();
  const auto source = paginate(tree.view(), 16384);
  PagedRenderer paged(*source, UINT64_MAX, pool);
  const Camera cam = view(40);
  Frame full, first;
  render(tree.view(), cam, RenderSettings{}, pool, full);
  paged.render(cam, RenderSettings{}, pool, first);
  EXPECT_FALSE(paged.complete());
  EXPECT_EQ(paged.stats().pages_loaded, 1u);
  EXPECT_LT(first.stats.splats, full.stats.splats);
  const ImageComparison c = compare(full, first);
  EXPECT_EQ(c.hole_count, 0u);
  EXPECT_GT(c.interior_count, 2000u);
}

TEST(PagedRender, ProgressiveFramesReadMoreAndConvergeToTheFullImage) {
  ThreadPool pool(2);
  const SphereTree& tree = demo_tree();
  const auto source = paginate(tree.view(), 4096);
  PagedRenderer paged(*source, UINT64_MAX, pool);
  const Camera cam = view(75);
  Frame full, frame;
  render(tree.view(), cam, RenderSettings{}, pool, full);
  std::uint64_t last_bytes = 0;
  double first_mse = -1, last_mse = -1;
  for (int i = 0; i < 100 && !(i > 0 && paged.complete()); ++i) {
    paged.render(cam, RenderSettings{}, pool, frame);
    const ImageComparison c = compare(full, frame);
    EXPECT_EQ(c.hole_count, 0u) << "frame " << i;
    if (first_mse < 0) first_mse = c.mse;
    last_mse = c.mse;
    EXPECT_GE(paged.stats().bytes_read, last_bytes);
    last_bytes = paged.stats().bytes_read;
    paged.load_requested(pool);
  }
  EXPECT_TRUE(paged.complete());
  EXPECT_GT(first_mse, 0.0);
  EXPECT_EQ(last_mse, 0.0);
  EXPECT_EQ(frame.color, full.color);
}

TEST(PagedRender, MemoryCapHoldsAndTheImageStillHasNoHoles) {
  ThreadPool pool(2);
  const SphereTree& tree = demo_tree();
  const auto source = paginate(tree.view(), 4096);
  const std::uint64_t total = all_pages_memory(*source);
  const std::uint64_t cap = total / 10;
  PagedRenderer paged(*source, cap, pool);
  // Orbit around the model: pages of the far side are dropped for those of the near side.
  for (float az = 0; az < 360; az += 45) {
    const Camera cam = view(az, 1.2f);
    Frame full, frame;
    render(tree.view(), cam, RenderSettings{}, pool, full);
    render_until_settled(paged, cam, pool, frame);
    EXPECT_LE(paged.stats().resident_bytes, cap);
    EXPECT_EQ(compare(full, frame).hole_count, 0u) << "azimuth " << az;
  }
  EXPECT_LE(paged.stats().resident_bytes_peak, cap);
  EXPECT_GT(paged.stats().pages_evicted, 0u);
  EXPECT_LT(paged.stats().resident_pages, source->page_count());
}

TEST(PagedRender, CapBelowTheFirstPageIsRefusedWithTheSizeNeeded) {
  ThreadPool pool(1);
  const auto source = paginate(demo_tree().view(), 65536);
  const std::uint64_t first = HierarchyPage::memory_bytes(source->page_node_count(0));
  try {
    PagedRenderer paged(*source, first - 1, pool);
    FAIL() << "expected OptionError";
  } catch (const OptionError& e) {
    EXPECT_NE(std::string(e.what()).find(std::to_string(first)), std::string::npos) << e.what();
  }
  EXPECT_THROW(paginate(demo_tree().view(), 100), OptionError);
}

TEST(PagedRender, BackgroundLoaderReachesTheFullImageAndHoldsTheCap) {
  // Pages decoded on the loader thread while frames render: whatever the timing, the frames
  // never show holes, the cap holds, and once everything has arrived the image is render()'s.
  ThreadPool pool(2);
  const SphereTree& tree = demo_tree();
  const auto source = paginate(tree.view(), 4096, 4);
  const Camera cam = view(200);
  Frame full, frame;
  render(tree.view(), cam, RenderSettings{}, pool, full);
  {
    PagedRenderer paged(*source, UINT64_MAX, pool);
    for (int i = 0; i < 400; ++i) {
      paged.render(cam, RenderSettings{}, pool, frame);
      EXPECT_EQ(compare(full, frame).hole_count, 0u) << "frame " << i;
      if (paged.complete()) break;
      paged.request_in_background(SIZE_MAX, 64 * 1024);
      if (i % 8 == 7) paged.wait_for_loader();
    }
    EXPECT_TRUE(paged.complete());
    EXPECT_EQ(frame.color, full.color);
  }
  const std::uint64_t total = all_pages_memory(*source);
  PagedRenderer capped(*source, total / 8, pool);
  for (float az = 0; az < 360; az += 60) {
    for (int i = 0; i < 60; ++i) {
      capped.render(view(az, 1.2f), RenderSettings{}, pool, frame);
      if (capped.request_in_background() == 0) capped.wait_for_loader();
      if (capped.complete()) break;
    }
    EXPECT_LE(capped.stats().resident_bytes_peak, total / 8) << "azimuth " << az;
  }
}

TEST(PagedRender, ImageDoesNotDependOnTheThreadCount) {
  // Partly resident (two load rounds), so stand-ins and refined subtrees mix.
  const SphereTree& tree = demo_tree();
  const auto source = paginate(tree.view(), 4096, 4);
  std::vector<Rgb8> images[2];
  std::uint64_t requested[2] = {};
  for (unsigned threads : {1u, 2u}) {
    ThreadPool pool(threads);
    PagedRenderer paged(*source, UINT64_MAX, pool);
    Frame frame;
    for (int i = 0; i < 3; ++i) {
      paged.render(view(310), RenderSettings{}, pool, frame);
      if (i < 2) paged.load_requested(pool, 6);
    }
    images[threads - 1].assign(frame.color.begin(), frame.color.end());
    requested[threads - 1] = paged.stats().pages_requested;
  }
  EXPECT_GT(requested[0], 0u);
  EXPECT_EQ(requested[0], requested[1]);
  EXPECT_EQ(images[0], images[1]);
}
