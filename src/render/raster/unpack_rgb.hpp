// Packed 0x00BBGGRR pixels (the fast rasterizer's colour buffer) from and to 3-byte RGB pixels.
#pragma once

#include <bit>
#include <cstdint>
#include <cstring>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "pointillist/core/math.hpp"

namespace pointillist::render_detail {

// 0x00BBGGRR: below 2^24, so signed and unsigned order agree (the fast rasterizer's tie rule
// compares packed colours).
inline std::uint32_t pack_rgb(Rgb8 c) {
  return static_cast<std::uint32_t>(c.r) | static_cast<std::uint32_t>(c.g) << 8 |
         static_cast<std::uint32_t>(c.b) << 16;
}

// n pixels from `in` to `dst`, four at a time (three little-endian words), with streaming
// stores where SSE2 has them: the output is written once per frame and not read back here.
inline void unpack_rgb(const std::uint32_t* in, std::size_t n, Rgb8* dst) {
  static_assert(sizeof(Rgb8) == 3);
  auto* bytes = reinterpret_cast<unsigned char*>(dst);
  std::size_t p = 0;
  if constexpr (std::endian::native == std::endian::little) {
#if defined(__SSE2__)
    // Streaming stores: the output is written once per frame and not read back here, so
    // bypassing the cache saves reading each line before overwriting it. Words must be 4-byte
    // aligned: go pixel by pixel until the output is.
    for (; p < n && (reinterpret_cast<std::uintptr_t>(bytes + 3 * p) & 3) != 0; ++p) {
      const std::uint32_t c = in[p];
      dst[p] = Rgb8{static_cast<std::uint8_t>(c), static_cast<std::uint8_t>(c >> 8),
                    static_cast<std::uint8_t>(c >> 16)};
    }
    for (; p + 4 <= n; p += 4) {
      const std::uint32_t a = in[p], b = in[p + 1], c = in[p + 2], d = in[p + 3];
      int* words = reinterpret_cast<int*>(bytes + 3 * p);
      _mm_stream_si32(words, static_cast<int>(a | b << 24));
      _mm_stream_si32(words + 1, static_cast<int>(b >> 8 | c << 16));
      _mm_stream_si32(words + 2, static_cast<int>(c >> 16 | d << 8));
    }
    _mm_sfence();
#else
    for (; p + 4 <= n; p += 4) {
      const std::uint32_t a = in[p], b = in[p + 1], c = in[p + 2], d = in[p + 3];
      const std::uint32_t words[3] = {a | b << 24, b >> 8 | c << 16, c >> 16 | d << 8};
      std::memcpy(bytes + 3 * p, words, sizeof words);
    }
#endif
  }
  for (; p < n; ++p) {
    const std::uint32_t c = in[p];
    dst[p] = Rgb8{static_cast<std::uint8_t>(c), static_cast<std::uint8_t>(c >> 8),
                  static_cast<std::uint8_t>(c >> 16)};
  }
}

}  // namespace pointillist::render_detail
