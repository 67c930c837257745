// Loading a page's first levels only (PagePrefix): what a paged view reads where its detail ends
// in a page's first levels. The expectations come from decode_page, the separate decoder of a
// whole page: its levels (counted here from the decoded child counts), its records and its
// nodes' first children.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "format/format_test_support.hpp"
#include "pointillist/format/ptl_v2.hpp"
#include "pointillist/format/ptl_v2_pages.hpp"
#include "pointillist/render/paged.hpp"
#include "pointillist/render/render.hpp"
#include "testing/testing.hpp"

using namespace pointillist;
using namespace pointillist::format_test;  // NOLINT(google-build-using-namespace)
using pointillist::testing::TempDir;

namespace {

// The end record of each level of a decoded page: level 1 holds the roots' children, each next
// level the children of the previous level's interior nodes.
std::vector<std::uint32_t> level_ends(const PtlV2Page& page) {
  std::vector<std::uint32_t> ends;
  std::uint32_t begin = 0, size = 0;
  for (const std::uint8_t k : page.root_child_counts) size += k;
  while (size > 0 && begin + size <= page.nodes.size()) {
    ends.push_back(begin + size);
    std::uint32_t next = 0;
    if (ends.back() < page.nodes.size()) {
      for (std::uint32_t i = begin; i < begin + size; ++i) next += page.nodes[i].child_count;
    }
    begin += size;
    size = next;
  }
  return ends;
}

// The number of levels a prefix takes, from its definition.
std::size_t expected_levels(const std::vector<std::uint32_t>& ends, const PagePrefix& prefix) {
  std::size_t node_level = 0;
  for (std::size_t l = 0; l < ends.size(); ++l) {
    if (node_level == 0 && prefix.node < ends[l]) node_level = l + 1;
    const std::size_t levels = l + 1;
    if (node_level != 0 && levels >= node_level + prefix.extra_levels &&
        ends[l] >= prefix.min_nodes) {
      return levels;
    }
  }
  return ends.size();
}

}  // namespace

TEST(PtlV2Prefix, APrefixIsThePagesFirstWholeLevelsLinkedToTheRest) {
  TempDir dir;
  for (const bool colors : {false, true}) {
    SCOPED_TRACE(colors ? "colours" : "no colours");
    const std::string path = dir.file("m.ptl");
    write_ptl_v2(path, scene_tree(30000, 81, colors), "", {.page_bytes = 16384});
    const auto file = PtlV2File::open(path);
    const auto source = ptl_v2_page_source(*file);
    const std::uint32_t record_size = colors ? 6 : 4;
    std::size_t partial = 0;
    for (std::uint32_t p = 0; p < file->page_count(); ++p) {
      PtlV2Page decoded;
      file->decode_page(p, decoded);
      const std::vector<std::uint32_t> ends = level_ends(decoded);
      ASSERT_EQ(ends.back(), decoded.nodes.size()) << "page " << p;
      HierarchyPage whole;
      source->load(p, whole);
      ASSERT_EQ(whole.node_count(), decoded.nodes.size());
      EXPECT_EQ(whole.storage_bytes, file->page_info(p).byte_size);
      const std::uint32_t second = ends[0];  // the second level's first record
      for (const PagePrefix prefix :
           {PagePrefix{.node = 0}, PagePrefix{.node = 0, .extra_levels = 1},
            PagePrefix{.node = second, .extra_levels = 0}, PagePrefix{.node = 0, .min_nodes = 200},
            PagePrefix{.node = second, .extra_levels = 2, .min_nodes = 50}}) {
        SCOPED_TRACE("page " + std::to_string(p) + ", prefix node " +
                     std::to_string(prefix.node) + " +" + std::to_string(prefix.extra_levels) +
                     " levels, at least " + std::to_string(prefix.min_nodes));
        const std::size_t levels = expected_levels(ends, prefix);
        const std::uint32_t count = ends[levels - 1];
        HierarchyPage page;
        source->load(p, page, prefix);
        ASSERT_EQ(page.node_count(), count);
        EXPECT_EQ(page.storage_bytes,
                  std::uint64_t{file->page_info(p).root_count} * 17 + count * record_size);
        for (std::uint32_t i = 0; i < count; ++i) {
          ASSERT_EQ(page.packed.records[i], whole.packed.records[i]) << "record " << i;
          if (colors) {
            ASSERT_EQ(page.packed.colors[i], whole.packed.colors[i]);
          }
        }
        if (levels == ends.size()) {
          // The whole page: its last level links to the child pages, as a whole load does.
          EXPECT_EQ(page.packed.last_level_begin, decoded.last_level_begin);
          ASSERT_EQ(page.packed.links.size(), whole.packed.links.size());
          for (std::size_t k = 0; k < page.packed.links.size(); ++k) {
            EXPECT_EQ(page.packed.links[k].page, whole.packed.links[k].page);
            EXPECT_EQ(page.packed.links[k].first, whole.packed.links[k].first);
          }
          continue;
        }
        ++partial;
        EXPECT_LE(page.memory_bytes(), source->page_memory_bytes(p));
        // Every interior node's link index is its first child's record in the whole page (past
        // the loaded records for the last loaded level); no links to other pages.
        EXPECT_EQ(page.packed.last_level_begin, count);
        EXPECT_TRUE(page.packed.links.empty());
        for (std::uint32_t i = 0; i < count; ++i) {
          const SphereNode& n = decoded.nodes[i];
          if (n.child_count == 0) continue;
          EXPECT_EQ(page.packed.link(i), n.first_child) << "record " << i;
          if (i >= (levels == 1 ? 0 : ends[levels - 2])) {
            EXPECT_GE(page.packed.link(i), count) << "record " << i;
          }
        }
      }
    }
    EXPECT_GT(partial, file->page_count());
  }
}

TEST(PtlV2Prefix, CoarseViewsReadThePagesFirstLevelsAndDrawTheWholeModelsImage) {
  // A model of deep pages: each settled frame is the frame of the whole decoded model. Seen
  // coarsely, what was read is a fraction of the pages it touched; seen finer, pages are
  // deepened, reading only what they lacked (each load reads its page's root table again).
  ThreadPool pool(2);
  TempDir dir;
  const std::string path = dir.file("m.ptl");
  write_ptl_v2(path, scene_tree(60000, 82, true), "", {.page_bytes = 32768});
  const auto file = PtlV2File::open(path);
  const SphereTree tree = file->decode_all();
  struct View {
    int width;
    float threshold;
    double max_share;  // of the touched pages' bytes
  };
  for (const View view : {View{64, 8.0f, 0.5}, View{64, 5.0f, 1.05}, View{160, 1.0f, 1.05}}) {
    SCOPED_TRACE(std::to_string(view.width) + " pixels wide, threshold " +
                 std::to_string(view.threshold));
    const auto source = ptl_v2_page_source(*file);
    PagedRenderer paged(*source, UINT64_MAX, pool);
    const Camera cam =
        orbit_camera(file->view_sphere(), {.width = view.width, .height = view.width * 3 / 4});
    const RenderSettings settings{.threshold_px = view.threshold};
    Frame frame;
    for (int frames = 0; frames < 200; ++frames) {
      paged.render(cam, settings, pool, frame);
      if (paged.complete() || paged.load_requested(pool) == 0) break;
    }
    ASSERT_TRUE(paged.complete());
    Frame expected;
    render(tree.view(), cam, settings, pool, expected);
    EXPECT_TRUE(frame.color == expected.color);
    EXPECT_TRUE(frame.depth == expected.depth);
    std::uint64_t whole = 0;
    for (std::uint32_t p = 0; p < file->page_count(); ++p) {
      if (paged.cache().pages()[p]) whole += file->page_info(p).byte_size;
    }
    const PagedRenderStats& s = paged.stats();
    EXPECT_EQ(s.resident_page_bytes, whole);
    EXPECT_LE(double(s.bytes_read - source->open_bytes()), view.max_share * double(whole))
        << s.pages_loaded << " pages loaded, " << s.pages_deepened << " deepened";
    if (view.threshold == 5.0f) {  // (seen fine, the first loads take whole pages)
      EXPECT_GT(s.pages_deepened, 0u);
    }
  }
}
