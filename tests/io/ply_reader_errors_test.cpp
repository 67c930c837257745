// PLY reader on malformed input: every case throws, and the message names the file and the place
// (line for headers and ascii bodies, byte offset for binary bodies), computed here by hand.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <random>

#include "io_test_support.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/io/ply.hpp"
#include "testing/testing.hpp"

namespace pointillist {
namespace {

using testing::put;
using testing::TempDir;
using testing::write_file;

#define EXPECT_CONTAINS(text, part)                          \
  EXPECT_NE(std::string(text).find(part), std::string::npos) \
      << "message: " << (text) << "\nexpected it to contain: " << (part)

// The FormatError message for reading `bytes` from a file, or a note that none was thrown.
std::string error_for(const TempDir& dir, const std::string& bytes,
                      std::string* path_out = nullptr) {
  const std::string path = dir.file("bad.ply");
  write_file(path, bytes);
  if (path_out) *path_out = path;
  try {
    read_ply(path);
  } catch (const FormatError& e) {
    return e.what();
  } catch (const std::exception& e) {
    return std::string("wrong exception type: ") + e.what();
  }
  return "no exception";
}

const std::string kXyz = "property float x\nproperty float y\nproperty float z\n";
// 7 lines: a body's first line is line 8.
const std::string kAsciiHeader2 =
    "ply\nformat ascii 1.0\nelement vertex 2\n" + kXyz + "end_header\n";

void expect_error(const std::string& bytes, const std::string& place, const std::string& what) {
  TempDir dir;
  std::string path;
  const std::string message = error_for(dir, bytes, &path);
  EXPECT_CONTAINS(message, path + ": " + place + ": ");
  EXPECT_CONTAINS(message, what);
}

// Header ------------------------------------------------------------------------------------

TEST(PlyReader, RejectsEmptyFile) { expect_error("", "line 1", "file is empty"); }

TEST(PlyReader, RejectsMissingMagic) {
  expect_error("plx\nformat ascii 1.0\n", "line 1",
               "not a PLY file: expected 'ply' on the first line, found 'plx?format ascii'");
}

TEST(PlyReader, RejectsMissingFormat) {
  expect_error("ply\nelement vertex 1\n" + kXyz + "end_header\n0 0 0\n", "line 2",
               "element before the format line");
  expect_error("ply\ncomment nothing\nend_header\n", "line 3", "header has no format line");
}

TEST(PlyReader, RejectsUnknownFormat) {
  expect_error("ply\nformat binary_middle_endian 1.0\n", "line 2",
               "unknown format 'binary_middle_endian'");
  expect_error("ply\nformat ascii\n", "line 2", "bad format line");
}

TEST(PlyReader, RejectsUnsupportedVersion) {
  expect_error("ply\nformat ascii 2.0\n", "line 2", "unsupported PLY version '2.0' (expected 1.0)");
}

TEST(PlyReader, RejectsBadElementLine) {
  expect_error("ply\nformat ascii 1.0\nelement vertex many\n", "line 3",
               "element vertex: count 'many' is not a non-negative integer");
  expect_error("ply\nformat ascii 1.0\nelement vertex -4\n", "line 3",
               "count '-4' is not a non-negative integer");
  expect_error("ply\nformat ascii 1.0\nelement vertex\n", "line 3", "bad element line");
}

TEST(PlyReader, RejectsBadPropertyLine) {
  expect_error("ply\nformat ascii 1.0\nelement vertex 1\nproperty flaot x\n", "line 4",
               "element vertex: unknown property type 'flaot'");
  expect_error("ply\nformat ascii 1.0\nelement vertex 1\nproperty float\n", "line 4",
               "bad property line");
  expect_error("ply\nformat ascii 1.0\nelement face 1\nproperty list uchar vertex_indices\n",
               "line 4", "bad list property");
  expect_error("ply\nformat ascii 1.0\nelement face 1\nproperty list float int vertex_indices\n",
               "line 4", "list count type must be an integer type, found 'float'");
  expect_error(
      "ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int32_t vertex_indices\n",
      "line 4", "unknown list item type 'int32_t'");
  expect_error("ply\nformat ascii 1.0\nelement vertex 1\n" + kXyz + "property double y\n", "line 7",
               "property y declared twice");
}

TEST(PlyReader, RejectsHeadersNoRealFileHas) {
  // 4097 properties on one element (4096 is the most allowed): line 3 + 4097 = 4100.
  std::string many = "ply\nformat ascii 1.0\nelement vertex 0\n";
  for (int i = 0; i < 4097; ++i) many += "property float p" + std::to_string(i) + "\n";
  expect_error(many + "end_header\n", "line 4100", "more than 4096 properties");
  // 1025 elements (1024 allowed): the 1025th is on line 2 + 1025.
  std::string elements = "ply\nformat ascii 1.0\n";
  for (int i = 0; i < 1025; ++i) elements += "element e" + std::to_string(i) + " 0\n";
  expect_error(elements + "end_header\n", "line 1027", "more than 1024 elements");
  // A duplicate among many properties is still found, with its line.
  std::string twice = "ply\nformat ascii 1.0\nelement vertex 0\n";
  for (int i = 0; i < 3000; ++i) twice += "property float p" + std::to_string(i) + "\n";
  twice += "property float p17\n";
  expect_error(twice + "end_header\n", "line 3004", "property p17 declared twice");
}

TEST(PlyReader, ReadsAHeaderWithTheMostPropertiesAllowed) {
  // 4096 properties: x, y, z and 4093 others; one vertex.
  std::string header = "ply\nformat ascii 1.0\nelement vertex 1\n" + kXyz;
  std::string body = "1 2 3";
  for (int i = 3; i < 4096; ++i) {
    header += "property uchar extra" + std::to_string(i) + "\n";
    body += " 7";
  }
  TempDir dir;
  const std::string path = dir.file("wide.ply");
  { std::ofstream(path, std::ios::binary) << header << "end_header\n" << body << "\n"; }
  const PointSet p = read_ply(path);
  ASSERT_EQ(p.size(), 1u);
  EXPECT_EQ(p.positions[0], (Vec3f{1, 2, 3}));
}

TEST(PlyReader, RejectsPropertyBeforeElement) {
  expect_error("ply\nformat ascii 1.0\nproperty float x\n", "line 3",
               "property before any element line");
}

TEST(PlyReader, RejectsUnknownHeaderKeyword) {
  expect_error("ply\nformat ascii 1.0\nelemnt vertex 1\n", "line 3",
               "unknown header keyword 'elemnt'");
}

TEST(PlyReader, RejectsHeaderWithoutEndHeader) {
  expect_error("ply\nformat ascii 1.0\nelement vertex 1\n" + kXyz, "line 6",
               "header has no end_header line");
  expect_error("ply\nformat ascii 1.0\nelement vertex 1\n" + kXyz + "end_header", "line 7",
               "no end_header line");
}

TEST(PlyReader, RejectsSecondVertexElement) {
  expect_error("ply\nformat ascii 1.0\nelement vertex 1\n" + kXyz + "element vertex 1\n", "line 7",
               "second 'vertex' element (the first is on line 3)");
}

TEST(PlyReader, RejectsFileWithoutVertices) {
  expect_error("ply\nformat ascii 1.0\nelement vertex 0\n" + kXyz + "end_header\n", "line 3",
               "element vertex has count 0");
  expect_error(
      "ply\nformat ascii 1.0\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n",
      "line 5", "header declares no vertex element");
}

TEST(PlyReader, RejectsMissingCoordinate) {
  expect_error(
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n0 "
      "0\n",
      "line 3", "element vertex has no property z");
}

TEST(PlyReader, RejectsListCoordinateAndScalarFaceIndices) {
  expect_error(
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty list uchar float x\nproperty float y\n"
      "property float z\nend_header\n1 0 0 0\n",
      "line 4", "property x must be a scalar, not a list");
  expect_error("ply\nformat ascii 1.0\nelement vertex 1\n" + kXyz +
                   "element face 1\nproperty int vertex_indices\n"
                   "end_header\n0 0 0\n0\n",
               "line 8", "property vertex_indices must be a list");
  expect_error("ply\nformat ascii 1.0\nelement vertex 1\n" + kXyz +
                   "element face 1\n"
                   "property list uchar float vertex_indices\nend_header\n0 0 0\n0\n",
               "line 8", "list vertex_indices must hold an integer type, found float");
}

// A count that cannot fit in the file is refused before anything is allocated for it.
TEST(PlyReader, RejectsHugeElementCounts) {
  // After a list element the exact place is unknown: the header line is named.
  std::string binary =
      "ply\nformat binary_little_endian 1.0\nelement face 1\nproperty list uchar int "
      "vertex_indices\n"
      "element vertex 1000000000000\n" +
      kXyz + "end_header\n";
  put(binary, std::uint8_t(0));
  for (int i = 0; i < 3; ++i) put(binary, 1.0f);
  expect_error(binary, "line 5",
               "element vertex: count 1000000000000 cannot fit in the file (each needs at least 12 "
               "bytes, 12 bytes remain");
  // With fixed-size elements only, the exact place is known.
  std::string fixed = "ply\nformat binary_little_endian 1.0\nelement vertex 1000000000000\n" +
                      kXyz + "end_header\n";
  const std::size_t body = fixed.size();
  for (int i = 0; i < 3; ++i) put(fixed, 1.0f);
  expect_error(fixed, "byte " + std::to_string(body + 12),
               "vertex 1 of 1000000000000: file ends early (property x needs 4 bytes, 0 remain)");
  expect_error("ply\nformat ascii 1.0\nelement vertex 1\n" + kXyz +
                   "element face 18446744073709551615\nproperty list uchar int "
                   "vertex_indices\nend_header\n0 0 0\n3 0 0 0\n",
               "line 7", "element face: count 18446744073709551615 cannot fit in the file");
  expect_error("ply\nformat ascii 1.0\nelement vertex 99999999999999999999\n", "line 3",
               "count '99999999999999999999' is not a non-negative integer");
}

// Binary bodies ---------------------------------------------------------------------------

std::string binary_header(const std::string& elements) {
  return "ply\nformat binary_little_endian 1.0\n" + elements + "end_header\n";
}

TEST(PlyReader, RejectsTruncatedBinaryVertices) {
  std::string file = binary_header("element vertex 3\n" + kXyz);
  const std::size_t body = file.size();
  for (int i = 0; i < 7; ++i) put(file, float(i));
  file += "ab";  // half of vertex 2's y
  expect_error(file, "byte " + std::to_string(body + 28),
               "vertex 2 of 3: file ends early (property y needs 4 bytes, 2 remain)");
}

TEST(PlyReader, RejectsTruncatedBinaryFaces) {
  std::string file = binary_header("element vertex 3\n" + kXyz +
                                   "element face 2\nproperty list uchar int vertex_indices\n");
  for (int i = 0; i < 9; ++i) put(file, float(i));
  put(file, std::uint8_t(3));
  for (int i : {0, 1, 2}) put(file, std::int32_t(i));
  const std::size_t second = file.size();
  put(file, std::uint8_t(3));
  for (int i : {2, 1}) put(file, std::int32_t(i));
  expect_error(
      file, "byte " + std::to_string(second + 1),
      "face 1 of 2: file ends early (list property vertex_indices needs 12 bytes, 8 remain)");
  // A face with another property goes through the generic walker.
  std::string generic = binary_header(
      "element vertex 3\n" + kXyz +
      "element face 1\nproperty list uchar int vertex_indices\nproperty float quality\n");
  for (int i = 0; i < 9; ++i) put(generic, float(i));
  put(generic, std::uint8_t(3));
  for (int i : {0, 1, 2}) put(generic, std::int32_t(i));
  const std::size_t quality = generic.size();
  generic += "q";
  expect_error(generic, "byte " + std::to_string(quality),
               "face 0 of 1: file ends early (property quality needs 4 bytes, 1 remain)");
}

TEST(PlyReader, RejectsTruncatedUnknownElement) {
  std::string file =
      binary_header("element vertex 1\n" + kXyz + "element extra 2\nproperty double value\n");
  for (int i = 0; i < 3; ++i) put(file, float(i));
  const std::size_t extra = file.size();
  put(file, 1.0);
  put(file, std::int32_t(0));
  expect_error(file, "byte " + std::to_string(extra + 8),
               "extra 1 of 2: file ends early (property value needs 8 bytes, 4 remain)");
}

TEST(PlyReader, RejectsBinaryFaceIndexOutOfRange) {
  for (std::int32_t bad : {3, -1}) {
    std::string file = binary_header("element vertex 3\n" + kXyz +
                                     "element face 1\nproperty list uchar int vertex_indices\n");
    for (int i = 0; i < 9; ++i) put(file, float(i));
    put(file, std::uint8_t(3));
    put(file, std::int32_t(0));
    const std::size_t offset = file.size();
    put(file, bad);
    put(file, std::int32_t(1));
    expect_error(file, "byte " + std::to_string(offset),
                 "face 0 of 1: list property vertex_indices: vertex index " + std::to_string(bad) +
                     " out of range (expected 0 to 3 - 1)");
  }
}

TEST(PlyReader, RejectsNegativeBinaryListCount) {
  std::string file = binary_header("element vertex 1\n" + kXyz +
                                   "element face 1\nproperty list char int vertex_indices\n");
  for (int i = 0; i < 3; ++i) put(file, float(i));
  const std::size_t offset = file.size();
  put(file, std::int8_t(-1));
  expect_error(file, "byte " + std::to_string(offset),
               "face 0 of 1: list property vertex_indices: negative count -1");
}

TEST(PlyReader, RejectsNonFiniteBinaryCoordinates) {
  for (float bad :
       {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
    std::string file = binary_header("element vertex 2000\n" + kXyz);
    const std::size_t body = file.size();
    for (int i = 0; i < 2000; ++i)
      for (int k = 0; k < 3; ++k) put(file, (i == 1500 && k == 2) ? bad : float(i));
    expect_error(file, "byte " + std::to_string(body + 1500 * 12 + 8),
                 "vertex 1500 of 2000: property z is not a finite number");
  }
  // double too large for a float, through the generic walker (the vertex has a list)
  std::string file = binary_header(
      "element vertex 1\nproperty double x\nproperty double y\nproperty double z\n"
      "property list uchar int extra\n");
  const std::size_t body = file.size();
  put(file, 1e300);
  put(file, 0.0);
  put(file, 0.0);
  put(file, std::uint8_t(0));
  expect_error(file, "byte " + std::to_string(body),
               "vertex 0 of 1: property x is not a finite number");
}

TEST(PlyReader, NamesDecompressedOffsetsInGzipFiles) {
  TempDir dir;
  std::string file = binary_header("element vertex 2\n" + kXyz);
  const std::size_t body = file.size();
  for (int i = 0; i < 5; ++i) put(file, float(i));
  const std::string path = dir.file("short.ply.gz");
  write_file(path, testing::gzip(file));
  try {
    read_ply(path);
    ADD_FAILURE() << "no exception";
  } catch (const FormatError& e) {
    EXPECT_CONTAINS(
        e.what(), path + ": byte " + std::to_string(body + 20) + " (decompressed): vertex 1 of 2");
  }
}

TEST(PlyReader, RejectsCorruptGzip) {
  TempDir dir;
  std::string body;
  for (int i = 0; i < 2000; ++i) body += std::to_string(i * 7919 % 1000) + " 0 0\n";
  const std::string file =
      "ply\nformat ascii 1.0\nelement vertex 2000\n" + kXyz + "end_header\n" + body;
  std::string zipped = testing::gzip(file);
  std::string corrupt = zipped;
  for (std::size_t i = 20; i < 60; ++i) corrupt[i] = static_cast<char>(corrupt[i] ^ 0x5a);
  std::string path;
  const std::string message = error_for(dir, corrupt, &path);
  EXPECT_CONTAINS(message, path + ": compressed byte ");
  EXPECT_CONTAINS(message, "corrupt gzip data");
  expect_error(zipped.substr(0, zipped.size() / 2),
               "compressed byte " + std::to_string(zipped.size() / 2), "gzip data ends early");
}

// Ascii bodies ----------------------------------------------------------------------------

TEST(PlyReader, RejectsAsciiLineWithMissingValue) {
  expect_error(kAsciiHeader2 + "0 0 0\n1 2\n3 4 5\n", "line 9",
               "vertex 1 of 2: property z: line ends early (expected a number, found end of line)");
}

TEST(PlyReader, RejectsAsciiLineWithExtraValue) {
  expect_error(kAsciiHeader2 + "0 0 0 7\n1 2 3\n", "line 8",
               "vertex 0 of 2: extra value '7' after property z (expected 3 values on this line)");
}

TEST(PlyReader, RejectsAsciiBodyWithMissingLines) {
  expect_error(kAsciiHeader2 + "0 0 0\n", "line 9",
               "file ends early: vertex 1 of 2 is missing (the header declares 2 vertex, found 1 "
               "element lines)");
  const std::string with_faces =
      "ply\nformat ascii 1.0\nelement vertex 1\n" + kXyz +
      "element face 2\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n3 0 0 0";
  expect_error(with_faces, "line 11", "file ends early: face 1 of 2 is missing");
}

TEST(PlyReader, RejectsAsciiBodyWithExtraLines) {
  expect_error(kAsciiHeader2 + "0 0 0\n1 1 1\n\n2 2 2\n", "line 11",
               "extra data after the last element (the header declares 2 vertex), found '2'");
}

TEST(PlyReader, RejectsNonNumericAsciiToken) {
  expect_error(kAsciiHeader2 + "0 0 0\n1 abc 3\n", "line 9",
               "vertex 1 of 2: property y: expected a number, found 'abc'");
  expect_error(kAsciiHeader2 + "0 0 0\n1 2 3x\n", "line 9",
               "property z: expected a number, found '3x'");
  expect_error(kAsciiHeader2 + "0 0 0\n1 2 --3\n", "line 9", "found '--3'");
}

TEST(PlyReader, RejectsAsciiIntegerProblems) {
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 1\n" + kXyz +
      "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n";
  expect_error(header + "0 0 0 300 0 0\n", "line 11",
               "vertex 0 of 1: property red: value 300 out of range for uchar");
  expect_error(header + "0 0 0 1.5 0 0\n", "line 11",
               "property red: expected an integer (uchar), found '1.5'");
}

TEST(PlyReader, RejectsAsciiFaceIndexOutOfRange) {
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 3\n" + kXyz +
      "element face 2\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 1 1\n2 2 2\n";
  expect_error(header + "3 0 1 2\n3 0 -1 2\n", "line 14",
               "face 1 of 2: list property vertex_indices: vertex index -1 out of range (expected "
               "0 to 3 - 1)");
  expect_error(header + "3 0 1 3\n3 0 1 2\n", "line 13",
               "face 0 of 2: list property vertex_indices: vertex index 3 out of range");
  expect_error(header + "3 0 1\n3 0 1 2\n", "line 13",
               "face 0 of 2: list property vertex_indices: line ends early (expected an integer, "
               "found end of line)");
  expect_error(header + "-3 0 1 2\n3 0 1 2\n", "line 13", "value -3 out of range for uchar");
}

TEST(PlyReader, RejectsNonFiniteAsciiCoordinates) {
  for (const char* bad : {"nan", "inf", "-inf", "1e999"}) {
    expect_error(
        kAsciiHeader2 + "0 0 0\n1 " + bad + " 3\n", "line 9",
        "vertex 1 of 2: property y is not a finite number (found '" + std::string(bad) + "')");
  }
}

TEST(PlyReader, RejectsNonFiniteRadius) {
  expect_error("ply\nformat ascii 1.0\nelement vertex 1\n" + kXyz +
                   "property float radius\nend_header\n0 0 0 nan\n",
               "line 9", "property radius is not a finite number");
}

// The file system -------------------------------------------------------------------------

TEST(PlyReader, RejectsMissingFileAndDirectoryWithIoError) {
  TempDir dir;
  const std::string missing = dir.file("missing.ply");
  try {
    read_ply(missing);
    ADD_FAILURE() << "no exception";
  } catch (const IoError& e) {
    EXPECT_CONTAINS(e.what(), "cannot open " + missing);
  }
  try {
    read_ply(dir.path().string());
    ADD_FAILURE() << "no exception";
  } catch (const IoError& e) {
    EXPECT_CONTAINS(e.what(), dir.path().string());
  }
}

// Seeded random damage (flipped bytes, cuts, inserted bytes) to valid files in every encoding:
// every outcome is a PointSet or a FormatError naming the file, never a crash, hang or other
// exception (the sanitizer build checks the memory accesses).
TEST(PlyReader, SurvivesRandomCorruption) {
  TempDir dir;
  std::vector<std::string> seeds;
  const std::string elements =
      "element vertex 4\n" + kXyz +
      "property uchar red\nproperty uchar green\nproperty uchar blue\nproperty float nx\n"
      "property float ny\nproperty float nz\n"
      "element face 2\nproperty list uchar int vertex_indices\n";
  seeds.push_back("ply\nformat ascii 1.0\n" + elements + "end_header\n" +
                  "0 0 0 1 2 3 0 0 1\n1 0 0 4 5 6 0 1 0\n1 1 0 7 8 9 1 0 0\n0 1 0 1 1 1 0 0 1\n3 0 "
                  "1 2\n4 0 1 2 3\n");
  for (bool big : {false, true}) {
    std::string b = std::string("ply\nformat ") +
                    (big ? "binary_big_endian" : "binary_little_endian") + " 1.0\n" + elements +
                    "end_header\n";
    for (int v = 0; v < 4; ++v) {
      for (int k = 0; k < 3; ++k) put(b, float(v + k), big);
      for (int k = 0; k < 3; ++k) put(b, std::uint8_t(v * 3 + k), big);
      for (int k = 0; k < 3; ++k) put(b, float(k == 2), big);
    }
    put(b, std::uint8_t(3), big);
    for (int i : {0, 1, 2}) put(b, std::int32_t(i), big);
    put(b, std::uint8_t(4), big);
    for (int i : {0, 1, 2, 3}) put(b, std::int32_t(i), big);
    seeds.push_back(b);
  }
  seeds.push_back(testing::gzip(seeds[0]));
  seeds.push_back(testing::gzip(seeds[1]));

  std::mt19937 rng(2024);
  const std::string path = dir.file("fuzz.ply");
  int ok = 0, rejected = 0;
  for (int round = 0; round < 600; ++round) {
    std::string bytes = seeds[round % seeds.size()];
    const int edits = 1 + static_cast<int>(rng() % 4);
    for (int k = 0; k < edits && !bytes.empty(); ++k) {
      const std::size_t at = rng() % bytes.size();
      switch (rng() % 4) {
        case 0:
          bytes[at] = static_cast<char>(rng());
          break;
        case 1:
          bytes.resize(at);
          break;
        case 2:
          bytes.insert(at, 1, static_cast<char>(rng()));
          break;
        default:
          bytes[at] = "0123456789 \n-.e"[rng() % 15];
          break;
      }
    }
    write_file(path, bytes);
    try {
      const PointSet points = read_ply(path);
      ++ok;
      for (const auto& t : points.triangles)
        for (std::uint32_t v : t) ASSERT_LT(v, points.size());
      for (Vec3f p : points.positions) ASSERT_TRUE(is_finite(p));
    } catch (const FormatError& e) {
      ++rejected;
      ASSERT_EQ(std::string(e.what()).rfind(path + ": ", 0), 0u) << e.what();
    }
  }
  EXPECT_GT(ok, 0);
  EXPECT_GT(rejected, 0);
}

}  // namespace
}  // namespace pointillist
