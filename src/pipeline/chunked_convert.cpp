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
// With --drop-outliers, steps 1-3 run once before, with a wider halo, for each chunk to find its
// outliers (chunk_stages.hpp); the real pass skips them, so its chunks are cut from the points the
// conversion in one piece keeps and give its hierarchy.
// Everything goes to a folder beside the output, removed at the end and on failure; the output
// appears only when complete.
#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <mutex>
#include <optional>
#include <set>
#include <sstream>

#include "chunk_features.hpp"
#include "chunk_files.hpp"
#include "chunk_inputs.hpp"
#include "chunk_messages.hpp"
#include "chunk_orientation.hpp"
#include "chunk_plan.hpp"
#include "chunk_stages.hpp"
#include "chunk_progress.hpp"
#include "chunked.hpp"
#include "mesh_streamed.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/core/morton.hpp"
#include "pointillist/format/ptl_v2.hpp"
#include "pointillist/io/ply.hpp"
#include "pointillist/io/point_file.hpp"
#include "pointillist/io/point_stream.hpp"
#include "pointillist/lod/sphere_tree.hpp"
#include "pointillist/pipeline/chunk_jobs.hpp"
#include "pointillist/prep/prepare.hpp"

namespace pointillist::chunking {
namespace {

std::string relations_kind(int rank) { return "relations" + std::to_string(rank); }

// A mesh's vertices as a point file in the work folder, with the normals and radii its faces
// give (prepare_mesh_vertices): the chunks hold points only. A mesh that fits the budget at
// about kMeshBytesPerVertex is read whole; a larger one streams its faces past its vertices'
// sums on disk (mesh_streamed.hpp). Other inputs pass
// through.
std::vector<std::string> meshes_as_points(std::span<const std::string> inputs,
                                          const WorkFolder& folder, const ConvertOptions& o,
                                          std::uint64_t budget, ThreadPool& pool,
                                          Progress& progress, std::vector<std::string>& warnings) {
  std::vector<std::string> out(inputs.begin(), inputs.end());
  for (std::size_t k = 0; k < inputs.size(); ++k) {
    const std::string& path = inputs[k];
    // Opening a LAS or text stream reads the whole file once; only PLY and OBJ hold faces.
    if (!may_hold_faces(path)) continue;
    std::uint64_t need = 0;
    {
      const auto stream = open_point_stream(path, {.columns = o.columns});
      if (!stream->info().is_mesh) continue;
      // The arrays, and the file's bytes (mapped, or for gzip decompressed: deflate mostly
      // shrinks a binary mesh to a quarter or more).
      need = stream->info().point_count * kMeshBytesPerVertex +
             stream->info().file_size * (path.ends_with(".gz") ? 4 : 1);
    }
    if (o.keep_faces) {
      warnings.push_back(path + ": its faces are not kept (a mesh converted in chunks keeps "
                         "points; render --hybrid needs them: convert in one piece, with a "
                         "larger --memory)");
    }
    progress.detail(path);
    PrepareOptions prepare = o.prepare;
    prepare.input_name = path;
    out[k] = folder.file("mesh" + std::to_string(k) + ".ply");
    if (need > budget) {
      // The streams' windows and batches take about 200 MB besides the pages.
      const StreamedMeshOptions streamed{
          .cache_bytes = budget > (std::uint64_t{400} << 20) ? budget / 2 : budget / 4};
      if (prepare_mesh_streamed(path, out[k], folder.file("mesh" + std::to_string(k) + ".sums"),
                                prepare, progress, streamed)) {
        std::filesystem::remove(folder.file("mesh" + std::to_string(k) + ".sums"));
        continue;
      }
      throw Error(path + ": a mesh of this size needs about " + std::to_string(need / 1'000'000) +
                  " MB to find its normals and radii from its faces, over the memory budget of " +
                  std::to_string(budget / 1'000'000) + " MB, and its faces cannot be streamed "
                  "from this file; raise --memory");
    }
    PointSet mesh = read_point_file(path, progress, {.columns = o.columns});
    prepare_mesh_vertices(mesh, pool, progress, prepare);
    write_ply(out[k], mesh);
  }
  return out;
}

}  // namespace

ConvertResult convert_chunked(std::span<const std::string> inputs, const std::string& output,
                              const ConvertOptions& o, const std::string& metadata_head,
                              std::uint64_t max_chunk_points, ThreadPool& pool,
                              Progress& outer_progress) {
  ChunkJobs& jobs = o.jobs ? *o.jobs : ChunkJobs::single();
  const bool root = jobs.rank() == 0;
  const std::uint64_t budget = o.memory_budget ? o.memory_budget : default_memory_budget();
  ConvertResult result;
  Shared sh;
  sh.input_name = inputs.size() == 1 ? inputs[0] : "the inputs";
  std::optional<MergedInputs> in;
  std::optional<OverallProgress> overall;
  std::optional<WorkFolder> folder;
  Progress* progress_ptr = &Progress::none();
  std::uint64_t input_points = 0;
  double mesh_seconds = -1;  // the meshes' preparation, when some input is one
  step(jobs, [&] {
    if (!root) return;
    folder.emplace(output);
    const auto start = std::chrono::steady_clock::now();
    const std::vector<std::string> sources =
        meshes_as_points(inputs, *folder, o, budget, pool, outer_progress, result.warnings);
    if (!std::equal(sources.begin(), sources.end(), inputs.begin())) {
      mesh_seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
    in.emplace(sources, o.columns);
    in->fit_batches(budget);
    input_points = in->count();
    sh.colors = in->has_colors();
    overall.emplace(outer_progress, input_points,
                    (o.prepare.drop_outliers ? kOutlierPassShare : 0.0) +
                        (o.features ? kFeaturePassShare : 0.0));
    progress_ptr = &*overall;
    if (const auto warning = in->colour_warning()) result.warnings.push_back(*warning);
  });
  if (!root) folder.emplace(output, WorkFolder::kJoin);
  if (o.prepare.drop_outliers) {
    // A first pass finds the outliers; the conversion then never sees them.
    std::vector<std::uint64_t> dropped = find_outliers_in_chunks(
        jobs, root ? &*in : nullptr, *folder, o, max_chunk_points, sh.input_name, pool,
        *progress_ptr);
    if (root) in->drop(std::move(dropped));
  }
  step(jobs, [&] {
    if (!root) return;
    sh.n = in->count();
    if (sh.n == 0) {
      throw Error(sh.input_name + ": every point is an outlier; convert without --drop-outliers");
    }
    const std::uint32_t levels = plan_levels(sh.n, std::max<std::uint64_t>(max_chunk_points, 2));
    scan_plan_distribute(*in, *folder, o, budget, levels, 1.0f, pool, *progress_ptr, sh, result);
  });
  broadcast_shared(jobs, sh);
  Progress& progress = *progress_ptr;
  const std::uint64_t n = sh.n;
  const ChunkPlan& plan = sh.plan;
  const std::size_t chunks = plan.chunk_count();
  const bool colors = sh.colors;
  result.input_points = root ? input_points : n;
  result.chunks = chunks;
  const RankChunks own_chunks = rank_chunks(jobs, plan);
  const std::vector<std::size_t>& mine = own_chunks.chunks;
  const std::uint64_t my_points = own_chunks.points;
  // A chunk number in a rank's message.
  const auto chunk_in = [&](MessageReader& m) {
    const auto c = std::size_t(m.get<std::uint64_t>());
    if (c >= chunks) {
      throw Error("chunked conversion: a rank sent chunk " + std::to_string(c) + " of " +
                  std::to_string(chunks) + "; every rank must run the same pointillist build");
    }
    return c;
  };

  // 4. Prepare each chunk with its halo; keep its own splats, their input indices and
  // orientation pieces; tell each halo point's owner how this chunk oriented it.
  std::vector<std::uint64_t> own_count(chunks, 0);
  std::vector<std::vector<double>> votes(chunks);
  std::atomic<bool> pieces{false};
  step(jobs, [&] {
    const std::string kind = relations_kind(jobs.rank());
    ChunkFiles relations(*folder, chunks, kind.c_str(),
                         ChunkFiles::buffer_bytes(chunks, std::uint64_t{64} << 20, budget));
    std::mutex relations_mutex;
    ProgressPhase phase(progress, "prepare", my_points);
    for_each_chunk(mine, pool, [&](std::size_t c, ThreadPool& chunk_pool) {
      const std::string path = folder->file(ChunkFiles::name("chunk", c));
      std::vector<std::uint8_t> own;
      Splats s;
      s.points = read_chunk(path, sh.layout, colors, own, s.index);
      std::filesystem::remove(path);
      PrepareOptions prepare = o.prepare;
      prepare.drop_outliers = false;  // the outlier pass dropped them
      prepare.orientation_centre = sh.centroid;
      prepare.input_name = sh.input_name;
      prepare.orientation_components = &s.piece;
      prepare_splats(s.points, chunk_pool, Progress::none(), prepare);
      if (!s.piece.empty()) {
        pieces = true;
        std::vector<std::pair<std::uint32_t, Relation>> halo;  // (owner chunk, relation)
        for (std::size_t i = 0; i < s.points.size(); ++i) {
          if (votes[c].size() <= s.piece[i]) votes[c].resize(s.piece[i] + 1, 0.0);
          if (own[i]) {
            votes[c][s.piece[i]] +=
                double(dot(s.points.normals[i], s.points.positions[i] - sh.centroid));
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
      write_splats(folder->file(ChunkFiles::name("chunk", c) + ".prepared"), s);
      phase.advance(plan.counts[c]);
    });
    relations.flush_all();
  });
  {
    // Rank 0 learns every chunk's count and votes.
    MessageWriter w;
    w.put(bool(pieces));
    for (const std::size_t c : mine) {
      w.put(std::uint64_t(c));
      w.put(own_count[c]);
      w.put_vector(votes[c]);
    }
    const std::vector<std::vector<char>> all = jobs.gather(w.bytes());
    step(jobs, [&] {
      for (std::size_t r = 1; r < all.size(); ++r) {
        MessageReader m(all[r]);
        if (m.get<bool>()) pieces = true;
        while (!m.done()) {
          const std::size_t c = chunk_in(m);
          own_count[c] = m.get<std::uint64_t>();
          votes[c] = m.get_vector<double>();
        }
      }
    });
  }

  // 5. Stitch the pieces of surfaces that cross chunks, and orient each surface as a whole
  // (rank 0); every rank learns which of its pieces flip.
  std::vector<std::vector<std::uint8_t>> flips(chunks);
  step(jobs, [&] {
    if (!root || !pieces) return;
    OrientationStitcher stitcher;
    for (std::size_t c = 0; c < chunks; ++c) stitcher.add_chunk(c, votes[c]);
    ProgressPhase phase(progress, "orientation", n);
    // Each chunk's relations are matched to its splats (their normals, indices and pieces only)
    // on every thread, a chunk a thread at a time, then given to the stitcher in chunk order.
    struct Related {
      std::uint32_t piece, other_chunk, other_piece;
      bool agree;
    };
    const std::size_t threads = pool.thread_count();
    std::vector<std::vector<Related>> related(threads);
    for (std::size_t first = 0; first < chunks; first += threads) {
      const std::size_t count = std::min(threads, chunks - first);
      pool.run(count, [&](std::size_t t) {
        const std::size_t c = first + t;
        std::vector<Related>& out = related[t];
        out.clear();
        std::optional<Splats> s;
        for (int rank = 0; rank < jobs.size(); ++rank) {
          const std::string rel_path =
              folder->file(ChunkFiles::name(relations_kind(rank).c_str(), c));
          if (!std::filesystem::exists(rel_path)) continue;
          if (!s) {
            s = read_splats(folder->file(ChunkFiles::name("chunk", c) + ".prepared"),
                            own_count[c], colors, true, true, false);
          }
          const std::vector<char> bytes = read_whole(rel_path);
          std::filesystem::remove(rel_path);
          for (std::size_t at = 0; at + sizeof(Relation) <= bytes.size(); at += sizeof(Relation)) {
            Relation r;
            std::memcpy(&r, bytes.data() + at, sizeof r);
            const auto it = std::lower_bound(s->index.begin(), s->index.end(), r.index);
            if (it == s->index.end() || *it != r.index) continue;
            const std::size_t i = std::size_t(it - s->index.begin());
            out.push_back({s->piece[i], r.chunk, r.piece, dot(s->points.normals[i], r.normal) >= 0});
          }
        }
      });
      for (std::size_t t = 0; t < count; ++t) {
        for (const Related& x : related[t]) {
          stitcher.relate(first + t, x.piece, x.other_chunk, x.other_piece, x.agree);
        }
        phase.advance(plan.counts[first + t]);
      }
    }
    stitcher.solve();
    for (std::size_t c = 0; c < chunks; ++c) {
      for (std::uint32_t k = 0; k < votes[c].size(); ++k) {
        flips[c].push_back(stitcher.flipped(c, k) ? 1 : 0);
      }
    }
  });
  {
    MessageWriter w;
    if (root) {
      w.put(bool(pieces));
      for (const auto& f : flips) w.put_vector(f);
    }
    jobs.broadcast(w.bytes());
    if (!root) {
      MessageReader m(w.bytes());
      pieces = m.get<bool>();
      for (auto& f : flips) f = m.get_vector<std::uint8_t>();
    }
  }

  // 6. Each chunk's subtree and summary; its splats kept in split order.
  std::vector<PtlV2SubtreeSummary> summaries(chunks);
  std::vector<Aabb> boxes(chunks);
  PtlV2WriteOptions v2;
  if (o.leaf_trim) v2.leaf_trim = *o.leaf_trim;
  step(jobs, [&] {
    ProgressPhase phase(progress, "hierarchy", my_points);
    for_each_chunk(mine, pool, [&](std::size_t c, ThreadPool& chunk_pool) {
      const std::string path = folder->file(ChunkFiles::name("chunk", c) + ".prepared");
      Splats s = read_splats(path, own_count[c], colors, true, pieces);
      std::filesystem::remove(path);
      if (pieces) {
        for (std::size_t i = 0; i < s.points.size(); ++i) {
          if (s.piece[i] < flips[c].size() && flips[c][s.piece[i]]) {
            s.points.normals[i] = -s.points.normals[i];
          }
        }
      }
      // A cloud whose neighbours were searched (its records lack normals or radii) comes in
      // its input's order, which need not follow space: the partition names its points by
      // their Morton order (1 M points in input order: 0.02 s to compute, 0.08 s less to
      // split). A mesh's vertices come in the mesh's order, coherent already.
      std::vector<std::uint32_t> morton;
      if (!sh.layout.normals || !sh.layout.radii) {
        morton = morton_order(s.points.positions, chunk_pool);
      }
      SphereTreeOptions tree_options;
      tree_options.morton_order = &morton;
      std::vector<std::uint32_t> order;
      const SphereTree tree =
          build_sphere_tree(s.points, chunk_pool, Progress::none(), tree_options, &order);
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
      write_splats(folder->file(ChunkFiles::name("chunk", c) + ".splats"), sorted);
      phase.advance(plan.counts[c]);
    });
  });
  {
    // Every rank learns every subtree's summary and box: rank 0 gathers them, then gives them
    // to all, which lay out the file alike.
    const auto put = [&](MessageWriter& w, std::size_t c) {
      const PtlV2SubtreeSummary& t = summaries[c];
      w.put(std::uint64_t(c));
      w.put(boxes[c]);
      w.put(t.root);
      w.put(t.node_count);
      w.put(t.leaf_count);
      w.put(t.depth);
      w.put_vector(t.pages);
    };
    const auto get = [&](MessageReader& m) {
      const std::size_t c = chunk_in(m);
      PtlV2SubtreeSummary& t = summaries[c];
      boxes[c] = m.get<Aabb>();
      t.root = m.get<SphereNode>();
      t.node_count = m.get<std::uint64_t>();
      t.leaf_count = m.get<std::uint64_t>();
      t.depth = m.get<std::uint32_t>();
      t.pages = m.get_vector<PtlV2PageInfo>();
    };
    MessageWriter w;
    for (const std::size_t c : mine) put(w, c);
    const std::vector<std::vector<char>> all = jobs.gather(w.bytes());
    step(jobs, [&] {
      for (std::size_t r = 1; r < all.size(); ++r) {
        MessageReader m(all[r]);
        while (!m.done()) get(m);
      }
    });
    if (jobs.size() > 1) {
      MessageWriter every;
      if (root) {
        for (std::size_t c = 0; c < chunks; ++c) put(every, c);
      }
      std::vector<char> bytes = every.bytes();
      jobs.broadcast(bytes);
      step(jobs, [&] {
        MessageReader m(bytes);
        while (!root && !m.done()) get(m);
      });
    }
  }

  // 7. Write: rank 0 lays out the file; every rank writes its own subtrees into it (the others
  // through the shared folder) and passes on what rank 0 needs of them; rank 0 finishes it
  // (with --features, leaving it unrenamed for step 8).
  std::optional<PtlV2PartWriter> writer;
  std::string metadata;
  Aabb bounds;
  for (const Aabb& b : boxes) bounds.extend(b);
  const Vec3f centre = bounds.center();
  std::vector<float> far2(chunks, 0.0f);
  step(jobs, [&] {
    if (root) writer.emplace(output, summaries, colors, v2);
  });
  if (jobs.size() > 1) {
    MessageWriter w;
    if (root) {
      const std::string& temp = writer->temp_path();
      w.put_vector(std::vector<char>(temp.begin(), temp.end()));
    }
    std::vector<char> bytes = w.bytes();
    jobs.broadcast(bytes);
    step(jobs, [&] {
      if (root) return;
      const std::vector<char> temp = MessageReader(bytes).get_vector<char>();
      writer.emplace(output, summaries, colors, v2, std::string(temp.begin(), temp.end()));
    });
  }
  step(jobs, [&] {
    ProgressPhase phase(progress, "write", my_points);
    // Subtrees are encoded and written in place a few at a time (as many as the chunks
    // prepared at once).
    for_each_chunk(mine, pool, [&](std::size_t c, ThreadPool& chunk_pool) {
      const std::string path = folder->file(ChunkFiles::name("chunk", c) + ".splats");
      const Splats s = read_splats(path, summaries[c].leaf_count, colors, false, false);
      std::filesystem::remove(path);
      const SphereTree tree =
          build_sphere_tree(s.points, chunk_pool, Progress::none(), {.presorted = true});
      for (const Vec3f& p : s.points.positions) {
        far2[c] = std::max(far2[c], length_squared(p - centre));
      }
      writer->write_subtree(c, tree, chunk_pool);
      phase.advance(plan.counts[c]);
    });
    if (!root) writer->sync();
  });
  {
    MessageWriter w;
    step(jobs, [&] {  // (a rank that failed here must still reach the gather)
      if (root) return;
      for (const std::size_t c : mine) {
        w.put(std::uint64_t(c));
        w.put(far2[c]);
        w.put_vector(writer->written_part(c));
      }
    });
    const std::vector<std::vector<char>> all = jobs.gather(w.bytes());
    step(jobs, [&] {
      for (std::size_t r = 1; r < all.size(); ++r) {
        MessageReader m(all[r]);
        while (!m.done()) {
          const std::size_t c = chunk_in(m);
          far2[c] = m.get<float>();
          writer->adopt_part(c, m.get_vector<char>());
        }
      }
    });
  }
  step(jobs, [&] {
    if (!root) return;
    const float view_radius = std::sqrt(*std::max_element(far2.begin(), far2.end()));
    std::ostringstream meta;
    meta << metadata_head;
    for (const std::string& comment : in->comments()) meta << "comment: " << comment << "\n";
    metadata = meta.str();
    if (o.features) {
      writer->finish_uncommitted(bounds, {centre, view_radius}, in->origin(), in->up(), metadata);
    } else {
      writer->finish(bounds, {centre, view_radius}, in->origin(), in->up(), metadata);
    }
  });
  // 8. Sharp features, found on the written file's leaves as the conversion in one piece finds
  // them, the parts shared among the ranks.
  if (o.features) {
    add_features_in_parts(jobs, root ? &*writer : nullptr, *folder, metadata,
                          for_quantized_model(*o.features), pool, progress, result.warnings);
  }
  result.output_points = 0;
  for (const std::uint64_t count : own_count) result.output_points += count;
  if (overall) result.phase_seconds = overall->phase_seconds();
  if (mesh_seconds >= 0) {
    result.phase_seconds.insert(result.phase_seconds.begin(), {"mesh", mesh_seconds});
  }
  return result;
}

}  // namespace pointillist::chunking
