// libFuzzer harness for read_obj and the OBJ stream: vertices with and without colours, normals,
// faces with every corner form and negative indices; what read_obj reads, the stream must give.
#include "fuzz_support.hpp"
#include "pointillist/io/obj.hpp"

using namespace pointillist;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static fuzz::InputFile file;
  fuzz::check_reader_and_stream(file, data, size, ".obj",
                                [](const std::string& path) { return read_obj(path); });
  return 0;
}
