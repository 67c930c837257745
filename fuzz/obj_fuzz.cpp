// libFuzzer harness for read_obj and the OBJ stream: vertices with and without colours, normals,
// faces with every corner form and negative indices; what read_obj reads, the stream must give,
// and the face stream (open_face_stream) its triangles.
#include "fuzz_support.hpp"
#include "pointillist/io/obj.hpp"
#include "pointillist/io/point_stream.hpp"

using namespace pointillist;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static fuzz::InputFile file;
  fuzz::check_reader_and_stream(file, data, size, ".obj",
                                [](const std::string& path) { return read_obj(path); });
  const std::string& named = file.named(".obj");
  PointSet whole;
  bool read = false;
  fuzz::expect_reader_errors(named, [&] {
    whole = read_obj(named);
    read = true;
  });
  fuzz::expect_face_stream_matches(named, read, whole);
  return 0;
}
