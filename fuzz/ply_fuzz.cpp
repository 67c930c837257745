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
  const std::string& named = file.named(".ply");
  bool opened = false, has_stream = false, streamed = false;
  std::vector<std::array<std::uint32_t, 3>> all;
  fuzz::expect_reader_errors(named, [&] {
    const std::unique_ptr<FaceStream> faces = open_face_stream(named);
    opened = true;
    if (!faces) return;  // no faces
    has_stream = true;
    std::vector<std::array<std::uint32_t, 3>> part;
    while (faces->read(part)) {
      all.insert(all.end(), part.begin(), part.end());
      if (read && all.size() > whole.triangles.size()) fuzz::finding("the face stream gives more");
    }
    streamed = true;
  });
  if (read && !opened) fuzz::finding("the face stream refused a header read_ply read");
  if (read && has_stream && !streamed) fuzz::finding("the face stream refused faces read_ply read");
  if (read && streamed && all != whole.triangles) {
    fuzz::finding("the face stream's triangles differ from read_ply's");
  }
  return 0;
}
