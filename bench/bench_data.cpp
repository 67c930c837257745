#include "bench_data.hpp"

#include "pointillist/core/model_cache.hpp"

#include <cstdlib>
#include <filesystem>
#include <map>

#include "pointillist/io/ply.hpp"
#include "pointillist/prep/prepare.hpp"
#include "pointillist/scene/analytic.hpp"

namespace pointillist::bench {

bool smoke_mode() { return std::getenv("POINTILLIST_BENCH_SMOKE") != nullptr; }

std::string dragon_path() { return cached_model_path("dragon_vrip.ply.gz"); }

const PointSet& dragon_raw() {
  static const PointSet points = [] {
    const std::string path = dragon_path();
    return path.empty() ? PointSet{} : read_ply(path);
  }();
  return points;
}

const PointSet& dragon_prepared() {
  static const PointSet points = [] {
    PointSet p = dragon_raw();
    if (p.size() > 0) {
      ThreadPool pool;
      prepare_splats(p, pool, Progress::none());
    }
    return p;
  }();
  return points;
}

const SphereTree& dragon_tree() {
  static const SphereTree tree = [] {
    ThreadPool pool;
    return dragon_prepared().size() > 0 ? build_sphere_tree(dragon_prepared(), pool)
                                        : SphereTree{};
  }();
  return tree;
}

const PointSet& generated_cloud(std::size_t count) {
  static std::map<std::size_t, PointSet> cache;
  auto it = cache.find(count);
  if (it == cache.end()) {
    it = cache.emplace(count, sample_scene(demo_scene(), count, 1).points).first;
  }
  return it->second;
}

}  // namespace pointillist::bench
