// LAS files assembled byte by byte from the ASPRS LAS 1.4 (R15) layout, for tests that need
// LAS input made independently of the reader (the reader's tests, the CLI's merge tests).
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "io/io_test_support.hpp"

namespace pointillist::testing {

struct LasPoint {
  std::int32_t x = 0, y = 0, z = 0;
  std::uint16_t r = 0, g = 0, b = 0;
};

struct LasSpec {
  int minor = 2;
  int format = 0;
  int extra_bytes = 0;   // appended to every record
  int vlr_padding = 0;   // bytes between the header and the first record
  double scale[3] = {0.01, 0.001, 0.25};
  double offset[3] = {100.0, -50.0, 2.5};
  bool legacy_count = true;  // 1.4: also fill the legacy 32-bit count
  std::optional<std::uint8_t> format_byte = {};
  std::optional<std::uint16_t> record_length = {};
  std::optional<std::uint16_t> header_size = {};
  std::optional<std::uint32_t> point_offset = {};
  std::optional<std::uint64_t> count = {};
  std::string signature = "LASF";
  int major = 1;
};

// Record sizes of formats 0..10 as the specification lists them.
constexpr int kSpecRecordSize[11] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};

inline int header_size_for(int minor) { return minor >= 4 ? 375 : minor == 3 ? 235 : 227; }

inline void put_text(std::string& out, const std::string& text, std::size_t size) {
  std::string field = text.substr(0, size);
  field.resize(size, '\0');
  out += field;
}

inline std::string record(const LasSpec& spec, const LasPoint& p) {
  const int f = spec.format;
  std::string r;
  put(r, p.x);
  put(r, p.y);
  put(r, p.z);
  put(r, std::uint16_t{0x1111});  // intensity
  if (f <= 5) {
    put(r, std::uint8_t{0x22});    // return number, returns, flags
    put(r, std::uint8_t{0x33});    // classification
    put(r, std::int8_t{-44});      // scan angle rank
    put(r, std::uint8_t{0x55});    // user data
    put(r, std::uint16_t{0x6666});  // point source ID
    if (f == 1 || f == 3 || f == 4 || f == 5) put(r, 1234.5);  // GPS time
    if (f == 2 || f == 3 || f == 5) {
      put(r, p.r);
      put(r, p.g);
      put(r, p.b);
    }
    if (f == 4 || f == 5) r.append(29, '\x77');  // wave packet
  } else {
    put(r, std::uint8_t{0x22});    // return number, returns
    put(r, std::uint8_t{0x0f});    // classification flags, channel, direction, edge
    put(r, std::uint8_t{0x33});    // classification
    put(r, std::uint8_t{0x55});    // user data
    put(r, std::int16_t{-1234});   // scan angle
    put(r, std::uint16_t{0x6666});  // point source ID
    put(r, 98765.25);              // GPS time
    if (f == 7 || f == 8 || f == 10) {
      put(r, p.r);
      put(r, p.g);
      put(r, p.b);
    }
    if (f == 8 || f == 10) put(r, std::uint16_t{0x9999});  // NIR
    if (f == 9 || f == 10) r.append(29, '\x77');
  }
  EXPECT_EQ(r.size(), static_cast<std::size_t>(kSpecRecordSize[f])) << "format " << f;
  r.append(static_cast<std::size_t>(spec.extra_bytes), '\xee');
  return r;
}

inline std::string build_las(const LasSpec& spec, const std::vector<LasPoint>& points) {
  const int header_size = spec.header_size.value_or(header_size_for(spec.minor));
  const std::uint64_t count = spec.count.value_or(points.size());
  std::string h;
  h += spec.signature;
  put(h, std::uint16_t{7});  // file source ID
  put(h, std::uint16_t{0});  // global encoding
  h.append(16, '\0');        // project GUID
  put(h, static_cast<std::uint8_t>(spec.major));
  put(h, static_cast<std::uint8_t>(spec.minor));
  put_text(h, "TEST SYSTEM", 32);
  put_text(h, "hand-built test", 32);
  put(h, std::uint16_t{100});   // creation day
  put(h, std::uint16_t{2024});  // year
  EXPECT_EQ(h.size(), 94u);
  put(h, static_cast<std::uint16_t>(header_size));
  put(h, spec.point_offset.value_or(static_cast<std::uint32_t>(header_size + spec.vlr_padding)));
  put(h, std::uint32_t{0});  // VLR count
  put(h, spec.format_byte.value_or(static_cast<std::uint8_t>(spec.format)));
  put(h, spec.record_length.value_or(
             static_cast<std::uint16_t>(kSpecRecordSize[spec.format] + spec.extra_bytes)));
  const bool legacy = spec.minor < 4 || spec.legacy_count;
  put(h, legacy ? static_cast<std::uint32_t>(count) : std::uint32_t{0});
  for (int i = 0; i < 5; ++i) put(h, std::uint32_t{0});  // points by return
  EXPECT_EQ(h.size(), 131u);
  for (double s : spec.scale) put(h, s);
  for (double o : spec.offset) put(h, o);
  for (int i = 0; i < 6; ++i) put(h, 0.0);  // bounds: left zero, as some writers do
  EXPECT_EQ(h.size(), 227u);
  if (spec.minor >= 3) put(h, std::uint64_t{0});  // waveform data start
  if (spec.minor >= 4) {
    put(h, std::uint64_t{0});  // first EVLR
    put(h, std::uint32_t{0});  // EVLR count
    put(h, count);             // 64-bit point count
    for (int i = 0; i < 15; ++i) put(h, std::uint64_t{0});
    EXPECT_EQ(h.size(), 375u);
  }
  if (static_cast<int>(h.size()) < header_size) h.resize(static_cast<std::size_t>(header_size), '\0');
  h.append(static_cast<std::size_t>(spec.vlr_padding), '\xcc');
  for (const LasPoint& p : points) h += record(spec, p);
  return h;
}

}  // namespace pointillist::testing
