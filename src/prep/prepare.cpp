// The preparation stage: drop unused mesh vertices, then normals and radii from the best source.
#include "pointillist/prep/prepare.hpp"

#include <cmath>
#include <sstream>

#include "pointillist/core/error.hpp"
#include "pointillist/prep/normals.hpp"
#include "pointillist/prep/outliers.hpp"
#include "ordered_cloud.hpp"

namespace pointillist {
namespace {

constexpr std::size_t kGrain = 1 << 15;

void check_options(const PrepareOptions& o) {
  if (o.k < 3) {
    throw OptionError("prepare: k = " + std::to_string(o.k) +
                      " neighbours cannot define a plane; use k >= 3 (16 is typical)");
  }
  if (!(o.radius_scale > 0.0f) || !std::isfinite(o.radius_scale)) {
    throw OptionError("prepare: radius scale " + std::to_string(o.radius_scale) +
                      " must be a positive number (1 keeps the computed radii)");
  }
  if (!(o.outlier_ratio_drop > 1.0f) || !std::isfinite(o.outlier_ratio_drop)) {
    throw OptionError("prepare: outlier ratio " + std::to_string(o.outlier_ratio_drop) +
                      " is invalid; give a number above 1 (3 is usual)");
  }
  if (!(o.coverage > 0.0f) || !std::isfinite(o.coverage)) {
    throw OptionError("prepare: coverage " + std::to_string(o.coverage) +
                      " must be a positive number (default " +
                      std::to_string(kDefaultCloudCoverage) + ")");
  }
}

void check_points(const PointSet& p, const std::string& name) {
  const std::size_t n = p.size();
  if (n == 0) {
    throw Error(name +
                ": has no points (0 vertices); check that the file holds a vertex "
                "element with x, y, z");
  }
  const auto check_size = [&](std::size_t size, const char* what) {
    if (size != 0 && size != n) {
      throw Error(name + ": " + std::to_string(size) + " " + what + " for " + std::to_string(n) +
                  " points; every attribute needs one value per point");
    }
  };
  check_size(p.normals.size(), "normals");
  check_size(p.colors.size(), "colors");
  check_size(p.radii.size(), "radii");
  for (std::size_t i = 0; i < n; ++i) {
    if (!is_finite(p.positions[i])) {
      std::ostringstream s;
      s << name << ": vertex " << i << " has a non-finite position (" << p.positions[i].x << ", "
        << p.positions[i].y << ", " << p.positions[i].z << "); remove it from the file";
      throw Error(s.str());
    }
  }
  for (std::size_t f = 0; f < p.triangles.size(); ++f) {
    for (const std::uint32_t v : p.triangles[f]) {
      if (v >= n) {
        throw Error(name + ": face " + std::to_string(f) + " refers to vertex " +
                    std::to_string(v) + ", but there are only " + std::to_string(n) +
                    " vertices; the file is damaged");
      }
    }
  }
}

// QSplat drops vertices that no face uses: they are usually scanner noise or leftovers of
// editing, and mesh radii are undefined for them.
void drop_unreferenced_vertices(PointSet& p) {
  std::vector<std::uint8_t> used(p.size(), 0);
  for (const auto& t : p.triangles) {
    for (const std::uint32_t v : t) used[v] = 1;
  }
  keep_points(p, used);
}

void normalize_in_place(std::vector<Vec3f>& normals, ThreadPool& pool) {
  parallel_for(pool, normals.size(), kGrain, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) normals[i] = normalized(normals[i], {0, 0, 1});
  });
}

}  // namespace

void prepare_splats(PointSet& points, ThreadPool& pool, Progress& progress,
                    const PrepareOptions& options) {
  check_options(options);
  const std::string& name = options.input_name;
  check_points(points, name);
  if (points.is_mesh()) drop_unreferenced_vertices(points);
  if (options.drop_outliers) {
    if (points.is_mesh()) {
      throw OptionError(name + " is a mesh: outlier removal applies to point clouds (a mesh's "
                        "faces define its surface; drop the option)");
    }
    remove_outliers(points, pool, progress, {.ratio = options.outlier_ratio_drop});
  }
  const std::size_t n = points.size();

  NormalSource source = options.normals;
  if (source == NormalSource::Auto) {
    source = points.has_normals() ? NormalSource::Keep
             : points.is_mesh()   ? NormalSource::Mesh
                                  : NormalSource::Pca;
  }
  if (source == NormalSource::Keep && !points.has_normals()) {
    throw Error("--normals keep: " + name +
                " has no normals (no nx/ny/nz vertex properties); use --normals auto or pca");
  }
  if (source == NormalSource::Mesh && !points.is_mesh()) {
    throw Error("--normals mesh: " + name +
                " has no faces, so there are no mesh normals; use --normals auto or pca");
  }
  if (source == NormalSource::Pca && n < 3) {
    throw Error(name + ": " + std::to_string(n) +
                " points are too few to estimate normals by PCA (at least 3 are needed); give "
                "normals in the file (nx, ny, nz) or faces");
  }
  const bool want_pca = source == NormalSource::Pca;
  const bool want_cloud_radii = !points.has_radii() && !points.is_mesh();

  // PCA normals and cloud radii share one neighbour search over the Morton-ordered cloud.
  constexpr std::uint32_t kRadiusNeighbours = CloudRadiusOptions{}.neighbours;
  prep_detail::OrderedCloud cloud;
  if (want_pca || want_cloud_radii) {
    const std::uint32_t k =
        std::max(want_pca ? options.k - 1 : 0u,
                 want_cloud_radii
                     ? (options.outlier_ratio > 0 ? std::max(kRadiusNeighbours, kOutlierNeighbours)
                                                  : kRadiusNeighbours)
                     : 0u);
    cloud = prep_detail::order_cloud(points.positions, k, pool, progress);
  }

  if (want_pca) {
    std::vector<Vec3f> normals = prep_detail::pca_normals_ordered(cloud, options.k, pool, progress);
    std::vector<std::uint32_t> components;
    prep_detail::orient_normals_ordered(
        cloud, prep_detail::orientation_graph_k(options.k), normals, pool, progress,
        options.orientation_centre ? &*options.orientation_centre : nullptr,
        options.orientation_components ? &components : nullptr);
    points.normals = prep_detail::to_caller_order<Vec3f>(cloud, normals, pool);
    if (options.orientation_components) {
      *options.orientation_components =
          prep_detail::to_caller_order<std::uint32_t>(cloud, components, pool);
    }
  } else {
    ProgressPhase phase(progress, "normals", n);
    if (source == NormalSource::Mesh) {
      points.normals = mesh_vertex_normals(points.positions, points.triangles, pool);
    } else {
      normalize_in_place(points.normals, pool);
    }
    phase.advance(n);
  }

  if (want_cloud_radii) {
    const std::vector<float> radii = prep_detail::cloud_radii_ordered(
        cloud, kRadiusNeighbours, options.coverage * options.radius_scale, options.outlier_ratio,
        pool, progress);
    points.radii = prep_detail::to_caller_order<float>(cloud, radii, pool);
  } else {
    ProgressPhase phase(progress, "radii", n);
    if (points.has_radii()) {
      const float scale = options.radius_scale;
      parallel_for(pool, n, kGrain, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i) points.radii[i] *= scale;
      });
    } else {
      points.radii = mesh_radii(points.positions, points.triangles, options.radius_scale, pool);
    }
    phase.advance(n);
  }
  // The neighbour search's order, when one ran.
  if (options.morton_order && !cloud.order.empty()) *options.morton_order = std::move(cloud.order);
}

void prepare_mesh_vertices(PointSet& mesh, ThreadPool& pool, Progress& progress,
                           const PrepareOptions& options) {
  check_options(options);
  const std::string& name = options.input_name;
  check_points(mesh, name);
  if (!mesh.is_mesh()) return;
  if (options.drop_outliers) {
    throw OptionError(name + " is a mesh: outlier removal applies to point clouds (a mesh's "
                      "faces define its surface; drop the option)");
  }
  drop_unreferenced_vertices(mesh);
  const NormalSource source = options.normals;
  if (source == NormalSource::Keep && !mesh.has_normals()) {
    throw Error("--normals keep: " + name +
                " has no normals (no nx/ny/nz vertex properties); use --normals auto or pca");
  }
  {
    ProgressPhase phase(progress, "normals", mesh.size());
    if (source == NormalSource::Pca) {
      mesh.normals.clear();
    } else if (source == NormalSource::Mesh ||
               (source == NormalSource::Auto && !mesh.has_normals())) {
      mesh.normals = mesh_vertex_normals(mesh.positions, mesh.triangles, pool);
    }
    phase.advance(mesh.size());
  }
  if (!mesh.has_radii()) {
    ProgressPhase phase(progress, "radii", mesh.size());
    mesh.radii = mesh_radii(mesh.positions, mesh.triangles, 1.0f, pool);
    phase.advance(mesh.size());
  }
  mesh.triangles.clear();
  mesh.triangles.shrink_to_fit();
}

}  // namespace pointillist
