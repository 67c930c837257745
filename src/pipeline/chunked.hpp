// The chunked conversion (private to pipeline; see chunked_convert.cpp).
#pragma once

#include <cstdint>
#include <span>
#include <string>

#include "pointillist/core/progress.hpp"
#include "pointillist/core/thread_pool.hpp"
#include "pointillist/pipeline/convert.hpp"

namespace pointillist::chunking {

// Memory a conversion in one piece takes per point (measured 184 bytes for a cloud, 217 for a
// mesh, with the output's hierarchy), and a chunk's per point of the chunk (its halo, the
// prepared splats, the neighbour rows, the subtree and its encoding).
constexpr std::uint64_t kInCoreBytesPerPoint = 220;
constexpr std::uint64_t kChunkBytesPerPoint = 400;
// With --features, the features' neighbour graph and per-edge work dominate: measured 1.59 GB at
// their peak for 1 M points in one piece (the demo scene, about 108 neighbours a splat at the
// drawn radii). In chunks they are found one part (a chunk and its halo, up to about as many
// points again) at a time, after the other passes.
constexpr std::uint64_t kFeatureBytesPerPoint = 1600;
// A mesh converted in chunks is first read whole and its vertices' normals and radii found from
// its faces: its positions, colours, faces (two triangles a vertex), normals and radii take
// about this much a vertex, besides the file's bytes (measured: 75 bytes a vertex in all on a
// 7 M-vertex binary PLY of 38 bytes a vertex).
constexpr std::uint64_t kMeshBytesPerVertex = 56;
// Chunks hold at most this many points whatever the budget: small chunks are faster (their
// neighbour searches and trees stay in cache) and lean (measured on 20 M points: chunks of
// 1.25 M 46 s and 0.61 GB, of 5 M 58 s and 1.88 GB, the conversion in one piece 55 s and 3.4 GB).
constexpr std::uint64_t kMaxChunkPoints = 2'000'000;
// The chunk plan in memory holds every position and its place in the split order; over the
// budget, the plan works from a file of the positions instead.
constexpr std::uint64_t kPlanBytesPerPoint = 16;
// A chunk's halo reaches this many point spacings beyond its box (a 16-neighbourhood on a
// surface spans about 2.3).
constexpr float kHaloSpacings = 6.0f;
// With outlier removal the halo reaches this much farther: a point's verdict takes its
// neighbours' neighbourhoods, and the chunk's own points need the verdicts of their neighbours.
constexpr float kOutlierHaloFactor = 2.0f;

// Converts `inputs` (point clouds) to the .ptl v2 file `output` in chunks of at most
// `max_chunk_points` points (rounded to the hierarchy's levels). `metadata_head` starts the
// file's metadata (the comments follow). A mesh is read whole first (meshes_as_points), within
// the budget; its faces are not kept (a warning says so). With --features, the features are
// found part by part on the written file (chunk_features.hpp). Throws Error for a mesh too large
// for the budget, and what reading and writing throw.
ConvertResult convert_chunked(std::span<const std::string> inputs, const std::string& output,
                              const ConvertOptions& options, const std::string& metadata_head,
                              std::uint64_t max_chunk_points, ThreadPool& pool,
                              Progress& progress);

}  // namespace pointillist::chunking
