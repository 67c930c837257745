// Recursive median split of a point range along the longest axis of its bounding box, the
// partition behind the QSplat hierarchy (Rusinkiewicz & Levoy, SIGGRAPH 2000, section 3.1).
// Private to the lod module.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "pointillist/core/math.hpp"
#include "pointillist/core/progress.hpp"
#include "pointillist/core/thread_pool.hpp"

namespace pointillist::lod_detail {

// Where a range of n >= 2 points splits in two: the first half has n / 2 points.
constexpr std::size_t split_half(std::size_t n) { return n / 2; }

// The order of the points after recursive median splits: the whole array is a range; a range of
// n >= 2 points splits into the split_half(n) smallest by (coordinate on the longest axis of the
// bounding box of its positions, input index), then the rest; both halves split again. Returns
// order[k] = input index of the k-th point. Ranges larger than `grain` are split by separate
// tasks on `pool`; the result is the same for any thread count. Positions must be finite and
// fewer than 2^31. Advances `progress` by one unit per point once its subtree is done. From
// `morton_labels_from` points, the partition names points by their rank along a Morton curve
// (faster on many points; the same result), computed; `morton`, when given (any permutation
// of the points gives the same result; a spatial order, the speed), is used instead from 65,536
// points.
std::vector<std::uint32_t> median_split_order(std::span<const Vec3f> positions, ThreadPool& pool,
                                              std::size_t grain, Progress& progress,
                                              std::size_t morton_labels_from,
                                              const std::vector<std::uint32_t>* morton = nullptr);

}  // namespace pointillist::lod_detail
