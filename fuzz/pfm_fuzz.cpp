// libFuzzer harness for PFM depth images (compare --depth, generate --reference-depth): read_pfm
// refuses with a FormatError naming the file, or reads an image that writes back and reads again
// to the same bits.
#include <unistd.h>

#include <cstring>
#include <string>

#include "fuzz_support.hpp"
#include "pointillist/io/pfm.hpp"

using namespace pointillist;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static fuzz::InputFile file;
  static const std::string copy = "/tmp/pointillist-fuzz-pfm-" + std::to_string(getpid()) + ".pfm";
  const std::string& path = file.write(data, size);
  fuzz::expect_reader_errors(path, [&] {
    const ImageFloat image = read_pfm(path);
    if (image.pixels.size() != static_cast<std::size_t>(image.width) * image.height) {
      fuzz::finding("read_pfm returned " + std::to_string(image.pixels.size()) + " pixels for " +
                    std::to_string(image.width) + "x" + std::to_string(image.height));
    }
    write_pfm(copy, image.width, image.height, image.pixels);
    const ImageFloat back = read_pfm(copy);
    if (back.width != image.width || back.height != image.height ||
        std::memcmp(back.pixels.data(), image.pixels.data(), 4 * image.pixels.size()) != 0) {
      fuzz::finding("a PFM written back does not read to the same bits");
    }
  });
  return 0;
}
