// pipeline::convert (see convert.hpp).
#include "pointillist/pipeline/convert.hpp"

#include "pointillist/core/atomic_file.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <optional>
#include <sstream>
#include <vector>

#include "pointillist/core/error.hpp"
#include "pointillist/core/heap.hpp"
#include "pointillist/format/ptl.hpp"
#include "pointillist/format/ptl_v2.hpp"
#include "pointillist/format/qs.hpp"
#include "pointillist/io/merge.hpp"
#include "pointillist/io/ply.hpp"
#include "pointillist/lod/tree_features.hpp"
#include "pointillist/io/point_file.hpp"
#include "pointillist/io/point_stream.hpp"
#include "chunked.hpp"
#include "pointillist/pipeline/chunk_jobs.hpp"
#include "pointillist/lod/sphere_tree.hpp"
#include "pointillist/pipeline/model.hpp"

namespace pointillist {
namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
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

// Throws OptionError when `output`'s extension is unknown or the options do not fit it.
void check_convert_options(const std::string& output, const ConvertOptions& o) {
  const bool to_ptl = ends_with(output, ".ptl");
  const bool to_ply = ends_with(output, ".ply");
  const bool to_qs = ends_with(output, ".qs");
  if (!to_ptl && !to_ply && !to_qs) {
    throw OptionError("convert: output '" + output +
                      "' has an unknown extension; use .ptl (Pointillist model), .qs (QSplat 1.1 "
                      "model) or .ply (points with normals and radii)");
  }
  if (o.ascii && !to_ply) throw OptionError("convert: --ascii applies only to .ply output");
  if (o.ptl_version != 1 && o.ptl_version != 2) {
    throw OptionError("convert: --ptl-version " + std::to_string(o.ptl_version) +
                      " does not exist; use 2 (compact, the default) or 1 (float nodes)");
  }
  if (o.features && !(to_ptl && o.ptl_version == 2)) {
    throw OptionError("convert: --features are stored only in .ptl version 2 output; write a .ptl "
                      "(or render the scan with --features)");
  }
  if (o.leaf_trim && !(to_ptl && o.ptl_version == 2)) {
    throw OptionError("convert: --leaf-trim applies only to .ptl version 2 output; drop it");
  }
}

// The metadata's first lines: generator, sources (a survey of hundreds of tiles names the first
// few, so the metadata stays readable in info), how normals and radii were made.
std::string metadata_head(std::span<const std::string> inputs, const ConvertOptions& o) {
  std::ostringstream meta;
  meta << "generator: pointillist " << "0.1.0" << "\n";
  constexpr std::size_t kListedSources = 5;
  for (std::size_t i = 0; i < inputs.size() && i < kListedSources; ++i) {
    meta << "source: " << inputs[i] << "\n";
  }
  if (inputs.size() > kListedSources) {
    meta << "source: ... and " << inputs.size() - kListedSources << " more files\n";
  }
  meta << "normals: " << normal_source_name(o.prepare.normals) << "\n"
       << "k: " << o.prepare.k << "\n"
       << "radius_scale: " << o.prepare.radius_scale << "\n";
  return meta.str();
}

std::string gigabytes(std::uint64_t bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f GB", double(bytes) / 1e9);
  return text;
}

}  // namespace

std::uint64_t default_memory_budget() {
  const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGE_SIZE);
  if (pages <= 0 || page <= 0) return std::uint64_t{4} << 30;
  return std::uint64_t(pages) * std::uint64_t(page) / 2;
}

ConvertResult convert(std::span<const std::string> inputs, const std::string& output,
                      const ConvertOptions& o, ThreadPool& pool, Progress& progress) {
  check_convert_options(output, o);
  check_outputs({inputs.begin(), inputs.end()}, {{"-o", output}});
  for (const std::string& path : inputs) {
    if (std::filesystem::exists(path) && is_model_file(path)) {
      throw Error(path + ": is already a splat model (" + (is_ptl_file(path) ? ".ptl" : ".qs") +
                  "); give the source scan (" + supported_point_file_extensions() +
                  ") to convert, or render the model directly");
    }
  }
  // Inputs too large for the memory budget in one piece go to .ptl v2 in chunks.
  const std::uint64_t budget = o.memory_budget ? o.memory_budget : default_memory_budget();
  // Each input's header count (binary PLY, LAS, ASCII PLY), read once: the budget's estimate
  // and the prefault below both use it.
  std::vector<std::optional<std::uint64_t>> exact;
  std::uint64_t estimate = 0;
  for (const std::string& path : inputs) {
    exact.push_back(exact_point_count(path));
    estimate += exact.back() ? *exact.back() : point_count_estimate(path);  // a bound
  }
  const bool to_v2 = ends_with(output, ".ptl") && o.ptl_version == 2;
  const std::uint64_t per_point =
      o.features ? chunking::kFeatureBytesPerPoint : chunking::kInCoreBytesPerPoint;
  const bool over = estimate > budget / per_point;
  const bool ranks = o.jobs != nullptr && o.jobs->size() > 1;
  if (to_v2 && (o.chunk_points != 0 || over || ranks)) {
    std::uint64_t most = budget / chunking::kChunkBytesPerPoint / pool.thread_count();
    // A part is found with its halo (up to as many points again) and the process around it.
    if (o.features) most = std::min(most, budget / (3 * chunking::kFeatureBytesPerPoint));
    const std::uint64_t chunk_points =
        o.chunk_points ? o.chunk_points
                       : std::clamp<std::uint64_t>(most, 1024, chunking::kMaxChunkPoints);
    return chunking::convert_chunked(inputs, output, o, metadata_head(inputs, o), chunk_points,
                                     pool, progress);
  }
  if (over) {
    throw Error("convert: the inputs hold up to " + std::to_string(estimate) +
                " points, which need about " +
                gigabytes(estimate * per_point) +
                " of memory in one piece, over the budget of " + gigabytes(budget) +
                "; write a .ptl (converted in chunks within the budget), or raise --memory");
  }
  if (ranks && o.jobs->rank() != 0) return {};  // rank 0 converts other outputs alone
  std::vector<std::string> warnings;
  const auto start = std::chrono::steady_clock::now();
  // Measured for model outputs (a .ply output needs little beyond what reading fills).
  const bool prefault = o.prefault && (ends_with(output, ".ptl") || ends_with(output, ".qs"));
  if (prefault) {
    // Reading fills arrays about the size of a binary input (PLY or LAS), at most ~40 bytes a
    // point with faces (an ASCII or gzip file's size says less): touch that much first, so
    // that it is not faulted in on the one reading thread.
    std::uint64_t bytes = 0;
    for (std::size_t i = 0; i < inputs.size(); ++i) {
      if (exact[i]) {
        bytes += std::min<std::uint64_t>(std::filesystem::file_size(inputs[i]), *exact[i] * 40);
      }
    }
    prefault_heap(std::min(bytes, budget / 4), pool);
  }
  PointSet points = merge_inputs(inputs, pool, progress, {.columns = o.columns}, &warnings);
  const double read_seconds = seconds_since(start);
  if (prefault) {
    // What the hierarchy and the encoder will need beyond the points just read, below every
    // measured in-one-piece peak (141-171 bytes a point in all, of which reading holds 36-50;
    // a mesh whose faces are kept, 180), counted only for inputs whose headers give the count
    // (binary PLY, LAS). Touched after reading, when the input file is no longer mapped, so
    // the peak does not hold both. Measured (same sitting, 2026-11-28): raising 90 to 115
    // bytes a point left the peaks of a 5 M cloud and a 7 M mesh without faces unchanged and
    // took 0.97x and 0.94x the wall time; 140 for the mesh with faces, 0.91x; more raised
    // the peaks.
    const bool faces_kept = points.is_mesh() && o.keep_faces && ends_with(output, ".ptl");
    const std::uint64_t prefault_per_point = faces_kept ? 140 : 115;
    std::uint64_t known = 0;
    for (const auto& count : exact) known += count.value_or(0);
    prefault_heap(std::min(known * prefault_per_point, budget / 2), pool);
  }
  const double memory_seconds = seconds_since(start) - read_seconds;
  ConvertResult result = convert_points(std::move(points), inputs, output, o, pool, progress);
  if (prefault) {
    result.phase_seconds.insert(result.phase_seconds.begin(), {"memory", memory_seconds});
  }
  result.phase_seconds.insert(result.phase_seconds.begin(), {"read", read_seconds});
  warnings.insert(warnings.end(), result.warnings.begin(), result.warnings.end());
  result.warnings = std::move(warnings);
  return result;
}

ConvertResult convert_points(PointSet points, std::span<const std::string> inputs,
                             const std::string& output, const ConvertOptions& o, ThreadPool& pool,
                             Progress& progress) {
  check_convert_options(output, o);
  const bool to_ptl = ends_with(output, ".ptl");
  const bool to_qs = ends_with(output, ".qs");
  ConvertResult result;
  result.input_points = points.size();
  auto phase_start = std::chrono::steady_clock::now();
  const auto phase_done = [&](const char* name) {
    result.phase_seconds.emplace_back(name, seconds_since(phase_start));
    phase_start = std::chrono::steady_clock::now();
  };
  // The Morton order of a cloud's neighbour search, which the hierarchy reuses.
  std::vector<std::uint32_t> morton;
  // A mesh goes to write_qs as read: like qsplat_make, it computes normals and radii from the
  // faces itself (that is what makes the file byte-identical to the original tool's).
  if (!(to_qs && points.is_mesh())) {
    PrepareOptions prepare = o.prepare;
    if (to_ptl) prepare.morton_order = &morton;
    prepare_splats(points, pool, progress, prepare);
    phase_done("prepare");
  } else if (o.prepare.normals != NormalSource::Auto || o.prepare.radius_scale != 1.0f ||
             o.prepare.k != PrepareOptions{}.k || o.prepare.drop_outliers) {
    result.warnings.push_back(
        "--normals, --k, --radius-scale and --drop-outliers are ignored for .qs output of a "
        "mesh: its normals and radii follow qsplat_make's rules, which make the file "
        "byte-identical to QSplat's (convert to .ply first to apply them)");
  }
  result.output_points = points.size();

  if (to_qs) {
    ProgressPhase phase(progress, "write", 0);
    write_qs(output, points, {.write_colors = points.has_colors()});
    phase_done("write");
  } else if (to_ptl) {
    // The faces have given their normals and radii; the points, once in the tree, are no longer
    // needed. Freed early, their memory is reused by the next phase instead of fresh pages
    // (each first touch costs; the dragon's faces alone are 10 MB).
    // .ptl v2 keeps them for the hybrid point/polygon mode (--no-faces drops them), moved out
    // first and put on the leaves once the tree is built.
    const bool keep_faces = o.keep_faces && o.ptl_version == 2 && points.is_mesh();
    std::vector<std::array<std::uint32_t, 3>> faces = std::move(points.triangles);
    points.triangles = {};
    if (!keep_faces) faces = {};
    std::vector<std::uint32_t> split_order;
    SphereTreeOptions tree_options;
    tree_options.morton_order = &morton;
    const SphereTree tree = build_sphere_tree(points, pool, progress, tree_options,
                                              keep_faces ? &split_order : nullptr);
    morton = {};
    if (keep_faces) faces = leaf_triangles(tree.view(), split_order, faces);
    split_order = {};
    phase_done("hierarchy");
    std::ostringstream meta;
    meta << metadata_head(inputs, o);
    for (const auto& c : points.comments) meta << "comment: " << c << "\n";
    points = {};
    ProgressPhase phase(progress, "write", 0);
    if (o.ptl_version == 1) {
      write_ptl(output, tree, meta.str());
      phase_done("write");
    } else {
      PtlV2WriteOptions v2;
      if (o.leaf_trim) v2.leaf_trim = *o.leaf_trim;
      v2.triangles = faces;
      if (keep_faces) meta << "faces: " << faces.size() << " triangles kept (render --hybrid)\n";
      write_ptl_v2(output, tree, meta.str(), v2, pool);
      phase_done("write");
      if (o.features) {
        // Features of the splats as the file stores them (quantized centres and normals,
        // enlarged radii), which is what the renderer draws: found on the written file's
        // decoded leaves, then written with it.
        const SphereTree decoded = PtlV2File::open(output)->decode_all();
        const TreeFeatures features = compute_tree_features(
            decoded.view(), pool, for_quantized_model(*o.features), progress);
        const std::string noisy = noisy_features_warning(features.stats, features.options);
        if (!noisy.empty()) result.warnings.push_back("--features: " + noisy);
        meta << "features: sharp threshold " << features.options.sharp_threshold << ", "
             << features.stats.clipped << " clipped splats, " << features.stats.segments
             << " surfaces\n";
        v2.features = &features;
        write_ptl_v2(output, tree, meta.str(), v2, pool);
        phase_done("features");
      }
    }
  } else {
    ProgressPhase phase(progress, "write", 0);
    write_ply(output, points,
              {.encoding = o.ascii ? PlyEncoding::Ascii : PlyEncoding::BinaryLittleEndian});
    phase_done("write");
  }
  return result;
}

}  // namespace pointillist
