#include <chrono>
#include <cstdio>
#include <filesystem>
#include <sstream>

#include "commands.hpp"
#include "model_loading.hpp"
#include "terminal_progress.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/format/ptl.hpp"
#include "pointillist/format/ptl_v2.hpp"
#include "pointillist/format/qs.hpp"
#include "pointillist/io/ply.hpp"
#include "pointillist/lod/sphere_tree.hpp"

namespace pointillist::cli {

namespace {

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

const char* normal_source_name(NormalSource s) {
  switch (s) {
    case NormalSource::Auto: return "auto";
    case NormalSource::Keep: return "keep";
    case NormalSource::Mesh: return "mesh";
    case NormalSource::Pca: return "pca";
  }
  return "?";
}

}  // namespace

int run_convert(const ConvertOptions& o) {
  const bool to_ptl = ends_with(o.output, ".ptl");
  const bool to_ply = ends_with(o.output, ".ply");
  const bool to_qs = ends_with(o.output, ".qs");
  if (!to_ptl && !to_ply && !to_qs) {
    throw OptionError("convert: output '" + o.output +
                      "' has an unknown extension; use .ptl (Pointillist model), .qs (QSplat 1.1 "
                      "model) or .ply (points with normals and radii)");
  }
  if (o.ascii && !to_ply) throw OptionError("convert: --ascii applies only to .ply output");
  if (o.ptl_version != 1 && o.ptl_version != 2) {
    throw OptionError("convert: --ptl-version " + std::to_string(o.ptl_version) +
                      " does not exist; use 2 (compact, the default) or 1 (float nodes)");
  }
  if (o.leaf_trim && !(to_ptl && o.ptl_version == 2)) {
    throw OptionError("convert: --leaf-trim applies only to .ptl version 2 output; drop it");
  }
  const auto start = std::chrono::steady_clock::now();
  ThreadPool pool(o.threads);
  TerminalProgress progress(!o.quiet && TerminalProgress::stderr_is_terminal());

  std::vector<std::string> warnings;
  PointSet points = read_inputs(o.inputs, pool, progress, o.columns, &warnings);
  for (const auto& w : warnings) std::fprintf(stderr, "pointillist convert: warning: %s\n", w.c_str());
  const std::size_t point_count = points.size();
  // A mesh goes to write_qs as read: like qsplat_make, it computes normals and radii from the
  // faces itself (that is what makes the file byte-identical to the original tool's).
  if (!(to_qs && points.is_mesh())) {
    prepare_splats(points, pool, progress, o.prepare);
    if (o.prepare.drop_outliers && !o.quiet) {
      std::printf("dropped %zu outliers of %zu points\n", point_count - points.size(), point_count);
    }
  } else if (o.prepare.normals != NormalSource::Auto || o.prepare.radius_scale != 1.0f ||
             o.prepare.k != PrepareOptions{}.k || o.prepare.drop_outliers) {
    std::fprintf(stderr,
                 "pointillist convert: warning: --normals, --k, --radius-scale and "
                 "--drop-outliers are ignored for "
                 ".qs output of a mesh: its normals and radii follow qsplat_make's rules, which "
                 "make the file byte-identical to QSplat's (convert to .ply first to apply them)\n");
  }

  if (to_qs) {
    ProgressPhase phase(progress, "write", 0);
    write_qs(o.output, points, {.write_colors = points.has_colors()});
  } else if (to_ptl) {
    const SphereTree tree = build_sphere_tree(points, pool, progress);
    std::ostringstream meta;
    meta << "generator: pointillist " << "0.1.0" << "\n";
    for (const auto& in : o.inputs) meta << "source: " << in << "\n";
    meta << "normals: " << normal_source_name(o.prepare.normals) << "\n"
         << "k: " << o.prepare.k << "\n"
         << "radius_scale: " << o.prepare.radius_scale << "\n";
    for (const auto& c : points.comments) meta << "comment: " << c << "\n";
    ProgressPhase phase(progress, "write", 0);
    if (o.ptl_version == 1) {
      write_ptl(o.output, tree, meta.str());
    } else {
      PtlV2WriteOptions v2;
      if (o.leaf_trim) v2.leaf_trim = *o.leaf_trim;
      write_ptl_v2(o.output, tree, meta.str(), v2, pool);
    }
  } else {
    ProgressPhase phase(progress, "write", 0);
    write_ply(o.output, points,
              {.encoding = o.ascii ? PlyEncoding::Ascii : PlyEncoding::BinaryLittleEndian});
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!o.quiet) {
    const double size = double(std::filesystem::file_size(o.output));
    std::printf("converted %zu points in %.2f s (%.2f M points/s) -> %s, %s, %.1f bytes/point\n",
                point_count, seconds, point_count / seconds / 1e6, o.output.c_str(),
                human_bytes(size).c_str(), point_count ? size / double(point_count) : 0.0);
  }
  return 0;
}

}  // namespace pointillist::cli
