// PFM depth images: the writer's bytes against the format's definition written out by hand, the
// reader on hand-made files of both byte orders, and its refusals.
#include "pointillist/io/pfm.hpp"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>

#include "io_test_support.hpp"
#include "pointillist/core/error.hpp"
#include "testing/testing.hpp"

namespace pointillist {
namespace {

using testing::read_file;
using testing::TempDir;
using testing::write_file;

std::string le(float f) {
  const auto u = std::bit_cast<std::uint32_t>(f);
  return {char(u & 0xff), char((u >> 8) & 0xff), char((u >> 16) & 0xff), char(u >> 24)};
}
std::string be(float f) {
  const std::string s = le(f);
  return {s[3], s[2], s[1], s[0]};
}

TEST(Pfm, WriterStoresRowsBottomUpLittleEndian) {
  TempDir dir;
  const float inf = std::numeric_limits<float>::infinity();
  const std::vector<float> pixels = {1.5f, -2.0f, inf,  // top row
                                     0.25f, 7.0f, 1e-30f};
  write_pfm(dir.file("d.pfm"), 3, 2, pixels);
  const std::string expected = "Pf\n3 2\n-1.0\n" + le(0.25f) + le(7.0f) + le(1e-30f) + le(1.5f) +
                               le(-2.0f) + le(inf);
  EXPECT_EQ(read_file(dir.file("d.pfm")), expected);
  const ImageFloat back = read_pfm(dir.file("d.pfm"));
  EXPECT_EQ(back.width, 3);
  EXPECT_EQ(back.height, 2);
  EXPECT_EQ(back.pixels, pixels);
}

TEST(Pfm, ReadsBigEndianAndOtherWhitespace) {
  TempDir dir;
  // Positive scale: big-endian; tokens separated by spaces and a tab.
  write_file(dir.file("b.pfm"), "Pf 2\t1 1.0\n" + be(3.0f) + be(-0.5f));
  const ImageFloat image = read_pfm(dir.file("b.pfm"));
  ASSERT_EQ(image.pixels.size(), 2u);
  EXPECT_EQ(image.pixels[0], 3.0f);
  EXPECT_EQ(image.pixels[1], -0.5f);
}

TEST(Pfm, RefusesWhatIsNotAGrayscalePfmNamingTheFile) {
  TempDir dir;
  const auto refused = [&](const std::string& bytes, const std::string& says) {
    write_file(dir.file("x.pfm"), bytes);
    try {
      read_pfm(dir.file("x.pfm"));
      ADD_FAILURE() << "accepted: " << says;
    } catch (const FormatError& e) {
      EXPECT_NE(std::string(e.what()).find("x.pfm"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
    }
  };
  refused("PF\n1 1\n-1\n" + le(1) + le(2) + le(3), "colour PFM");
  refused("P6\n1 1\n255\nabc", "not a PFM");
  refused("Pf\n0 1\n-1\n", "width");
  refused("Pf\n70000 1\n-1\n", "width");
  refused("Pf\n2 x\n-1\n", "height");
  refused("Pf\n1 1\n0\n" + le(1), "scale");
  refused("Pf\n2 2\n-1\n" + le(1) + le(2) + le(3), "needs 16 bytes");  // truncated
  refused("Pf\n1 1\n-1\n" + le(1) + "extra", "needs 4 bytes");
  refused("", "not a PFM");
  EXPECT_THROW(read_pfm(dir.file("missing.pfm")), IoError);
}

}  // namespace
}  // namespace pointillist

namespace pointillist {
namespace {

TEST(Pfm, ExpectedSizeIsCheckedBeforeTheBodyAndPipesAreRefused) {
  TempDir dir;
  write_pfm(dir.file("d.pfm"), 3, 2, std::vector<float>(6, 1.0f));
  EXPECT_EQ(read_pfm(dir.file("d.pfm"), 3, 2).pixels.size(), 6u);
  try {
    read_pfm(dir.file("d.pfm"), 4, 2);
    ADD_FAILURE() << "accepted a 3x2 image as 4x2";
  } catch (const FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("is 3x2 but 4x2 was expected"), std::string::npos)
        << e.what();
  }
  // A header announcing the largest size with a body to match is refused by the expected size
  // alone (the file is sparse: nothing is read or allocated).
  {
    std::ofstream out(dir.file("big.pfm"), std::ios::binary);
    out << "Pf\n65536 65536\n-1\n";
  }
  std::filesystem::resize_file(dir.file("big.pfm"), 18 + 4ull * 65536 * 65536);
  EXPECT_THROW(read_pfm(dir.file("big.pfm"), 64, 64), FormatError);
  EXPECT_THROW(read_pfm(dir.file(""), 1, 1), IoError);  // a folder
}

}  // namespace
}  // namespace pointillist
