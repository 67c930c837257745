// Scans to a model file in one call: read and merge the inputs, prepare the splats (normals,
// radii, outliers), build the hierarchy and write .ptl, QSplat .qs or the prepared points as .ply.
#pragma once

#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "pointillist/core/point_set.hpp"
#include "pointillist/core/progress.hpp"
#include "pointillist/core/thread_pool.hpp"
#include "pointillist/features/features.hpp"
#include "pointillist/lod/quantization.hpp"
#include "pointillist/prep/prepare.hpp"

namespace pointillist {

class ChunkJobs;

struct ConvertOptions {
  PrepareOptions prepare;    // normals, radii, outliers
  std::string columns;       // text inputs: the column layout (empty = detected)
  bool ascii = false;        // .ply output: text instead of binary little endian
  unsigned ptl_version = 2;  // .ptl output: 2 (quantized, paged) or 1 (float nodes)
  // .ptl v2 output: how leaves keep their radius trim (sixteenths; eighths for readers older
  // than 2026-11-24). Unset: the default, allowed with any output.
  std::optional<quant::LeafTrim> leaf_trim;
  // .ptl v2 output: compute the sharp features on the hierarchy's leaves and store them.
  std::optional<FeatureOptions> features;
  // .ptl v2 output of a mesh: keep its faces (about 5 bytes a triangle) for the hybrid
  // point/polygon mode (render --lod spt --hybrid). Off: points only.
  bool keep_faces = true;
  // Bytes of memory the conversion may use; 0: half of the physical memory. Point clouds that
  // need more in one piece (about 220 bytes a point) are converted to .ptl v2 in chunks that
  // fit; other outputs and meshes that do not fit are refused before any work.
  std::uint64_t memory_budget = 0;
  // Force the chunked conversion (.ptl v2) with chunks of at most this many points (rounded down
  // to the hierarchy's levels); 0: only when the budget asks for it, in chunks of what the
  // budget holds on each thread, at most 2 M points.
  std::uint64_t chunk_points = 0;
  // The processes sharing a chunked conversion (chunk_jobs.hpp): null for this process alone.
  // With more than one, a .ptl v2 output is always converted in chunks (the same file bytes as
  // one process converting with the same options in chunks): rank 0 lays it out and finishes
  // it, every rank writes its own chunks' subtrees into it; other outputs are converted by
  // rank 0 alone.
  ChunkJobs* jobs = nullptr;
  // In one piece, touch most of the memory the conversion will need on every thread before
  // reading (prefault_heap, core/heap.hpp): for processes that keep freed memory (the CLI).
  bool prefault = false;
};

struct ConvertResult {
  std::size_t input_points = 0;   // points (vertices) read from all inputs
  std::size_t output_points = 0;  // points written (fewer when outliers were dropped)
  // Things the user should know that did not stop the work (inputs without colors, options
  // that do not apply to this output).
  std::vector<std::string> warnings;
  std::size_t chunks = 0;           // chunks of a chunked conversion (0: in one piece)
  std::uint64_t halo_points = 0;    // points copied into other chunks' halos
  // Wall time of each phase, in order (chunked: rank 0's view under MPI; in one piece: read,
  // prepare, hierarchy, write, features).
  std::vector<std::pair<std::string, double>> phase_seconds;
};

// Half of the physical memory: the default ConvertOptions::memory_budget.
std::uint64_t default_memory_budget();

// The smallest budget a conversion holds itself to: below it the program, its threads' heaps
// and its smallest buffers alone come near the budget (measured: 5 M points under 24M peaked at
// 29 MB, 1 M points under 32M at 32-33 MB; under 40M, 1 M and 5 M points and a 7 M-vertex mesh
// took 33-34 MB). `convert --memory` refuses less; the library takes smaller budgets (tests use
// them to force chunks on small inputs).
inline constexpr std::uint64_t kLeastMemoryBudget = std::uint64_t{40} << 20;

// Converts `inputs` (scans, merged in the first one's frame: see merge_inputs) to `output`,
// chosen by its extension: .ptl, .qs (a mesh gives the bytes QSplat's qsplat_make writes) or
// .ply. The output is written atomically. Throws OptionError for an unknown output extension or
// options that do not fit it, Error when an input is already a model, and what reading,
// preparing, building and writing throw.
ConvertResult convert(std::span<const std::string> inputs, const std::string& output,
                      const ConvertOptions& options, ThreadPool& pool, Progress& progress);

// The same for points made in memory (a generated model, say): prepares `points` (normals and
// radii they have are kept, see prepare_splats) and writes `output` as convert does; `sources`
// name where the points came from in the model's metadata. Throws OptionError for an unknown
// output extension or options that do not fit it, and what preparing, building and writing
// throw.
ConvertResult convert_points(PointSet points, std::span<const std::string> sources,
                             const std::string& output, const ConvertOptions& options,
                             ThreadPool& pool, Progress& progress);

}  // namespace pointillist
