// PNG writer and reader. The oracle is a small PNG codec written here from the specification
// (chunks, CRC, zlib, the five row filters), independent of libspng.
#include "pointillist/io/png.hpp"

#include <gtest/gtest.h>
#include <zlib.h>

#include <filesystem>
#include <random>

#include "io_test_support.hpp"
#include "pointillist/core/error.hpp"
#include "testing/testing.hpp"

namespace pointillist {
namespace {

using testing::read_file;
using testing::TempDir;
using testing::write_file;

std::uint32_t be32(const std::string& s, std::size_t at) {
  std::uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v = (v << 8) | static_cast<unsigned char>(s[at + i]);
  return v;
}

struct DecodedPng {
  std::uint32_t width = 0, height = 0;
  int bit_depth = 0, color_type = 0;
  std::vector<std::uint8_t> rows;  // unfiltered samples, row after row
  std::vector<std::string> chunk_types;
};

int paeth(int a, int b, int c) {
  const int p = a + b - c, pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
  return (pa <= pb && pa <= pc) ? a : (pb <= pc ? b : c);
}

// Non-interlaced PNGs with 1 (gray) or 3 (RGB) channels only: what our writer produces.
DecodedPng decode_png(const std::string& png) {
  DecodedPng d;
  EXPECT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  std::string idat;
  for (std::size_t at = 8; at + 12 <= png.size();) {
    const std::uint32_t length = be32(png, at);
    const std::string type = png.substr(at + 4, 4);
    const std::string data = png.substr(at + 8, length);
    const auto crc = crc32(crc32(0, nullptr, 0),
                           reinterpret_cast<const Bytef*>(png.data() + at + 4), length + 4);
    EXPECT_EQ(crc, be32(png, at + 8 + length)) << type;
    d.chunk_types.push_back(type);
    if (type == "IHDR") {
      d.width = be32(data, 0);
      d.height = be32(data, 4);
      d.bit_depth = static_cast<unsigned char>(data[8]);
      d.color_type = static_cast<unsigned char>(data[9]);
      EXPECT_EQ(data[12], 0) << "interlaced";
    } else if (type == "IDAT") {
      idat += data;
    }
    at += 12 + length;
  }
  const int channels = d.color_type == 2 ? 3 : 1;
  const std::size_t bpp = static_cast<std::size_t>(channels * d.bit_depth / 8);
  const std::size_t stride = d.width * bpp;
  std::vector<std::uint8_t> raw((stride + 1) * d.height);
  uLongf raw_size = raw.size();
  EXPECT_EQ(
      uncompress(raw.data(), &raw_size, reinterpret_cast<const Bytef*>(idat.data()), idat.size()),
      Z_OK);
  EXPECT_EQ(raw_size, raw.size());
  d.rows.assign(stride * d.height, 0);
  for (std::size_t y = 0; y < d.height; ++y) {
    const int filter = raw[y * (stride + 1)];
    const std::uint8_t* in = &raw[y * (stride + 1) + 1];
    std::uint8_t* out = &d.rows[y * stride];
    const std::uint8_t* up = y > 0 ? &d.rows[(y - 1) * stride] : nullptr;
    for (std::size_t x = 0; x < stride; ++x) {
      const int a = x >= bpp ? out[x - bpp] : 0, b = up ? up[x] : 0,
                c = (up && x >= bpp) ? up[x - bpp] : 0;
      const int predictor = filter == 0   ? 0
                            : filter == 1 ? a
                            : filter == 2 ? b
                            : filter == 3 ? (a + b) / 2
                                          : paeth(a, b, c);
      out[x] = static_cast<std::uint8_t>(in[x] + predictor);
    }
  }
  return d;
}

void put_chunk(std::string& png, const std::string& type, const std::string& data) {
  testing::put(png, static_cast<std::uint32_t>(data.size()), true);
  const std::string body = type + data;
  png += body;
  testing::put(png,
               static_cast<std::uint32_t>(crc32(
                   crc32(0, nullptr, 0), reinterpret_cast<const Bytef*>(body.data()), body.size())),
               true);
}

// A PNG built by hand: filter 0 on every row.
std::string make_png(std::uint32_t width, std::uint32_t height, int bit_depth, int color_type,
                     const std::string& samples, std::size_t stride, const std::string& plte = "") {
  std::string png("\x89PNG\r\n\x1a\n", 8);
  std::string ihdr;
  testing::put(ihdr, width, true);
  testing::put(ihdr, height, true);
  ihdr += static_cast<char>(bit_depth);
  ihdr += static_cast<char>(color_type);
  ihdr += std::string(3, '\0');
  put_chunk(png, "IHDR", ihdr);
  if (!plte.empty()) put_chunk(png, "PLTE", plte);
  std::string raw;
  for (std::uint32_t y = 0; y < height; ++y) raw += '\0' + samples.substr(y * stride, stride);
  std::string z(compressBound(raw.size()), '\0');
  uLongf z_size = z.size();
  compress(reinterpret_cast<Bytef*>(z.data()), &z_size, reinterpret_cast<const Bytef*>(raw.data()),
           raw.size());
  z.resize(z_size);
  put_chunk(png, "IDAT", z);
  put_chunk(png, "IEND", "");
  return png;
}

std::vector<Rgb8> gradient(int w, int h) {
  std::vector<Rgb8> pixels;
  std::mt19937 rng(7);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      pixels.push_back({std::uint8_t(x * 40), std::uint8_t(y * 50), std::uint8_t(rng())});
  return pixels;
}

TEST(Png, WritesRgb8) {
  TempDir dir;
  const std::string path = dir.file("image.png");
  const std::vector<Rgb8> pixels = gradient(5, 3);
  write_png_rgb8(path, 5, 3, pixels);
  const DecodedPng d = decode_png(read_file(path));
  EXPECT_EQ(d.width, 5u);
  EXPECT_EQ(d.height, 3u);
  EXPECT_EQ(d.bit_depth, 8);
  EXPECT_EQ(d.color_type, 2);
  EXPECT_EQ(d.chunk_types.front(), "IHDR");
  EXPECT_EQ(d.chunk_types.back(), "IEND");
  ASSERT_EQ(d.rows.size(), pixels.size() * 3);
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    EXPECT_EQ(d.rows[3 * i], pixels[i].r);
    EXPECT_EQ(d.rows[3 * i + 1], pixels[i].g);
    EXPECT_EQ(d.rows[3 * i + 2], pixels[i].b);
  }
}

TEST(Png, WritesGray16BigEndian) {
  TempDir dir;
  const std::string path = dir.file("depth.png");
  const std::vector<std::uint16_t> pixels = {0, 1, 0x1234, 0xffff, 0x8000, 42};
  write_png_gray16(path, 3, 2, pixels);
  const DecodedPng d = decode_png(read_file(path));
  EXPECT_EQ(d.width, 3u);
  EXPECT_EQ(d.height, 2u);
  EXPECT_EQ(d.bit_depth, 16);
  EXPECT_EQ(d.color_type, 0);
  ASSERT_EQ(d.rows.size(), 12u);
  for (std::size_t i = 0; i < pixels.size(); ++i)
    EXPECT_EQ((d.rows[2 * i] << 8) | d.rows[2 * i + 1], pixels[i]) << i;
}

TEST(Png, ReadsRgb8) {
  TempDir dir;
  const std::string samples("\x01\x02\x03\xff\x00\x80\x10\x20\x30\x40\x50\x60", 12);
  write_file(dir.file("a.png"), make_png(2, 2, 8, 2, samples, 6));
  const ImageRgb8 image = read_png_rgb8(dir.file("a.png"));
  EXPECT_EQ(image.width, 2);
  EXPECT_EQ(image.height, 2);
  const std::vector<Rgb8> expected = {{1, 2, 3}, {255, 0, 128}, {16, 32, 48}, {64, 80, 96}};
  EXPECT_EQ(image.pixels, expected);
}

TEST(Png, ReadsOtherColorTypesAsRgb8) {
  TempDir dir;
  // Gray 8: each value in all three channels.
  write_file(dir.file("g.png"), make_png(3, 1, 8, 0, std::string("\x00\x7f\xff", 3), 3));
  EXPECT_EQ(read_png_rgb8(dir.file("g.png")).pixels,
            (std::vector<Rgb8>{{0, 0, 0}, {127, 127, 127}, {255, 255, 255}}));
  // RGBA 8: alpha dropped.
  write_file(dir.file("rgba.png"),
             make_png(2, 1, 8, 6, std::string("\x0a\x0b\x0c\x00\x0d\x0e\x0f\xff", 8), 8));
  EXPECT_EQ(read_png_rgb8(dir.file("rgba.png")).pixels,
            (std::vector<Rgb8>{{10, 11, 12}, {13, 14, 15}}));
  // RGB 16: 0xABAB -> 0xAB (values where every 16-to-8 rule agrees).
  write_file(dir.file("rgb16.png"),
             make_png(1, 1, 16, 2, std::string("\xab\xab\x00\x00\xff\xff", 6), 6));
  EXPECT_EQ(read_png_rgb8(dir.file("rgb16.png")).pixels, (std::vector<Rgb8>{{0xab, 0, 0xff}}));
  // Palette.
  write_file(dir.file("p.png"), make_png(3, 1, 8, 3, std::string("\x01\x00\x01", 3), 3,
                                         std::string("\x05\x06\x07\xc8\xc9\xca", 6)));
  EXPECT_EQ(read_png_rgb8(dir.file("p.png")).pixels,
            (std::vector<Rgb8>{{200, 201, 202}, {5, 6, 7}, {200, 201, 202}}));
}

TEST(Png, RoundTripsThroughWriterAndReader) {
  TempDir dir;
  const std::vector<Rgb8> pixels = gradient(17, 9);
  write_png_rgb8(dir.file("r.png"), 17, 9, pixels);
  const ImageRgb8 image = read_png_rgb8(dir.file("r.png"));
  EXPECT_EQ(image.width, 17);
  EXPECT_EQ(image.height, 9);
  EXPECT_EQ(image.pixels, pixels);
}

TEST(Png, RejectsGarbageAndCorruptFilesNamingThePath) {
  TempDir dir;
  const std::string path = dir.file("bad.png");
  write_file(path, "this is not a png at all");
  try {
    read_png_rgb8(path);
    ADD_FAILURE() << "no exception";
  } catch (const FormatError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(path + ": ", 0), 0u) << e.what();
  }
  std::string png = make_png(2, 2, 8, 2, std::string(12, '\x11'), 6);
  png[png.size() - 20] ^= 0x40;  // inside IDAT: CRC mismatch
  write_file(path, png);
  EXPECT_THROW(read_png_rgb8(path), FormatError);
  try {
    read_png_rgb8(dir.file("missing.png"));
    ADD_FAILURE() << "no exception";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find(dir.file("missing.png")), std::string::npos) << e.what();
  }
}

TEST(Png, WritesAtomically) {
  TempDir dir;
  const std::string path = dir.file("out.png");
  write_file(path, "old");
  write_png_rgb8(path, 1, 1, std::vector<Rgb8>{{1, 2, 3}});
  EXPECT_EQ(read_png_rgb8(path).pixels, (std::vector<Rgb8>{{1, 2, 3}}));
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(dir.path()))
    names.push_back(entry.path().filename());
  EXPECT_EQ(names, std::vector<std::string>{"out.png"});
  EXPECT_THROW(write_png_rgb8(dir.file("missing/out.png"), 1, 1, std::vector<Rgb8>{{1, 2, 3}}),
               IoError);
}

}  // namespace
}  // namespace pointillist
