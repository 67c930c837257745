// libFuzzer harness for read_xyz, the text scan reader: separators, header lines, PTS counts,
// column detection, normals against colours, large coordinates; what read_xyz reads, the stream
// must give.
#include "fuzz_support.hpp"
#include "pointillist/io/xyz.hpp"

using namespace pointillist;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static fuzz::InputFile file;
  fuzz::check_reader_and_stream(file, data, size, ".xyz",
                                [](const std::string& path) { return read_xyz(path); });
  return 0;
}
