// Paged rendering straight from .ptl version 2 files: pages stay packed and are decoded during
// the traversal. The reference is the in-memory renderer over the whole decoded model
// (PtlV2File::decode_all), whose decoder is separate code.
#include "pointillist/format/ptl_v2_pages.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "format/format_test_support.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/format/ptl_v2.hpp"
#include "pointillist/render/paged.hpp"
#include "pointillist/render/quality.hpp"
#include "pointillist/render/render.hpp"
#include "testing/testing.hpp"

using namespace pointillist;
using namespace pointillist::format_test;  // NOLINT(google-build-using-namespace)
using pointillist::testing::TempDir;

namespace {

constexpr std::size_t kPageTableAt = 256, kPageEntryBytes = 32, kRootEntryBytes = 17;

// Renders until nothing more is wanted (every page the view needs is resident).
void render_settled(PagedRenderer& r, const Camera& cam, const RenderSettings& settings,
                    ThreadPool& pool, Frame& frame) {
  for (int i = 0; i < 500; ++i) {
    r.render(cam, settings, pool, frame);
    if (r.complete() || r.load_requested(pool) == 0) return;
  }
  FAIL() << "did not settle";
}

struct Variant {
  bool colors;
  quant::LeafTrim trim;
  std::uint32_t page_bytes;
};

}  // namespace

TEST(PtlV2Pages, FullyResidentFramesAreBitIdenticalToTheDecodedModel) {
  ThreadPool pool(2);
  TempDir dir;
  for (const Variant variant : {Variant{false, quant::LeafTrim::Sixteenths, 1024},
                                Variant{true, quant::LeafTrim::Sixteenths, 1024},
                                Variant{true, quant::LeafTrim::Eighths, 1024},
                                Variant{false, quant::LeafTrim::Sixteenths, 1u << 20}}) {
    SCOPED_TRACE(std::string(variant.colors ? "colours, " : "no colours, ") +
                 (variant.trim == quant::LeafTrim::Eighths ? "eighths, " : "sixteenths, ") +
                 std::to_string(variant.page_bytes) + "-byte pages");
    const std::string path = dir.file("m.ptl");
    write_ptl_v2(path, scene_tree(20000, 61, variant.colors), "",
                 {.page_bytes = variant.page_bytes, .leaf_trim = variant.trim});
    const auto file = PtlV2File::open(path);
    // Small pages: many pages, link blocks straddling each page's last level; large: one page
    // of all ~28,000 nodes.
    ASSERT_EQ(file->page_count() > 20u, variant.page_bytes == 1024);
    const SphereTree decoded = file->decode_all();
    const auto source = ptl_v2_page_source(*file);
    PagedRenderer paged(*source, UINT64_MAX, pool);
    for (const float azimuth : {0.0f, 130.0f}) {
      for (const bool backface : {true, false}) {
        const Camera cam = orbit_camera(file->view_sphere(),
                                        {.azimuth_deg = azimuth, .elevation_deg = 25,
                                         .distance = 1.6f, .width = 240, .height = 180});
        RenderSettings settings;
        settings.backface_culling = backface;
        Frame expected, frame;
        render(decoded.view(), cam, settings, pool, expected);
        render_settled(paged, cam, settings, pool, frame);
        EXPECT_EQ(frame.stats.splats, expected.stats.splats) << "azimuth " << azimuth;
        EXPECT_EQ(frame.stats.nodes_visited, expected.stats.nodes_visited);
        EXPECT_TRUE(frame.color == expected.color) << "azimuth " << azimuth;
        EXPECT_TRUE(frame.depth == expected.depth) << "azimuth " << azimuth;
        // The quality mode draws the same selection: the same image as on the decoded model.
        Frame expected_quality, quality_frame;
        QualityScratch scratch;
        render_quality(decoded.view(), cam, settings, QualitySettings{}, pool, expected_quality);
        paged.render_quality(cam, settings, QualitySettings{}, pool, quality_frame, scratch);
        EXPECT_TRUE(quality_frame.color == expected_quality.color) << "azimuth " << azimuth;
        EXPECT_TRUE(quality_frame.depth == expected_quality.depth) << "azimuth " << azimuth;
      }
    }
  }
}

TEST(PtlV2Pages, ResidentPagesTakeAboutTheFilesBytesNotTheDecodedNodes) {
  ThreadPool pool(2);
  TempDir dir;
  for (const bool colors : {false, true}) {
    const std::string path = dir.file("m.ptl");
    const PtlV2WriteReport report =
        write_ptl_v2(path, scene_tree(20000, 62, colors), "", {.page_bytes = 4096});
    const auto file = PtlV2File::open(path);
    const auto source = ptl_v2_page_source(*file);
    PagedRenderer paged(*source, UINT64_MAX, pool);
    const Camera cam = orbit_camera(file->view_sphere(), {.width = 320, .height = 240});
    Frame frame;
    render_settled(paged, cam, RenderSettings{}, pool, frame);
    // Every node as its record (4 bytes, 6 with colour) and a 1-byte link step, a 4-byte link
    // base per 64 nodes (two more per page for partial blocks), and an 8-byte link for every
    // root of a child page.
    std::uint64_t expected = 0, nodes = 0;
    for (std::uint32_t p = 0; p < file->page_count(); ++p) {
      const std::uint64_t n = file->page_info(p).node_count;
      expected += n * (colors ? 7 : 5) + (n / 64 + 2) * 4;
      if (p > 0) expected += 8 * std::uint64_t{file->page_info(p).root_count};
      nodes += n;
    }
    ASSERT_EQ(paged.stats().resident_pages, file->page_count()) << "a whole view of the model";
    EXPECT_EQ(paged.stats().resident_bytes, expected);
    // Against the file's records: about 1.3 times them (1.2 with colours) with the links.
    EXPECT_LE(double(paged.stats().resident_bytes), 1.35 * double(report.record_bytes));
    // Decoded, the same nodes would take 44 bytes each.
    EXPECT_LT(paged.stats().resident_bytes * 6, HierarchyPage::memory_bytes(nodes));
  }
}

TEST(PtlV2Pages, ChildPageWhoseRootsDisagreeWithTheParentRecordIsRejectedOnLoad) {
  ThreadPool pool(2);
  TempDir dir;
  const std::string path = dir.file("m.ptl");
  write_ptl_v2(path, scene_tree(6000, 63, false), "", {.page_bytes = 1024});
  Bytes b = read_bytes(path);
  ASSERT_GT(get_u32(b, 52), 2u);
  // Page 1's first root claims one child fewer or more than its record in page 0 says.
  const std::size_t entry1 = kPageTableAt + kPageEntryBytes;
  const std::size_t page1 = get_u64(b, entry1);
  const std::uint32_t roots = get_u32(b, entry1 + 24);
  const std::size_t count_at = page1 + 16 * roots;
  ASSERT_GE(b[count_at], 2);
  ASSERT_LE(b[count_at], 4);
  b[count_at] = b[count_at] == 4 ? 3 : b[count_at] + 1;
  write_bytes(path, b);
  const auto file = PtlV2File::open(path);
  const auto source = ptl_v2_page_source(*file);
  HierarchyPage page;
  try {
    source->load(1, page);
    ADD_FAILURE() << "no error";
  } catch (const FormatError& e) {
    const std::string m = e.what();
    // Either the page's own levels no longer add up, or its root disagrees with the record.
    EXPECT_NE(m.find(path + ": byte "), std::string::npos) << m;
    EXPECT_NE(m.find("page 1"), std::string::npos) << m;
  }
}

TEST(PtlV2Pages, Bit15IsALeafTrimBitOnlyWhereTheSchemaSaysSo) {
  TempDir dir;
  for (const auto trim : {quant::LeafTrim::Eighths, quant::LeafTrim::Sixteenths}) {
    const std::string path = dir.file("m.ptl");
    write_ptl_v2(path, scene_tree(3000, 64, false), "", {.page_bytes = 1024, .leaf_trim = trim});
    const Bytes good = read_bytes(path);
    const std::size_t page0 = get_u64(good, kPageTableAt);
    const std::size_t root_record = page0 + kRootEntryBytes;  // page 0 has one root entry
    // The root is an interior node: bit 15 set is an error in either layout.
    Bytes b = good;
    b[root_record + 1] |= 0x80;
    write_bytes(path, b);
    const auto file = PtlV2File::open(path);
    const auto source = ptl_v2_page_source(*file);
    HierarchyPage page;
    try {
      source->load(0, page);
      ADD_FAILURE() << "no error";
    } catch (const FormatError& e) {
      EXPECT_NE(std::string(e.what()).find("reserved bit 15"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(": byte " + std::to_string(root_record + 1)),
                std::string::npos)
          << e.what();
    }
  }
}

TEST(PtlV2Pages, RandomCorruptionIsRejectedOrRenderedNeverMisread) {
  // Seeded random byte flips in the pages, then a paged render of every page the view wants:
  // loading either succeeds (a flipped code is still a valid code) or throws FormatError; under
  // ASan this also checks that the traversal never reads outside a page.
  ThreadPool pool(2);
  TempDir dir;
  const std::string path = dir.file("fuzz.ptl");
  write_ptl_v2(path, scene_tree(4000, 65, true), "meta", {.page_bytes = 1024});
  const Bytes good = read_bytes(path);
  const std::size_t pages_at = get_u64(good, kPageTableAt);
  std::mt19937 rng(66);
  std::size_t rejected = 0;
  for (int trial = 0; trial < 150; ++trial) {
    Bytes b = good;
    for (int k = 0; k < 1 + trial % 4; ++k) {
      b[pages_at + rng() % (b.size() - pages_at)] ^= std::uint8_t(1u << (rng() % 8));
    }
    write_bytes(path, b);
    try {
      const auto file = PtlV2File::open(path);
      const auto source = ptl_v2_page_source(*file);
      PagedRenderer paged(*source, UINT64_MAX, pool);
      const Camera cam = orbit_camera(file->view_sphere(),
                                      {.azimuth_deg = float(trial * 7), .width = 96, .height = 72});
      Frame frame;
      render_settled(paged, cam, RenderSettings{}, pool, frame);
    } catch (const FormatError& e) {
      ++rejected;
      EXPECT_NE(std::string(e.what()).find("page "), std::string::npos) << e.what();
    }
  }
  EXPECT_GT(rejected, 10u);  // most flips in records give other valid codes
}

namespace {

// The file pages mapped into this process (RssFile of /proc/self/status), in bytes.
std::uint64_t mapped_file_bytes() {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("RssFile:", 0) == 0) return std::stoull(line.substr(8)) * 1024;
  }
  return 0;
}

}  // namespace

TEST(PtlV2Pages, OpeningAModelReadsItsHeaderAndPageTableNotItsPages) {
  // A render of a model larger than memory must not read it all first: opening maps the file
  // and reads the header and page table; the pages come in when used. The file is in the page
  // cache (just written), so a mapping that is filled at once shows as that many bytes mapped;
  // touching the header and the metadata at its end maps up to about 512 KB around each here.
  TempDir dir;
  const std::string path = dir.file("m.ptl");
  write_ptl_v2(path, scene_tree(800000, 67, false), "", {.page_bytes = 32768});
  const std::uint64_t size = read_bytes(path).size();
  ASSERT_GT(size, 4u << 20);
  PtlV2File::open(path);  // the code that opens a file, mapped in before measuring
  const std::uint64_t before = mapped_file_bytes();
  const auto file = PtlV2File::open(path);
  const std::uint64_t opened = mapped_file_bytes();
  EXPECT_LT(opened, before + size / 3) << "opening a " << size << "-byte model mapped "
                                       << opened - before << " bytes of it";
  // Reading every page does map them (the measure sees the pages).
  const SphereTree tree = file->decode_all();
  EXPECT_GT(mapped_file_bytes(), before + size / 2);
  EXPECT_EQ(tree.nodes.size(), file->node_count());
}

TEST(PtlV2Pages, LoadedPagesDoNotStayMappedBesideTheirPackedCopies) {
  // A paged render copies each page it loads into a packed page, which the page cache counts
  // against its cap. The file's bytes it read must not stay in the process too: loading every
  // page of a model (in the page cache, just written) leaves under a third of the file mapped,
  // where reading the pages through the mapping alone maps over half of it (the measure sees
  // them, as the test above checks).
  TempDir dir;
  const std::string path = dir.file("m.ptl");
  write_ptl_v2(path, scene_tree(800000, 71, true), "", {.page_bytes = 32768});
  const std::uint64_t size = read_bytes(path).size();
  ASSERT_GT(size, 4u << 20);
  const auto file = PtlV2File::open(path);
  const auto source = ptl_v2_page_source(*file);
  ASSERT_GT(source->page_count(), 100u);
  HierarchyPage first;
  source->load(0, first, {});  // the code that loads, mapped in before measuring
  const std::uint64_t before = mapped_file_bytes();
  std::uint64_t nodes = 0;
  for (std::uint32_t q = 0; q < source->page_count(); ++q) {
    HierarchyPage page;  // (one that holds records is taken as an earlier prefix of q)
    source->load(q, page, {});
    nodes += page.packed.records.size();
    EXPECT_EQ(page.packed.records.size(), file->page_info(q).node_count);
  }
  EXPECT_EQ(nodes, file->node_count());
  const std::uint64_t after = mapped_file_bytes();
  EXPECT_LT(after, before + size / 3) << "loading every page of a " << size
                                      << "-byte model left " << after - before
                                      << " bytes of it mapped";
}
