// PFM: a text header of three tokens ("Pf", "W H", scale) each ended by one whitespace
// character, then W × H 32-bit floats, rows from the bottom up, little-endian when scale < 0.
#include "pointillist/io/pfm.hpp"

#include <algorithm>
#include <bit>
#include <cassert>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "pointillist/core/atomic_file.hpp"
#include "pointillist/core/error.hpp"

namespace pointillist {
namespace {

constexpr int kMaxSide = 65536;
constexpr std::size_t kMaxHeader = 256;

// The next whitespace-separated token of the header from `pos`, then past the one whitespace
// character that ends it; empty when the header ends early.
std::string token(const std::string& data, std::size_t& pos) {
  while (pos < data.size() && pos < kMaxHeader && std::isspace(static_cast<unsigned char>(data[pos]))) ++pos;
  const std::size_t start = pos;
  while (pos < data.size() && pos < kMaxHeader && !std::isspace(static_cast<unsigned char>(data[pos]))) ++pos;
  std::string out = data.substr(start, pos - start);
  if (pos < data.size()) ++pos;  // the single whitespace character after the token
  return out;
}

int side(const std::string& text, const std::string& path, const char* what) {
  std::size_t used = 0;
  long value = 0;
  try {
    value = std::stol(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || text.empty() || value < 1 || value > kMaxSide) {
    throw FormatError(path + ": the PFM header's " + what + " is '" + text +
                      "'; it must be a whole number from 1 to " + std::to_string(kMaxSide));
  }
  return static_cast<int>(value);
}

}  // namespace

void write_pfm(const std::string& path, int width, int height, std::span<const float> pixels) {
  if (width <= 0 || height <= 0) throw Error("cannot write " + path + ": the image is empty");
  assert(pixels.size() == static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
  AtomicFile file(path);
  file.write("Pf\n" + std::to_string(width) + " " + std::to_string(height) + "\n-1.0\n");
  std::vector<std::uint32_t> row(static_cast<std::size_t>(width));
  for (int y = height - 1; y >= 0; --y) {
    const float* src = pixels.data() + static_cast<std::size_t>(y) * width;
    for (int x = 0; x < width; ++x) {
      std::uint32_t bits = std::bit_cast<std::uint32_t>(src[x]);
      if constexpr (std::endian::native == std::endian::big) bits = __builtin_bswap32(bits);
      row[static_cast<std::size_t>(x)] = bits;
    }
    file.write(row.data(), row.size() * sizeof(std::uint32_t));
  }
  file.commit();
}

ImageFloat read_pfm(const std::string& path, int expect_width, int expect_height) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec) throw IoError("cannot read " + path + ": " + ec.message());
  if (!std::filesystem::is_regular_file(status)) {
    throw IoError("cannot read " + path + ": not a regular file; give a .pfm file (written by "
                  "render --depth D.pfm or generate --reference-depth), not a pipe or a device");
  }
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec) throw IoError("cannot read " + path + ": " + ec.message());
  // The largest body a valid header can announce, so that nothing larger is read.
  const std::uintmax_t limit = kMaxHeader + 4ull * kMaxSide * kMaxSide;
  if (size > limit) {
    throw FormatError(path + ": " + std::to_string(size) +
                      " bytes is more than any PFM of at most 65536 pixels a side holds");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError("cannot open " + path + ": " + std::strerror(errno));
  const auto read_exactly = [&](char* to, std::size_t bytes) {
    in.read(to, static_cast<std::streamsize>(bytes));
    if (static_cast<std::size_t>(in.gcount()) != bytes) {
      throw IoError("cannot read " + path + ": it ended after " +
                    std::to_string(in.gcount()) + " of " + std::to_string(bytes) +
                    " bytes (did it change while being read?)");
    }
  };
  std::string head(static_cast<std::size_t>(std::min<std::uintmax_t>(size, kMaxHeader)), '\0');
  read_exactly(head.data(), head.size());
  std::size_t pos = 0;
  const std::string magic = token(head, pos);
  if (magic == "PF") {
    throw FormatError(path + " is a colour PFM (PF); a depth image has one channel (Pf)");
  }
  if (magic != "Pf") {
    throw FormatError(path + " is not a PFM image (it should begin with 'Pf'); write depth "
                      "images with render --depth FILE.pfm");
  }
  ImageFloat image;
  image.width = side(token(head, pos), path, "width");
  image.height = side(token(head, pos), path, "height");
  const std::string scale_text = token(head, pos);
  char* end = nullptr;
  const double scale = std::strtod(scale_text.c_str(), &end);
  if (scale_text.empty() || end != scale_text.c_str() + scale_text.size() ||
      !std::isfinite(scale) || scale == 0) {
    throw FormatError(path + ": the PFM header's scale is '" + scale_text +
                      "'; it must be a nonzero number (negative: little-endian)");
  }
  if ((expect_width > 0 && image.width != expect_width) ||
      (expect_height > 0 && image.height != expect_height)) {
    throw FormatError(path + " is " + std::to_string(image.width) + "x" +
                      std::to_string(image.height) + " but " + std::to_string(expect_width) +
                      "x" + std::to_string(expect_height) +
                      " was expected; give the depth image written with the colour image");
  }
  const std::uint64_t count = static_cast<std::uint64_t>(image.width) * image.height;
  if (size - pos != 4 * count) {
    throw FormatError(path + ": a " + std::to_string(image.width) + "x" +
                      std::to_string(image.height) + " PFM needs " + std::to_string(4 * count) +
                      " bytes after its header, the file has " + std::to_string(size - pos) +
                      " (truncated or not a PFM)");
  }
  // Read into the image, then put the rows top to bottom and the bytes in the host's order.
  image.pixels.resize(count);
  in.seekg(static_cast<std::streamoff>(pos));
  read_exactly(reinterpret_cast<char*>(image.pixels.data()), 4 * count);
  const std::size_t w = static_cast<std::size_t>(image.width);
  for (int y = 0; y < image.height / 2; ++y) {
    std::swap_ranges(image.pixels.begin() + static_cast<std::ptrdiff_t>(y * w),
                     image.pixels.begin() + static_cast<std::ptrdiff_t>((y + 1) * w),
                     image.pixels.begin() + static_cast<std::ptrdiff_t>((image.height - 1 - y) * w));
  }
  const bool little = scale < 0;
  if (little != (std::endian::native == std::endian::little)) {
    for (float& v : image.pixels) {
      v = std::bit_cast<float>(__builtin_bswap32(std::bit_cast<std::uint32_t>(v)));
    }
  }
  return image;
}

}  // namespace pointillist
