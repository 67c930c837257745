// The chunked conversion (see convert.hpp, ConvertOptions::memory_budget): scans larger than the
// memory budget become a .ptl v2 file chunk by chunk.
//   1. scan: the inputs are streamed once for their positions (12 bytes a point, in memory or,
//      when the budget cannot hold them, in a file) and centroid;
//   2. plan: the top binary levels of the hierarchy's median splits cut the points into chunks
//      that are exactly subtrees of the one-piece hierarchy (chunk_plan.hpp; out of core by
//      radix selection when the positions are on disk);
//   3. distribute: the inputs are streamed again into one file per chunk, with a halo: the
//      points of other chunks near its box, so normals and radii see across its border;
//   4. prepare: each chunk (and its halo) gets normals and radii, loses its halo, becomes its
//      subtree, is summarized and kept on disk as its splats in split order;
//   5. write: a PtlV2PartWriter lays out the file over the summaries; each chunk's subtree is
//      rebuilt from its splats (no partition: they are in split order) and written in place.
// Everything goes to a folder beside the output, removed at the end and on failure; the output
// appears only when complete.
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstring>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <mutex>
#include <optional>
#include <set>
#include <sstream>

#include "chunk_files.hpp"
#include "chunk_orientation.hpp"
#include "chunk_plan.hpp"
#include "chunked.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/format/ptl_v2.hpp"
#include "pointillist/io/point_stream.hpp"
#include "pointillist/lod/sphere_tree.hpp"
#include "pointillist/prep/prepare.hpp"

namespace pointillist::chunking {
namespace {

constexpr Rgb8 kMissingColor{180, 180, 180};  // as merge_inputs gives parts without colours
constexpr std::size_t kBatch = 1 << 20;      // points per read

// The inputs as one stream, with merge_inputs' rules: parts move into the first part's frame,
// normals and radii survive when every part has them, colours when any has them (grey else).
class MergedInputs {
 public:
  MergedInputs(std::span<const std::string> paths, const std::string& columns) {
    for (const std::string& path : paths) {
      streams_.push_back(open_point_stream(path, {.columns = columns}));
      const PointStreamInfo& info = streams_.back()->info();
      if (info.is_mesh) {
        throw Error(path + ": is a mesh; meshes are converted in one piece (give a larger "
                           "--memory, or convert its vertices as points)");
      }
      count_ += info.point_count;
      normals_ = normals_ && info.has_normals;
      radii_ = radii_ && info.has_radii;
      colors_ = colors_ || info.has_colors;
      for (const std::string& c : info.comments) {
        if (paths.size() == 1 || seen_.insert(c).second) comments_.push_back(c);
      }
    }
    origin_ = streams_[0]->info().origin;
    up_ = streams_[0]->info().up;
  }

  // As merge_inputs warns: files without colours among files with them are drawn grey.
  std::optional<std::string> colour_warning() const {
    std::vector<std::string> without;
    for (const auto& s : streams_) {
      if (!s->info().has_colors) without.push_back(s->info().path);
    }
    if (!colors_ || without.empty()) return std::nullopt;
    std::string list;
    for (std::size_t i = 0; i < without.size() && i < 5; ++i) list += (i ? ", " : "") + without[i];
    if (without.size() > 5) list += ", ...";
    return std::to_string(without.size()) + " of " + std::to_string(streams_.size()) +
           " input files have no colors; their points are grey (" + list + ")";
  }

  std::uint64_t count() const { return count_; }
  bool has_normals() const { return normals_; }
  bool has_radii() const { return radii_; }
  bool has_colors() const { return colors_; }
  const std::array<double, 3>& origin() const { return origin_; }
  Vec3f up() const { return up_; }
  const std::vector<std::string>& comments() const { return comments_; }
  const std::vector<std::unique_ptr<PointStream>>& streams() const { return streams_; }
  // After a full pass: a part whose normals were all unusable has none (as read_point_file).
  void drop_unusable_normals() {
    for (const auto& s : streams_) normals_ = normals_ && s->saw_usable_normals();
  }

  // Calls fn(batch, index of its first point) over every point, in order; tells `progress`
  // which file it reads when there are several.
  template <class Fn>
  void for_each_batch(Progress& progress, Fn&& fn) {
    std::uint64_t next = 0;
    PointSet batch;
    for (std::size_t k = 0; k < streams_.size(); ++k) {
      const auto& stream = streams_[k];
      if (streams_.size() > 1) {
        const std::string& path = stream->info().path;
        const std::size_t slash = path.find_last_of('/');
        progress.detail(path.substr(slash == std::string::npos ? 0 : slash + 1) + " (" +
                        std::to_string(k + 1) + "/" + std::to_string(streams_.size()) + ")");
      }
      stream->rewind();
      const std::array<double, 3>& o = stream->info().origin;
      const double shift[3] = {o[0] - origin_[0], o[1] - origin_[1], o[2] - origin_[2]};
      const bool shifted = shift[0] != 0 || shift[1] != 0 || shift[2] != 0;
      while (const std::size_t n = stream->read(batch, kBatch)) {
        if (shifted) {
          for (Vec3f& p : batch.positions) {
            p = {float(p.x + shift[0]), float(p.y + shift[1]), float(p.z + shift[2])};
          }
        }
        if (!normals_) batch.normals.clear();
        if (!radii_) batch.radii.clear();
        if (colors_ && batch.colors.empty()) batch.colors.assign(n, kMissingColor);
        fn(batch, next);
        next += n;
      }
    }
  }

 private:
  std::vector<std::unique_ptr<PointStream>> streams_;
  std::uint64_t count_ = 0;
  bool normals_ = true, radii_ = true, colors_ = false;
  std::array<double, 3> origin_{};
  Vec3f up_{0, 1, 0};
  std::vector<std::string> comments_;
  std::set<std::string> seen_;
};

// Binary levels of the plan: enough chunks for `max_points` each, paired as the hierarchy's
// levels pair (sphere_tree_root_halves), at least one level.
std::uint32_t plan_levels(std::uint64_t n, std::uint64_t max_points) {
  std::uint32_t levels = 1;
  while ((n >> levels) > max_points && levels < 20) ++levels;
  const bool odd = sphere_tree_root_halves(n);
  if ((levels % 2 == 1) != odd) ++levels;
  while (levels > 1 && (n >> levels) < 2) levels -= 2;
  return levels;
}

// The phases of a chunked conversion, each with its share of the whole job's time (estimates
// from the profile of a 10 M-point run, where preparing the chunks, their neighbours, normals
// and radii, is most of it), as one overall figure in points: phase names and totals go to
// `inner` as they are.
class OverallProgress final : public Progress {
 public:
  OverallProgress(Progress& inner, std::uint64_t points) : inner_(inner), points_(points) {}
  void begin_phase(std::string_view name, std::uint64_t total) override {
    inner_.begin_phase(name, total);
    phase_ = kPhases.size();
    for (std::size_t i = 0; i < kPhases.size(); ++i) {
      if (name == kPhases[i].name) phase_ = i;
    }
    total_ = total;
    done_ = 0;
    report();
  }
  void advance(std::uint64_t units) override {
    inner_.advance(units);
    done_ += units;
    report();
  }
  void end_phase() override {
    if (phase_ < kPhases.size()) finished_ += kPhases[phase_].share;
    phase_ = kPhases.size();
    inner_.end_phase();
    report();
  }
  void detail(std::string_view text) override { inner_.detail(text); }

 private:
  struct Phase {
    std::string_view name;
    double share;
  };
  static constexpr std::array<Phase, 7> kPhases = {{{"scan", 0.03},
                                                    {"plan", 0.03},
                                                    {"distribute", 0.05},
                                                    {"prepare", 0.55},
                                                    {"orientation", 0.02},
                                                    {"hierarchy", 0.12},
                                                    {"write", 0.20}}};
  void report() {
    double f = finished_;
    if (phase_ < kPhases.size() && total_ > 0) {
      f += kPhases[phase_].share * std::min(1.0, double(done_.load()) / double(total_));
    }
    inner_.overall(std::uint64_t(std::min(1.0, f) * double(points_)), points_);
  }
  Progress& inner_;
  std::uint64_t points_;
  std::size_t phase_ = kPhases.size();
  std::uint64_t total_ = 0;
  std::atomic<std::uint64_t> done_{0};
  double finished_ = 0;
};

// Calls fn(chunk, pool) for every chunk, `workers` chunks at a time, each worker with a pool of
// its own (one thread): the serial parts of preparing a chunk (its orientation tree) then
// overlap. Results go to per-chunk slots, so they do not depend on the worker count.
void for_each_chunk(std::size_t chunks, ThreadPool& pool,
                    const std::function<void(std::size_t, ThreadPool&)>& fn) {
  const std::size_t workers = std::min<std::size_t>(pool.thread_count(), chunks);
  if (workers <= 1) {
    for (std::size_t c = 0; c < chunks; ++c) fn(c, pool);
    return;
  }
  std::vector<std::unique_ptr<ThreadPool>> pools;
  for (std::size_t w = 0; w < workers; ++w) pools.push_back(std::make_unique<ThreadPool>(1));
  std::atomic<std::size_t> next{0};
  pool.run(workers, [&](std::size_t w) {
    for (std::size_t c; (c = next.fetch_add(1)) < chunks;) fn(c, *pools[w]);
  });
}

}  // namespace

ConvertResult convert_chunked(std::span<const std::string> inputs, const std::string& output,
                              const ConvertOptions& o, const std::string& metadata_head,
                              std::uint64_t max_chunk_points, ThreadPool& pool,
                              Progress& outer_progress) {
  if (o.prepare.drop_outliers) {
    throw OptionError("convert: --drop-outliers is not available for chunked conversion yet (the "
                      "input needs more than --memory); give a larger --memory, or drop the "
                      "outliers first (convert to .ply with --drop-outliers, in parts)");
  }
  if (o.features) {
    throw OptionError("convert: --features are not available for chunked conversion yet (the "
                      "input needs more than --memory); give a larger --memory");
  }
  MergedInputs in(inputs, o.columns);
  const std::uint64_t n = in.count();
  OverallProgress overall(outer_progress, n);
  Progress& progress = overall;
  ConvertResult result;
  result.input_points = n;
  if (const auto warning = in.colour_warning()) result.warnings.push_back(*warning);

  // The plan holds every position in memory when the budget allows, else it works from a file
  // of them.
  const std::uint64_t budget = o.memory_budget ? o.memory_budget : default_memory_budget();
  const bool plan_on_disk = n * kPlanBytesPerPoint > budget;
  const std::uint32_t levels = plan_levels(n, std::max<std::uint64_t>(max_chunk_points, 2));

  // The folder, once the disk is known to hold the conversion's files at their peak: the
  // positions (for a plan on disk), then the chunk files (each point once, plus its halo
  // copies), which become the prepared splats (43 bytes each), then the splats in split order
  // (31 bytes) as the output is written.
  WorkFolder folder(output);
  const RecordLayout layout{in.has_normals(), in.has_radii()};
  {
    const double halo_share = 0.1;  // a generous bound: chunks of 1 M points have about 2 %
    const double per_point = std::max({plan_on_disk ? 12.0 : 0.0,
                                       double(layout.size()) * (1 + halo_share), 43.0, 31.0 + 12});
    const auto need = std::uint64_t(double(n) * per_point + double(max_chunk_points) * 43);
    std::error_code error;
    const std::filesystem::space_info space =
        std::filesystem::space(std::filesystem::path(folder.file("")).parent_path(), error);
    if (!error && space.available < need) {
      throw IoError(folder.file("") + ": the chunked conversion needs about " +
                    std::to_string(need / 1000000) + " MB of free disk beside the output, " +
                    std::to_string(space.available / 1000000) +
                    " MB are free; free some space or write the output to another disk");
    }
  }

  // 1. Positions, their box and centroid.
  std::vector<Vec3f> positions;
  std::optional<ChunkFiles> position_file;
  if (plan_on_disk) {
    position_file.emplace(folder, 1, "positions", std::size_t{1} << 22);
  } else {
    positions.reserve(n);
  }
  double sum[3] = {0, 0, 0};
  Aabb box;
  {
    ProgressPhase phase(progress, "scan", n);
    std::uint64_t seen = 0;
    in.for_each_batch(progress, [&](const PointSet& b, std::uint64_t) {
      for (const Vec3f& p : b.positions) {
        if (!is_finite(p)) {
          throw Error(std::string(inputs.size() == 1 ? inputs[0] : "the inputs") +
                      ": vertex " + std::to_string(seen) +
                      " has a non-finite position; remove it from the file");
        }
        ++seen;
        if (plan_on_disk) {
          position_file->append(0, &p, sizeof p);
        } else {
          positions.push_back(p);
        }
        box.extend(p);
        sum[0] += p.x;
        sum[1] += p.y;
        sum[2] += p.z;
      }
      phase.advance(b.size());
    });
    if (position_file) position_file->flush_all();
  }
  in.drop_unusable_normals();
  const Vec3f centroid{float(sum[0] / double(n)), float(sum[1] / double(n)),
                       float(sum[2] / double(n))};

  // 2. The plan.
  ChunkPlan plan;
  {
    ProgressPhase phase(progress, "plan", n);
    if (plan_on_disk) {
      const std::string path = folder.file(ChunkFiles::name("positions", 0));
      // A quarter of the budget for the selections' candidates (32 bytes each).
      const std::size_t candidates = std::max<std::uint64_t>(budget / 4 / 32, 1024);
      plan = plan_chunks_on_disk(path, n, box, levels, candidates, pool, progress);
      std::filesystem::remove(path);
    } else {
      plan = plan_chunks(positions, levels, pool);
      phase.advance(n);
    }
  }
  std::vector<Vec3f>().swap(positions);
  const std::size_t chunks = plan.chunk_count();
  result.chunks = chunks;
  // Halo reach: a multiple of the chunk's point spacing (its box's two largest extents over its
  // point count, as for a surface), scaled with the neighbourhood size.
  std::vector<float> reach(chunks);
  float max_reach = 0;
  const float neighbourhood = std::sqrt(std::max(16.0f, float(o.prepare.k)) / 16.0f);
  for (std::size_t c = 0; c < chunks; ++c) {
    const Vec3f e = plan.boxes[c].hi - plan.boxes[c].lo;
    float x[3] = {e.x, e.y, e.z};
    std::sort(x, x + 3);
    const float spacing = std::sqrt(x[2] * x[1] / float(std::max<std::uint64_t>(plan.counts[c], 1)));
    reach[c] = kHaloSpacings * spacing * neighbourhood;
    max_reach = std::max(max_reach, reach[c]);
  }

  // 3. Distribute.
  const std::size_t buffer_bytes =
      std::clamp<std::size_t>((std::size_t{256} << 20) / chunks, 4096, 1 << 20);
  {
    ChunkFiles files(folder, chunks, "chunk", buffer_bytes);
    ProgressPhase phase(progress, "distribute", n);
    std::vector<char> record(layout.size());
    in.for_each_batch(progress, [&](const PointSet& b, std::uint64_t first) {
      for (std::size_t i = 0; i < b.size(); ++i) {
        const Vec3f& p = b.positions[i];
        const std::uint32_t own = plan.chunk_of(p, first + i);
        encode_record(layout, b, i, first + i, false, record.data());
        files.append(own, record.data(), record.size());
        record[15] = 1;
        plan.for_near_chunks(p, own, reach, max_reach, [&](std::uint32_t c) {
          files.append(c, record.data(), record.size());
          ++result.halo_points;
        });
      }
      phase.advance(b.size());
    });
    files.flush_all();
  }

  // 4. Prepare each chunk with its halo; keep its own splats, their input indices and
  // orientation pieces; tell each halo point's owner how this chunk oriented it.
  const bool colors = in.has_colors();
  OrientationStitcher stitcher;
  std::vector<std::uint64_t> own_count(chunks, 0);
  std::vector<std::vector<double>> votes(chunks);
  std::atomic<bool> pieces{false};
  {
    ChunkFiles relations(folder, chunks, "relations", buffer_bytes);
    std::mutex relations_mutex;
    ProgressPhase phase(progress, "prepare", n);
    for_each_chunk(chunks, pool, [&](std::size_t c, ThreadPool& chunk_pool) {
      const std::string path = folder.file(ChunkFiles::name("chunk", c));
      std::vector<std::uint8_t> own;
      Splats s;
      s.points = read_chunk(path, layout, colors, own, s.index);
      std::filesystem::remove(path);
      PrepareOptions prepare = o.prepare;
      prepare.orientation_centre = centroid;
      prepare.input_name = inputs.size() == 1 ? inputs[0] : "the inputs";
      prepare.orientation_components = &s.piece;
      prepare_splats(s.points, chunk_pool, Progress::none(), prepare);
      if (!s.piece.empty()) {
        pieces = true;
        std::vector<std::pair<std::uint32_t, Relation>> halo;  // (owner chunk, relation)
        for (std::size_t i = 0; i < s.points.size(); ++i) {
          if (votes[c].size() <= s.piece[i]) votes[c].resize(s.piece[i] + 1, 0.0);
          if (own[i]) {
            votes[c][s.piece[i]] +=
                double(dot(s.points.normals[i], s.points.positions[i] - centroid));
          } else {
            halo.push_back({plan.chunk_of(s.points.positions[i], s.index[i]),
                            {s.index[i], std::uint32_t(c), s.piece[i], s.points.normals[i]}});
          }
        }
        const std::lock_guard<std::mutex> lock(relations_mutex);
        for (const auto& [owner, r] : halo) relations.append(owner, &r, sizeof r);
      }
      // Own splats only.
      std::size_t k = 0;
      for (std::size_t i = 0; i < own.size(); ++i) {
        if (!own[i]) continue;
        s.index[k] = s.index[i];
        if (!s.piece.empty()) s.piece[k] = s.piece[i];
        ++k;
      }
      s.index.resize(k);
      if (!s.piece.empty()) s.piece.resize(k);
      keep_points(s.points, own);
      own_count[c] = k;
      write_splats(folder.file(ChunkFiles::name("chunk", c) + ".prepared"), s);
      phase.advance(plan.counts[c]);
    });
    relations.flush_all();
    for (std::size_t c = 0; c < chunks; ++c) stitcher.add_chunk(c, std::move(votes[c]));
  }

  // 5. Stitch the pieces of surfaces that cross chunks, and orient each surface as a whole.
  if (pieces) {
    ProgressPhase phase(progress, "orientation", n);
    for (std::size_t c = 0; c < chunks; ++c) {
      const std::string rel_path = folder.file(ChunkFiles::name("relations", c));
      if (!std::filesystem::exists(rel_path)) continue;
      const Splats s = read_splats(folder.file(ChunkFiles::name("chunk", c) + ".prepared"),
                                   own_count[c], colors, true, true);
      const std::vector<char> bytes = read_whole(rel_path);
      std::filesystem::remove(rel_path);
      for (std::size_t at = 0; at + sizeof(Relation) <= bytes.size(); at += sizeof(Relation)) {
        Relation r;
        std::memcpy(&r, bytes.data() + at, sizeof r);
        const auto it = std::lower_bound(s.index.begin(), s.index.end(), r.index);
        if (it == s.index.end() || *it != r.index) continue;
        const std::size_t i = std::size_t(it - s.index.begin());
        stitcher.relate(c, s.piece[i], r.chunk, r.piece, dot(s.points.normals[i], r.normal) >= 0);
      }
      phase.advance(plan.counts[c]);
    }
    stitcher.solve();
  }

  // 6. Each chunk's subtree and summary; its splats kept in split order.
  std::vector<PtlV2SubtreeSummary> summaries(chunks);
  Aabb bounds;
  PtlV2WriteOptions v2;
  if (o.leaf_trim) v2.leaf_trim = *o.leaf_trim;
  {
    ProgressPhase phase(progress, "hierarchy", n);
    std::vector<Aabb> boxes(chunks);
    for_each_chunk(chunks, pool, [&](std::size_t c, ThreadPool& chunk_pool) {
      const std::string path = folder.file(ChunkFiles::name("chunk", c) + ".prepared");
      Splats s = read_splats(path, own_count[c], colors, true, pieces);
      std::filesystem::remove(path);
      if (pieces) {
        for (std::size_t i = 0; i < s.points.size(); ++i) {
          if (stitcher.flipped(c, s.piece[i])) s.points.normals[i] = -s.points.normals[i];
        }
      }
      std::vector<std::uint32_t> order;
      const SphereTree tree =
          build_sphere_tree(s.points, chunk_pool, Progress::none(), {}, &order);
      summaries[c] = summarize_ptl_v2_subtree(tree, v2);
      boxes[c] = tree.bounds;
      Splats sorted;
      const auto permute = [&](auto& dst, const auto& src) {
        dst.resize(src.size());
        for (std::size_t k = 0; k < order.size() && !src.empty(); ++k) dst[k] = src[order[k]];
      };
      permute(sorted.points.positions, s.points.positions);
      permute(sorted.points.normals, s.points.normals);
      permute(sorted.points.radii, s.points.radii);
      permute(sorted.points.colors, s.points.colors);
      write_splats(folder.file(ChunkFiles::name("chunk", c) + ".splats"), sorted);
      phase.advance(plan.counts[c]);
    });
    for (const Aabb& b : boxes) bounds.extend(b);
  }

  // 7. Write.
  {
    ProgressPhase phase(progress, "write", n);
    PtlV2PartWriter writer(output, summaries, colors, v2);
    const Vec3f centre = bounds.center();
    float far2 = 0;
    for (std::size_t c = 0; c < chunks; ++c) {
      const std::string path = folder.file(ChunkFiles::name("chunk", c) + ".splats");
      const Splats s = read_splats(path, summaries[c].leaf_count, colors, false, false);
      std::filesystem::remove(path);
      const SphereTree tree =
          build_sphere_tree(s.points, pool, Progress::none(), {.presorted = true});
      for (const Vec3f& p : s.points.positions) far2 = std::max(far2, length_squared(p - centre));
      writer.write_subtree(c, tree, pool);
      phase.advance(plan.counts[c]);
    }
    std::ostringstream meta;
    meta << metadata_head;
    for (const std::string& comment : in.comments()) meta << "comment: " << comment << "\n";
    writer.finish(bounds, {centre, std::sqrt(far2)}, in.origin(), in.up(), meta.str());
  }
  result.output_points = n;
  return result;
}

}  // namespace pointillist::chunking
