// libFuzzer harness for read_ply: ascii and binary (both byte orders) bodies, gzip, the header
// parser; the seeds hold one of each.
#include "fuzz_support.hpp"
#include "pointillist/io/ply.hpp"

using namespace pointillist;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static fuzz::InputFile file;
  const std::string& path = file.write(data, size);
  fuzz::expect_reader_errors(path, [&] { fuzz::check_point_set(read_ply(path)); });
  return 0;
}
