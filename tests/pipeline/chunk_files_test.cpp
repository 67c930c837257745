// The chunked conversion's splat files (private to the pipeline module): what is written comes
// back, with the arrays asked for; a file of another size is named as changed.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "chunk_files.hpp"
#include "pointillist/core/error.hpp"
#include "testing/testing.hpp"

namespace pointillist::chunking {
namespace {

Splats some_splats(std::size_t n) {
  Splats s;
  for (std::size_t i = 0; i < n; ++i) {
    const float f = float(i);
    s.points.positions.push_back({f, 2 * f, -f});
    s.points.normals.push_back({0, f > 2 ? 1.0f : -1.0f, 0});
    s.points.radii.push_back(0.5f + f);
    s.points.colors.push_back({std::uint8_t(i), std::uint8_t(2 * i), 7});
    s.index.push_back(1000 + 3 * i);
    s.piece.push_back(std::uint32_t(i % 2));
  }
  return s;
}

TEST(ChunkFiles, SplatsComeBackWithTheArraysAskedFor) {
  testing::TempDir dir;
  const std::string path = dir.file("s.prepared");
  const Splats s = some_splats(5);
  write_splats(path, s);
  const Splats all = read_splats(path, 5, true, true, true);
  EXPECT_EQ(all.points.positions, s.points.positions);
  EXPECT_EQ(all.points.normals, s.points.normals);
  EXPECT_EQ(all.points.radii, s.points.radii);
  EXPECT_EQ(all.points.colors, s.points.colors);
  EXPECT_EQ(all.index, s.index);
  EXPECT_EQ(all.piece, s.piece);
  // Normals, indices and pieces only: no geometry.
  const Splats some = read_splats(path, 5, true, true, true, false);
  EXPECT_TRUE(some.points.positions.empty());
  EXPECT_TRUE(some.points.radii.empty());
  EXPECT_EQ(some.points.normals, s.points.normals);
  EXPECT_EQ(some.index, s.index);
  EXPECT_EQ(some.piece, s.piece);
}

TEST(ChunkFiles, ASplatFileOfAnotherSizeIsNamedAsChanged) {
  testing::TempDir dir;
  const std::string path = dir.file("s.prepared");
  write_splats(path, some_splats(5));
  std::ofstream(path, std::ios::binary | std::ios::app).write("x", 1);
  try {
    read_splats(path, 5, true, true, true);
    FAIL() << "no error";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find(path + ": a chunk file changed on disk"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace pointillist::chunking
