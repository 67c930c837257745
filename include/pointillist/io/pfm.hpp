// Single-channel float images as PFM files (the Portable Float Map of Netpbm and HDR tools:
// "Pf", width and height, a scale whose sign gives the byte order, then 32-bit floats in rows
// from the bottom up). Used for metric depth images (`render --depth D.pfm`,
// `generate --reference-depth`), which the label metrics' see-through count compares.
#pragma once

#include <span>
#include <string>
#include <vector>

namespace pointillist {

struct ImageFloat {
  int width = 0, height = 0;
  std::vector<float> pixels;  // rows top to bottom
};

// Writes `pixels` (rows top to bottom) as a little-endian grayscale PFM, atomically (temporary
// file + rename). Infinities (background depth) are stored as they are. Throws IoError (Error for
// a size of zero); asserts pixels.size() == width * height.
void write_pfm(const std::string& path, int width, int height, std::span<const float> pixels);

// Reads a grayscale PFM ("Pf") in either byte order. With expect_width / expect_height > 0 the
// header's size must be that (checked before anything is allocated by it). Throws FormatError
// naming the file for a colour PFM ("PF"), a header that is not a PFM's, sizes above 65536 a
// side or other than expected, or a body whose length is not width × height floats; IoError
// when the file cannot be read or is not a regular file.
ImageFloat read_pfm(const std::string& path, int expect_width = 0, int expect_height = 0);

}  // namespace pointillist
