// libFuzzer harness for read_obj and the OBJ stream: vertices with and without colours, normals,
// faces with every corner form and negative indices; what read_obj reads, the stream must give.
#include "fuzz_support.hpp"
#include "pointillist/io/obj.hpp"

using namespace pointillist;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static fuzz::InputFile file;
  const std::string& path = file.write(data, size);
  PointSet whole;
  bool read = false;
  fuzz::expect_reader_errors(path, [&] {
    whole = read_obj(path);
    fuzz::check_point_set(whole);
    read = true;
  });
  // The stream (a window of lines at a time) must give what the whole reader gave.
  if (read) fuzz::expect_stream_matches(file.named(".obj"), whole);
  return 0;
}
