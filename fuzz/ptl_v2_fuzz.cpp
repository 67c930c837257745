// libFuzzer harness for .ptl version 2 (quantized pages): PtlV2File::open (header, schema, page
// table), decode_all, the sharp-features section, the mesh faces' section, every page through the page source (as the paged renderer loads them),
// and the model opened decoded and paged by open_model, each drawn at 32x24.
#include "fuzz_support.hpp"
#include "pointillist/format/ptl_v2.hpp"
#include "pointillist/format/ptl_v2_pages.hpp"

using namespace pointillist;

namespace {

// Pages decode independently, so a corrupt one must not stop the others from being tried.
void load_every_page(const std::string& path) {
  const std::unique_ptr<PtlV2File> file = PtlV2File::open(path);
  fuzz::expect_reader_errors(path, [&] { (void)file->decode_all(); });
  fuzz::expect_reader_errors(path, [&] { (void)file->features(); });
  fuzz::expect_reader_errors(path, [&] {
    for (const auto& t : file->triangles()) {
      for (const std::uint32_t c : t) {
        if (c >= file->leaf_count()) fuzz::finding("a triangle corner beyond the leaves");
      }
    }
  });
  const std::unique_ptr<PageSource> source = ptl_v2_page_source(*file);
  (void)source->summary();
  HierarchyPage page;
  for (std::uint32_t p = 0; p < source->page_count(); ++p) {
    fuzz::expect_reader_errors(path, [&] {
      source->load(p, page);
      if (page.node_count() != source->page_node_count(p))
        fuzz::finding("page " + std::to_string(p) + " loaded with another node count");
    });
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static fuzz::InputFile file;
  static ThreadPool pool(1);
  const std::string& path = file.write(data, size);
  fuzz::expect_reader_errors(path, [&] { load_every_page(path); });
  for (Paging paging : {Paging::Never, Paging::Always}) {
    fuzz::expect_reader_errors(path, [&] {
      const Model model = open_model(path, {.paging = paging}, pool, Progress::none());
      fuzz::render_small(model, pool);
    });
  }
  return 0;
}
