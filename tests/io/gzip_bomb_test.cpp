// Gzip files whose data goes on far past what their PLY or LAS header describes (a "gzip bomb": a small
// file inflating to gigabytes) is refused as soon as the inflated data passes the most bytes the
// header allows (plus 1 MiB), whether it is inflated whole or while parsing. The oracle: the
// header size plus the body size the test's own header gives (10 binary vertices of 12 bytes).
#include <gtest/gtest.h>

#include <string>

#include "io_test_support.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/core/thread_pool.hpp"
#include "las_builder.hpp"
#include "pointillist/io/las.hpp"
#include "pointillist/io/ply.hpp"
#include "testing/testing.hpp"

using namespace pointillist;

namespace {

const std::string kHeader =
    "ply\nformat binary_little_endian 1.0\nelement vertex 10\nproperty float x\n"
    "property float y\nproperty float z\nend_header\n";

std::string error_of(const std::string& path, ThreadPool* pool) {
  try {
    read_ply(path, Progress::none(), {.pool = pool});
  } catch (const FormatError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(PlyGzip, DataFarPastWhatTheHeaderDescribesIsRefusedAtTheBound) {
  pointillist::testing::TempDir dir;
  const std::string path = dir.file("bomb.ply.gz");
  // 10 vertices, then 64 MiB of zeros: about 64 KB compressed.
  const std::string body(10 * 12, '\0');
  pointillist::testing::write_file(path, pointillist::testing::gzip(kHeader + body + std::string(64 << 20, '\0'), 9));
  // The header's bytes and body, and 1 MiB of slack for trailing bytes some writers leave.
  const std::size_t bound = kHeader.size() + body.size() + (1 << 20);
  const std::string expected = path + ": decompressed byte " + std::to_string(bound) +
                               ": the data goes on past the " + std::to_string(bound) + " bytes";
  ThreadPool one(1), two(2);
  for (ThreadPool* pool : {static_cast<ThreadPool*>(nullptr), &one, &two}) {
    const std::string message = error_of(path, pool);
    EXPECT_NE(message.find(expected), std::string::npos)
        << "threads " << (pool ? pool->thread_count() : 0) << ": " << message;
  }
}

TEST(PlyGzip, AFileThatEndsWhereItsHeaderSaysStillReads) {
  pointillist::testing::TempDir dir;
  const std::string path = dir.file("ok.ply.gz");
  std::string body;
  for (int i = 0; i < 10; ++i) {
    const float v[3] = {float(i), 2.0f * float(i), -1.0f};
    body.append(reinterpret_cast<const char*>(v), sizeof v);
  }
  pointillist::testing::write_file(path, pointillist::testing::gzip(kHeader + body));
  ThreadPool two(2);
  for (ThreadPool* pool : {static_cast<ThreadPool*>(nullptr), &two}) {
    const PointSet p = read_ply(path, Progress::none(), {.pool = pool});
    ASSERT_EQ(p.size(), 10u);
    EXPECT_EQ(p.positions[9], (Vec3f{9, 18, -1}));
  }
}

// The same for LAS: the public header's point data offset + count × record length bound it.
TEST(LasGzip, DataFarPastWhatTheHeaderDescribesIsRefusedAtTheBound) {
  pointillist::testing::TempDir dir;
  const std::string path = dir.file("bomb.las.gz");
  const std::vector<pointillist::testing::LasPoint> points(10, {1, 2, 3});
  const std::string las = pointillist::testing::build_las({.minor = 2}, points);
  pointillist::testing::write_file(path,
                                   pointillist::testing::gzip(las + std::string(64 << 20, '\0'), 9));
  const std::size_t bound = las.size() + (1 << 20);  // header + records, 1 MiB of slack
  try {
    read_las(path, Progress::none());
    FAIL() << "a LAS gzip bomb was read";
  } catch (const FormatError& e) {
    EXPECT_NE(std::string(e.what()).find(path + ": decompressed byte " + std::to_string(bound) +
                                         ": the data goes on past"),
              std::string::npos)
        << e.what();
  }
  // Without the zeros it reads.
  pointillist::testing::write_file(path, pointillist::testing::gzip(las, 9));
  EXPECT_EQ(read_las(path, Progress::none()).size(), 10u);
}
