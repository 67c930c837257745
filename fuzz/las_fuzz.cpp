// libFuzzer harness for read_las: the public header, variable-length records, point formats
// 0 to 10, the origin shift and colour scaling.
#include "fuzz_support.hpp"
#include "pointillist/io/las.hpp"

using namespace pointillist;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static fuzz::InputFile file;
  const std::string& path = file.write(data, size);
  fuzz::expect_reader_errors(path, [&] { fuzz::check_point_set(read_las(path)); });
  return 0;
}
