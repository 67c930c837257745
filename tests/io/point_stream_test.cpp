// Streamed reading: every stream yields, batch by batch, exactly the points read_point_file
// reads from the same file (the whole-file readers are the oracle), and bad data is reported
// at the same place.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <optional>

#include "io/io_test_support.hpp"
#include "io/las_builder.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/io/ply.hpp"
#include "pointillist/io/point_stream.hpp"
#include "testing/testing.hpp"

namespace pointillist {
namespace {

using testing::TempDir;

// Every point of `stream`, read `batch` at a time (twice, with a rewind in between, to check
// that rewinding starts over).
PointSet drain(PointStream& stream, std::size_t batch) {
  PointSet all, part;
  for (int pass = 0; pass < 2; ++pass) {
    all = PointSet{};
    stream.rewind();
    while (const std::size_t n = stream.read(part, batch)) {
      EXPECT_LE(n, batch);
      EXPECT_EQ(part.size(), n);
      const auto append = [](auto& dst, const auto& src) {
        dst.insert(dst.end(), src.begin(), src.end());
      };
      append(all.positions, part.positions);
      append(all.normals, part.normals);
      append(all.colors, part.colors);
      append(all.radii, part.radii);
    }
  }
  return all;
}

// The message of the FormatError that `fn` throws ("" when it throws none).
template <class Fn>
std::string format_error_of(Fn&& fn) {
  try {
    fn();
  } catch (const FormatError& e) {
    return e.what();
  }
  return "";
}

template <class T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

void expect_same_points(const PointSet& streamed, const PointSet& whole) {
  EXPECT_EQ(streamed.size(), whole.size());
  EXPECT_TRUE(same_bits(streamed.positions, whole.positions));
  EXPECT_TRUE(same_bits(streamed.normals, whole.normals));
  EXPECT_TRUE(same_bits(streamed.colors, whole.colors));
  EXPECT_TRUE(same_bits(streamed.radii, whole.radii));
}

PointSet sample_points(std::size_t n, bool normals, bool colors, bool radii) {
  PointSet p;
  for (std::size_t i = 0; i < n; ++i) {
    const float t = float(i) * 0.37f;
    p.positions.push_back({std::cos(t) * 3.0f, std::sin(t) * 2.0f, float(i) * 0.01f - 4.0f});
    if (normals) p.normals.push_back(normalized(Vec3f{std::cos(t), std::sin(t), 0.25f}));
    if (colors) p.colors.push_back({std::uint8_t(i), std::uint8_t(i * 7), std::uint8_t(i * 13)});
    if (radii) p.radii.push_back(0.01f + float(i % 17) * 0.001f);
  }
  return p;
}

// Each text file of `files` (name, contents), plain and gzip, with and without colours: its
// stream states what read_point_file reads and yields its points, bit for bit (a mesh's
// vertex positions only: their normals come from its faces).
void expect_text_files_stream_as_read_whole(
    const TempDir& dir, const std::vector<std::pair<std::string, std::string>>& files) {
  for (const auto& [name, text] : files) {
    for (const bool gz : {false, true}) {
      const std::string path = dir.file(name + (gz ? ".gz" : ""));
      testing::write_file(path, gz ? testing::gzip(text) : text);
      for (const bool colors : {true, false}) {
        SCOPED_TRACE(path + (colors ? "" : ", no colours"));
        const PointReadOptions options{.read_colors = colors};
        const auto stream = open_point_stream(path, options);
        EXPECT_TRUE(stream->info().streamed);
        const PointSet whole = read_point_file(path, Progress::none(), options);
        EXPECT_EQ(stream->info().point_count, whole.size());
        EXPECT_EQ(stream->info().origin, whole.origin);
        EXPECT_EQ(stream->info().comments, whole.comments);
        EXPECT_EQ(stream->info().has_colors, whole.has_colors());
        EXPECT_EQ(stream->info().is_mesh, whole.is_mesh());
        PointSet streamed = drain(*stream, 100000);
        if (!stream->saw_usable_normals()) streamed.normals.clear();
        if (whole.is_mesh()) {
          EXPECT_TRUE(same_bits(streamed.positions, whole.positions));
        } else {
          expect_same_points(streamed, whole);
        }
      }
    }
  }
}

TEST(PointStream, BinaryPlyGivesTheSamePointsAsTheWholeFileReader) {
  TempDir dir;
  for (const PlyEncoding encoding : {PlyEncoding::BinaryLittleEndian,
                                     PlyEncoding::BinaryBigEndian}) {
    const std::string path = dir.file("cloud.ply");
    PointSet points = sample_points(5000, true, true, true);
    points.origin = {1000.5, -20, 3};
    points.up = {0, 0, 1};
    points.comments = {"scanned on a Tuesday"};
    write_ply(path, points, {.encoding = encoding});
    const auto stream = open_point_stream(path);
    const PointStreamInfo& info = stream->info();
    EXPECT_TRUE(info.streamed);
    EXPECT_FALSE(info.is_mesh);
    EXPECT_EQ(info.point_count, 5000u);
    EXPECT_TRUE(info.has_normals && info.has_colors && info.has_radii);
    const PointSet whole = read_point_file(path);
    EXPECT_EQ(info.origin, whole.origin);
    EXPECT_EQ(info.up, whole.up);
    EXPECT_EQ(info.comments, whole.comments);
    expect_same_points(drain(*stream, 777), whole);
    EXPECT_EQ(stream->bytes_done(), info.file_size);
    EXPECT_TRUE(stream->saw_usable_normals());
  }
}

// Hand-made bytes: an element of fixed-size records before the vertices, and faces after them.
TEST(PointStream, FindsVerticesAfterAnotherElementAndFlagsMeshes) {
  TempDir dir;
  std::string bytes =
      "ply\nformat binary_little_endian 1.0\nelement camera 2\nproperty double a\n"
      "property uchar b\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  for (int c = 0; c < 2; ++c) {
    testing::put(bytes, 1.5 * c);
    testing::put(bytes, std::uint8_t(c));
  }
  for (int v = 0; v < 3; ++v) {
    testing::put(bytes, float(v));
    testing::put(bytes, float(v * 2));
    testing::put(bytes, float(-v));
  }
  testing::put(bytes, std::uint8_t(3));
  for (int v = 0; v < 3; ++v) testing::put(bytes, std::int32_t(v));
  const std::string path = dir.file("mesh.ply");
  testing::write_file(path, bytes);
  const auto stream = open_point_stream(path);
  EXPECT_TRUE(stream->info().streamed);
  EXPECT_TRUE(stream->info().is_mesh);
  const PointSet streamed = drain(*stream, 2);
  ASSERT_EQ(streamed.size(), 3u);
  EXPECT_EQ(streamed.positions[2], (Vec3f{2, 4, -2}));
  expect_same_points(streamed, read_point_file(path));
}

TEST(PointStream, ReportsBadValuesAtTheSamePlaceAsTheWholeFileReader) {
  TempDir dir;
  PointSet points = sample_points(3000, false, false, false);
  points.positions[2345].y = std::numeric_limits<float>::quiet_NaN();
  const std::string path = dir.file("nan.ply");
  write_ply(path, points);
  const std::string whole_message = format_error_of([&] { read_point_file(path); });
  const std::string stream_message =
      format_error_of([&] { drain(*open_point_stream(path), 1000); });
  EXPECT_NE(whole_message.find("vertex 2345 of 3000"), std::string::npos) << whole_message;
  EXPECT_EQ(stream_message, whole_message);
}

TEST(PointStream, RefusesATruncatedBinaryPlyWhenOpened) {
  TempDir dir;
  const std::string path = dir.file("short.ply");
  write_ply(path, sample_points(100, false, true, false));
  std::string bytes = testing::read_file(path);
  bytes.resize(bytes.size() - 5);
  testing::write_file(path, bytes);
  try {
    open_point_stream(path);
    FAIL() << "a truncated file opened";
  } catch (const FormatError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find(path), std::string::npos) << m;
    EXPECT_NE(m.find("truncated"), std::string::npos) << m;
  }
}

TEST(PointStream, AllZeroNormalsAreSeenAsUnusable) {
  TempDir dir;
  PointSet points = sample_points(50, true, false, false);
  for (Vec3f& n : points.normals) n = {0, 0, 0};
  const std::string path = dir.file("zeros.ply");
  write_ply(path, points);
  EXPECT_FALSE(read_point_file(path).has_normals());  // what the stream must let callers know
  const auto stream = open_point_stream(path);
  drain(*stream, 16);
  EXPECT_FALSE(stream->saw_usable_normals());
}

// ASCII PLY streams a window of lines at a time, plain or gzip, with an element before the
// vertices and blank lines among them: the whole-file reader's points are the oracle.
TEST(PointStream, AsciiPlyStreamsTheWholeFileReadersPoints) {
  TempDir dir;
  const std::string made = dir.file("made.ply");
  write_ply(made, sample_points(300000, true, true, true), {.encoding = PlyEncoding::Ascii});
  std::string text = testing::read_file(made);
  // an element of two lines before the vertices, and blank lines in the body
  const std::size_t at = text.find("element vertex");
  text.insert(at, "element camera 2\nproperty float f\n");
  const std::size_t body = text.find("end_header\n") + 11;
  text.insert(body, "1.5\n\n2.5\n");
  text.insert(text.find('\n', body + 5000) + 1, "  \n");
  const std::string plain = dir.file("cloud.ply"), packed = dir.file("cloud.ply.gz");
  testing::write_file(plain, text);
  testing::write_file(packed, testing::gzip(text));
  const PointSet whole = read_point_file(plain);
  ASSERT_EQ(whole.size(), 300000u);
  for (const std::string& path : {plain, packed}) {
    const auto stream = open_point_stream(path);
    EXPECT_TRUE(stream->info().streamed) << path;
    EXPECT_EQ(stream->info().point_count, 300000u);
    expect_same_points(drain(*stream, 70000), whole);
  }
}

// A bad value in an ASCII PLY is named at the same line by the stream as by the whole-file
// reader, past several windows; a file with too few vertex lines fails when read.
TEST(PointStream, AsciiPlyErrorsNameTheSameLineAsTheWholeFileReader) {
  TempDir dir;
  const std::string path = dir.file("bad.ply");
  write_ply(path, sample_points(200000, false, false, false), {.encoding = PlyEncoding::Ascii});
  std::string text = testing::read_file(path);
  std::size_t line_start = text.find("end_header\n") + 11;
  for (int k = 0; k < 180000; ++k) line_start = text.find('\n', line_start) + 1;
  text.replace(line_start, text.find(' ', line_start) - line_start, "1.2.3");
  testing::write_file(path, text);
  const std::string whole_message = format_error_of([&] { read_point_file(path); });
  const std::string stream_message =
      format_error_of([&] { drain(*open_point_stream(path), 50000); });
  EXPECT_NE(whole_message.find("vertex 180000 of 200000"), std::string::npos) << whole_message;
  EXPECT_EQ(stream_message, whole_message);

  const std::string short_path = dir.file("short.ply");
  write_ply(short_path, sample_points(1000, false, false, false), {.encoding = PlyEncoding::Ascii});
  std::string short_text = testing::read_file(short_path);
  short_text.resize(short_text.rfind('\n', short_text.size() - 2) + 1);  // the last line gone
  testing::write_file(short_path, short_text);
  try {
    const auto stream = open_point_stream(short_path);
    drain(*stream, 300);
    FAIL() << "a short ASCII PLY read to the end";
  } catch (const FormatError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find(short_path), std::string::npos) << m;
    EXPECT_NE(m.find("ends early"), std::string::npos) << m;
  }
}

// Text files of every shape read_xyz knows, streamed: the same points, origin and comments as
// the whole-file reader (its result is the oracle), plain and gzip.
TEST(PointStream, TextFilesAreStreamedWithTheSamePointsAsTheWholeFileReader) {
  TempDir dir;
  std::string big;  // past several windows: 12 MB of lines, normals and 0..1 colours
  for (int i = 0; i < 260000; ++i) {
    const double a = i * 0.001;
    big += std::to_string(512000.25 + std::cos(a) * 40) + " " +
           std::to_string(5400000.5 + std::sin(a) * 40) + " " + std::to_string(i % 977 * 0.01) +
           " " + std::to_string(std::cos(a)) + " " + std::to_string(std::sin(a)) + " 0 " +
           std::to_string((i % 100) / 100.0) + " 0.5 1.0\n";
    if (i % 50000 == 7) big += "\n# a comment among the points\n";
  }
  const std::vector<std::pair<std::string, std::string>> files = {
      {"colours.xyz", "1 2 3 255 0 0\n4 5 6 0 255 0\n\n7 8 9 0 0 255"},  // no last newline
      {"header.csv", "//X,Y,Z,R,G,B\n1.5,2,3,10,20,30\n4,5,6,40,50,60,\n"},
      {"scan.pts", "3\n1 2 3 -1200 200 100 50\n4 5 6 -900 1 2 3\n7 8 9 -1 4 5 6\n"},
      {"words.txt", "# x y z r g b\n0 0 0 65535 0 1000\n1 1 1 300 300 300\n"},
      {"zeros.xyz", "1 2 3 0 0 0\n2 3 4 0 0 0\n"},
      {"big.xyz", big}};
  expect_text_files_stream_as_read_whole(dir, files);
  // The columns option too.
  const std::string path = dir.file("columns.xyz");
  testing::write_file(path, "1 2 3 9 0.5 0.5 0.5\n4 5 6 9 1 0 0\n");
  const PointReadOptions options{.columns = "x y z skip r g b"};
  const auto stream = open_point_stream(path, options);
  expect_same_points(drain(*stream, 1), read_point_file(path, Progress::none(), options));
}

// A bad value far into a text file (past the first windows) is reported on the same line as
// the whole-file reader reports it, when the stream opens (its first pass reads every line).
TEST(PointStream, ReportsABadTextLineAtTheSameLineAsTheWholeFileReader) {
  TempDir dir;
  std::string text = "x y z nx ny nz\n";
  for (int i = 0; i < 400000; ++i) {
    text += std::to_string(i) + " 1 2 0.6 0.8 0\n";
    if (i == 333333) text += "5 5 five 0 0 1\n";
  }
  const std::string path = dir.file("bad.xyz");
  testing::write_file(path, text);
  std::string whole, streamed;
  try {
    read_point_file(path);
  } catch (const FormatError& e) {
    whole = e.what();
  }
  try {
    open_point_stream(path);
  } catch (const FormatError& e) {
    streamed = e.what();
  }
  EXPECT_NE(whole.find("line 333336"), std::string::npos) << whole;
  EXPECT_EQ(streamed, whole);
}

TEST(PointStream, ObjFilesAreStreamedWithTheSamePointsAsTheWholeFileReader) {
  TempDir dir;
  // Past several windows: 14 MB of vertex lines far from the origin, with 0..1 colours, among
  // normals, texture coordinates, groups and comments.
  std::string big = "# a scan written as OBJ\no scan\n";
  for (int i = 0; i < 250000; ++i) {
    const double a = i * 0.001;
    big += "v " + std::to_string(512000.25 + std::cos(a) * 40) + " " +
           std::to_string(5400000.5 + std::sin(a) * 40) + " " + std::to_string(i % 977 * 0.01) +
           " " + std::to_string((i % 100) / 100.0) + " 0.5 1.0\n";
    if (i % 50000 == 7) big += "vn 0 0 1\nvt 0.5 0.5\n\n# more points\ng part\n";
  }
  const std::vector<std::pair<std::string, std::string>> files = {
      {"bytes.obj", "v 1 2 3 255 0 0\nv 4 5 6 0 255 0\n\nv 7 8 9 0 0 255"},  // no last newline
      {"w.obj", "# x y z w\nv 1 2 3 1\nv 4 5 6 1\r\n  v\t7 8 9\n"},
      {"some.obj", "v 1 2 3 0.5 0.5 0.5\nv 4 5 6\n"},  // colours on one vertex of two: none
      {"mesh.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1\n"},
      {"line.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n"},  // no triangle: points
      {"big.obj", big}};
  expect_text_files_stream_as_read_whole(dir, files);
}

// A bad vertex far into an OBJ file is reported on the same line as the whole-file reader
// reports it, when the stream opens.
TEST(PointStream, ReportsABadObjVertexAtTheSameLineAsTheWholeFileReader) {
  TempDir dir;
  for (const std::string bad : {"v 5 5 five", "v 1 2", "v 1 2 3 4 5", "v 1 inf 2",
                                "v 1 2 3 4 5 6 7 8", "v 1e300 0 0"}) {
    SCOPED_TRACE(bad);
    std::string text;
    for (int i = 0; i < 300000; ++i) {
      text += "v " + std::to_string(i) + " 1 2\n";
      if (i == 222222) text += bad + "\n";
    }
    const std::string path = dir.file("bad.obj");
    testing::write_file(path, text);
    const std::string whole = format_error_of([&] { read_point_file(path); });
    const std::string streamed = format_error_of([&] { open_point_stream(path); });
    EXPECT_NE(whole.find("line 222224"), std::string::npos) << whole;
    EXPECT_EQ(streamed, whole);
  }
}

TEST(PointStream, LasGivesTheSamePointsOriginAndColoursAsTheWholeFileReader) {
  TempDir dir;
  testing::LasSpec spec{.format = 3, .scale = {0.01, 0.01, 0.01}, .offset = {500000, 5400000, 0}};
  std::vector<testing::LasPoint> points;
  for (std::int32_t i = 0; i < 70000; ++i) {
    points.push_back({i * 7 - 5000, (i * 13) % 100000, -i, static_cast<std::uint16_t>(i * 5),
                      static_cast<std::uint16_t>(i * 3), static_cast<std::uint16_t>(i)});
  }
  const std::string path = dir.file("tile.las");
  testing::write_file(path, testing::build_las(spec, points));
  const auto stream = open_point_stream(path);
  EXPECT_TRUE(stream->info().streamed);
  const PointSet whole = read_point_file(path);
  EXPECT_EQ(stream->info().origin, whole.origin);
  EXPECT_NE(whole.origin, (std::array<double, 3>{}));  // the shift is exercised
  EXPECT_EQ(stream->info().up, whole.up);
  EXPECT_EQ(stream->info().comments, whole.comments);
  EXPECT_TRUE(stream->info().has_colors);
  expect_same_points(drain(*stream, 4096), whole);
}

// gzip PLY and LAS files stream too (decompressed as they are read, again on rewind): the
// points, frame and colours of the plain file read whole are the oracle.
TEST(PointStream, GzipBinaryPlyAndLasStreamTheirPlainFilesPoints) {
  TempDir dir;
  const std::string plain = dir.file("cloud.ply"), packed = dir.file("cloud.ply.gz");
  write_ply(plain, sample_points(40000, true, true, true), {.encoding = PlyEncoding::BinaryBigEndian});
  testing::write_file(packed, testing::gzip(testing::read_file(plain)));
  auto stream = open_point_stream(packed);
  EXPECT_TRUE(stream->info().streamed);
  EXPECT_EQ(stream->info().point_count, 40000u);
  expect_same_points(drain(*stream, 3000), read_point_file(plain));
  EXPECT_EQ(stream->bytes_done(), stream->info().file_size);  // progress ends at 100 %
  EXPECT_EQ(exact_point_count(packed), std::optional<std::uint64_t>(40000));

  testing::LasSpec spec{.format = 2, .scale = {0.001, 0.001, 0.001}, .offset = {300000, 0, 0}};
  std::vector<testing::LasPoint> points;
  for (std::int32_t i = 0; i < 30000; ++i) {
    points.push_back({i * 3 - 7000, (i * 11) % 9000, i % 500, static_cast<std::uint16_t>(i * 9),
                      static_cast<std::uint16_t>(i * 5), static_cast<std::uint16_t>(i * 2)});
  }
  const std::string las = dir.file("tile.las"), las_gz = dir.file("tile.las.gz");
  testing::write_file(las, testing::build_las(spec, points));
  testing::write_file(las_gz, testing::gzip(testing::read_file(las)));
  stream = open_point_stream(las_gz);
  EXPECT_TRUE(stream->info().streamed);
  const PointSet whole = read_point_file(las);
  EXPECT_EQ(stream->info().origin, whole.origin);
  EXPECT_TRUE(stream->info().has_colors);
  expect_same_points(drain(*stream, 2500), whole);
}

// A gzip file whose data ends early, or is damaged, fails with a message naming it (its length
// is known only at its end, so the short one fails when the missing points are read).
TEST(PointStream, ShortOrDamagedGzipDataFailsWithAMessage) {
  TempDir dir;
  const std::string plain = dir.file("cloud.ply");
  write_ply(plain, sample_points(20000, false, true, false));
  std::string bytes = testing::read_file(plain);
  bytes.resize(bytes.size() - 7);
  const std::string short_gz = dir.file("short.ply.gz");
  testing::write_file(short_gz, testing::gzip(bytes));
  try {
    auto stream = open_point_stream(short_gz);
    drain(*stream, 4096);
    FAIL() << "a short gzip file read to the end";
  } catch (const FormatError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find(short_gz), std::string::npos) << m;
    EXPECT_NE(m.find("truncated"), std::string::npos) << m;
  }
  std::string packed = testing::gzip(testing::read_file(plain));
  for (std::size_t i = packed.size() / 2; i < packed.size() / 2 + 64; ++i) packed[i] ^= 0x5a;
  const std::string damaged = dir.file("damaged.ply.gz");
  testing::write_file(damaged, packed);
  try {
    auto stream = open_point_stream(damaged);
    drain(*stream, 4096);
    FAIL() << "a damaged gzip file read to the end";
  } catch (const FormatError& e) {
    EXPECT_NE(std::string(e.what()).find(damaged), std::string::npos) << e.what();
  }
}

// A gzip LAS whose header claims more points than its data can inflate to (deflate's ratio is
// at most 1032 to 1) is refused when opened, before anything is sized by that count.
TEST(PointStream, AGzipHeaderClaimingMorePointsThanItsDataCanHoldIsRefused) {
  TempDir dir;
  std::vector<testing::LasPoint> points(100, testing::LasPoint{1, 2, 3, 0, 0, 0});
  std::string las = testing::build_las(testing::LasSpec{.format = 2}, points);
  for (int i = 107; i < 111; ++i) las[i] = static_cast<char>(0xff);  // 4,294,967,295 points
  const std::string path = dir.file("bomb.las.gz");
  testing::write_file(path, testing::gzip(las));
  try {
    open_point_stream(path);
    FAIL() << "the claim was believed";
  } catch (const FormatError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find(path), std::string::npos) << m;
    EXPECT_NE(m.find("4294967295 points"), std::string::npos) << m;
    EXPECT_NE(m.find("inflate to at most"), std::string::npos) << m;
  }
  EXPECT_THROW(point_count_estimate(path), FormatError);
}

TEST(PointStream, MissingFileIsAnIoError) {
  TempDir dir;
  EXPECT_THROW(open_point_stream(dir.file("nothing.ply")), IoError);
}

}  // namespace
}  // namespace pointillist
