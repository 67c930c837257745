// Inputs shared by the benchmarks, built once per process outside the timed loops.
#pragma once

#include <string>

#include "pointillist/core/point_set.hpp"
#include "pointillist/lod/sphere_tree.hpp"

namespace pointillist::bench {

// True when POINTILLIST_BENCH_SMOKE is set (CTest's one tiny pass): benchmarks use small inputs.
bool smoke_mode();
// Path of the fetched dragon (.ply.gz), or "" when scripts/fetch-models.sh has not run.
std::string dragon_path();
// The dragon as read from its file (positions and faces), cached; empty when not fetched.
const PointSet& dragon_raw();
// The dragon prepared (normals, radii), and its hierarchy, cached.
const PointSet& dragon_prepared();
const SphereTree& dragon_tree();
// `count` samples of the analytic demo scene (positions only), seed 1, cached per count.
const PointSet& generated_cloud(std::size_t count);

}  // namespace pointillist::bench
