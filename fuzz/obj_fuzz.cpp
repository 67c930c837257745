// libFuzzer harness for read_obj: vertices with and without colours, normals, faces with every
// corner form and negative indices.
#include "fuzz_support.hpp"
#include "pointillist/io/obj.hpp"

using namespace pointillist;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static fuzz::InputFile file;
  const std::string& path = file.write(data, size);
  fuzz::expect_reader_errors(path, [&] { fuzz::check_point_set(read_obj(path)); });
  return 0;
}
