// PNG images (through libspng).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "pointillist/core/math.hpp"

namespace pointillist {

// Writes an 8-bit RGB PNG (rows top to bottom), atomically (temporary file + rename).
// Throws IoError (Error for a size of zero); asserts pixels.size() == width * height.
void write_png_rgb8(const std::string& path, int width, int height, std::span<const Rgb8> pixels);

// Writes a 16-bit grayscale PNG (rows top to bottom), atomically. Throws IoError (Error for a
// size of zero); asserts pixels.size() == width * height.
void write_png_gray16(const std::string& path, int width, int height,
                      std::span<const std::uint16_t> pixels);

struct ImageRgb8 {
  int width = 0, height = 0;
  std::vector<Rgb8> pixels;
};

// Reads a PNG of any color type and bit depth, converted to 8-bit RGB (alpha dropped, 16-bit
// samples scaled to 8 bits). Throws FormatError naming the file for data that is not a PNG,
// is corrupt (CRC errors included) or exceeds 65536 pixels a side; IoError when the file cannot
// be read.
ImageRgb8 read_png_rgb8(const std::string& path);

}  // namespace pointillist
