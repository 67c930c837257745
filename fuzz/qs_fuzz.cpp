// libFuzzer harness for QSplat .qs files: read_qs (fragments, groups, records, the enclosure
// fix), then the model as open_model decodes it, drawn at 32x24.
#include "fuzz_support.hpp"
#include "pointillist/format/qs.hpp"

using namespace pointillist;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static fuzz::InputFile file;
  static ThreadPool pool(1);
  const std::string& path = file.write(data, size);
  fuzz::expect_reader_errors(path, [&] {
    const QsModel qs = read_qs(path);
    (void)qs.metadata();
    const Model model = open_model(path, {.paging = Paging::Never}, pool, Progress::none());
    fuzz::render_small(model, pool);
  });
  return 0;
}
