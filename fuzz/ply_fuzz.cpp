// libFuzzer harness for read_ply: ascii and binary (both byte orders) bodies, gzip, the header
// parser; the seeds hold one of each. The face stream (open_face_stream, binary or ASCII) runs on
// the same input: it may refuse only as readers do, and where read_ply read the file, it must
// give the same triangles.
#include "fuzz_support.hpp"
#include "pointillist/io/ply.hpp"
#include "pointillist/io/point_stream.hpp"

using namespace pointillist;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static fuzz::InputFile file;
  const std::string& path = file.write(data, size);
  PointSet whole;
  bool read = false;
  fuzz::expect_reader_errors(path, [&] {
    whole = read_ply(path);
    fuzz::check_point_set(whole);
    read = true;
  });
  fuzz::expect_face_stream_matches(file.named(".ply"), read, whole);
  return 0;
}
