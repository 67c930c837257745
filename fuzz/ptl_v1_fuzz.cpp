// libFuzzer harness for .ptl version 1 (mapped float nodes): PtlFile::open's validation, which
// the traversal then trusts, checked by drawing the model at 32x24; read_ptl's copy too.
#include "fuzz_support.hpp"
#include "pointillist/format/ptl.hpp"
#include "pointillist/format/ptl_v2.hpp"

using namespace pointillist;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static fuzz::InputFile file;
  static ThreadPool pool(1);
  const std::string& path = file.write(data, size);
  fuzz::expect_reader_errors(path, [&] {
    (void)ptl_file_version(path);
    const PtlModel copy = read_ptl(path);
    const Model model = open_model(path, {.paging = Paging::Never}, pool, Progress::none());
    fuzz::render_small(model, pool);
  });
  return 0;
}
