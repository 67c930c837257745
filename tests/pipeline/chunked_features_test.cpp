// Sharp features of a model converted in chunks (--features with --memory or --chunk-points):
// the conversion in one piece is the oracle. Its decoded hierarchy and every node's features
// (surface id, clip mode, planes) must come out bit for bit, with the same statistics, since the
// chunks are subtrees of the one-piece hierarchy and the features are found on the same decoded
// leaves, part by part with halos. (The files differ in their pages: each chunk has its own.)
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>

#include "pointillist/format/ptl_v2.hpp"
#include "pointillist/io/ply.hpp"
#include "pointillist/pipeline/convert.hpp"
#include "pointillist/scene/analytic.hpp"
#include "testing/testing.hpp"

namespace pointillist {
namespace {

using testing::TempDir;

// The demo scene (sphere, torus, and a cube with its creases) sampled without normals or radii.
std::string write_cloud(const TempDir& dir, std::size_t count) {
  const PointSet p = sample_scene(demo_scene(), count, 11).points;
  const std::string path = dir.file("scene.ply");
  write_ply(path, p);
  return path;
}

TEST(ChunkedFeatures, ManySmallChunksGiveTheOnePieceFeatures) {
  TempDir dir;
  const std::vector<std::string> inputs{write_cloud(dir, 40000)};
  ThreadPool pool(2);
  for (const FeatureOptions& features :
       {FeatureOptions{}, FeatureOptions{.edge_test = EdgeTest::Linsen,
                                         .clip_rule = ClipRule::Dissertation}}) {
    ConvertOptions whole_options;
    whole_options.features = features;
    ConvertOptions parts_options = whole_options;
    parts_options.chunk_points = 1500;
    const std::string whole = dir.file("whole.ptl"), parts = dir.file("parts.ptl");
    const ConvertResult w = convert(inputs, whole, whole_options, pool, Progress::none());
    const ConvertResult p = convert(inputs, parts, parts_options, pool, Progress::none());
    EXPECT_EQ(w.chunks, 0u);
    EXPECT_GE(p.chunks, 16u);
    const auto file = PtlV2File::open(parts);
    ASSERT_TRUE(file->has_features());
    const TreeFeatures* summary = file->feature_summary();
    ASSERT_NE(summary, nullptr);
    std::printf("[chunked features] %zu chunks: %llu clipped splats, %llu surfaces, %llu edges\n",
                p.chunks, (unsigned long long)summary->stats.clipped,
                (unsigned long long)summary->stats.segments,
                (unsigned long long)summary->stats.edges);
    EXPECT_GT(summary->stats.clipped, 100u) << "the cube's creases are clipped";
    EXPECT_GE(summary->stats.segments, 3u);
    TreeFeatures fa, fb;
    const SphereTree ta = PtlV2File::open(whole)->decode_all(&fa);
    const SphereTree tb = file->decode_all(&fb);
    ASSERT_EQ(ta.nodes.size(), tb.nodes.size());
    EXPECT_EQ(std::memcmp(ta.nodes.data(), tb.nodes.data(), ta.nodes.size() * sizeof(SphereNode)),
              0);
    EXPECT_EQ(fa.options.sharp_threshold, fb.options.sharp_threshold);
    EXPECT_EQ(fa.surface_count, fb.surface_count);
    EXPECT_EQ(fa.surface, fb.surface);
    EXPECT_EQ(fa.clip_mode, fb.clip_mode);
    EXPECT_EQ(fa.clip_offset, fb.clip_offset);
    ASSERT_EQ(fa.clip_planes.size(), fb.clip_planes.size());
    EXPECT_EQ(std::memcmp(fa.clip_planes.data(), fb.clip_planes.data(),
                          fa.clip_planes.size() * sizeof(ClipPlane)),
              0);
    EXPECT_EQ(std::memcmp(&fa.stats, &fb.stats, sizeof(FeatureStats)), 0);
    EXPECT_EQ(PtlV2File::open(whole)->metadata(), file->metadata());
    EXPECT_FALSE(std::filesystem::exists(parts + ".chunks"));
  }
}

}  // namespace
}  // namespace pointillist
