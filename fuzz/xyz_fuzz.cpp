// libFuzzer harness for read_xyz, the text scan reader: separators, header lines, PTS counts,
// column detection, normals against colours, large coordinates.
#include "fuzz_support.hpp"
#include "pointillist/io/xyz.hpp"

using namespace pointillist;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static fuzz::InputFile file;
  const std::string& path = file.write(data, size);
  fuzz::expect_reader_errors(path, [&] { fuzz::check_point_set(read_xyz(path)); });
  return 0;
}
