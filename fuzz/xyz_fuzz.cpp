// libFuzzer harness for read_xyz, the text scan reader: separators, header lines, PTS counts,
// column detection, normals against colours, large coordinates; what read_xyz reads, the stream
// must give.
#include "fuzz_support.hpp"
#include "pointillist/io/xyz.hpp"

using namespace pointillist;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static fuzz::InputFile file;
  const std::string& path = file.write(data, size);
  PointSet whole;
  bool read = false;
  fuzz::expect_reader_errors(path, [&] {
    whole = read_xyz(path);
    fuzz::check_point_set(whole);
    read = true;
  });
  // The stream (a window of lines at a time) must give what the whole reader gave.
  if (read) fuzz::expect_stream_matches(file.named(".xyz"), whole);
  return 0;
}
