#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>
#include <vector>

#include "commands.hpp"
#include "pointillist/pipeline/model.hpp"
#include "stats_json.hpp"
#include "terminal_progress.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/io/png.hpp"
#include "pointillist/render/depth_image.hpp"
#include "pointillist/render/frame_control.hpp"
#include "pointillist/render/mesh_reference.hpp"
#include "pointillist/render/paged.hpp"
#include "pointillist/render/spt_render.hpp"

namespace pointillist::cli {

Camera make_camera(const ViewOptions& v, const SphereTreeView& tree) {
  const bool explicit_eye = v.eye || v.target;
  if (explicit_eye) {
    if (!v.eye || !v.target) {
      throw OptionError("--eye and --target must be given together (--up is optional, default 0,1,0)");
    }
    Camera c;
    c.eye = *v.eye;
    c.target = *v.target;
    c.up = v.up.value_or(Vec3f{0, 1, 0});
    c.fov_deg = v.fov_deg;
    c.width = v.width;
    c.height = v.height;
    return c;
  }
  return orbit_camera(tree.view_sphere, {.azimuth_deg = v.azimuth_deg,
                                         .elevation_deg = v.elevation_deg,
                                         .distance = v.distance,
                                         .fov_deg = v.fov_deg,
                                         .width = v.width,
                                         .height = v.height,
                                         .up = v.up.value_or(Vec3f{0, 1, 0})});
}

void write_text(const std::string& where, const std::string& json) {
  if (where == "-") {
    std::fputs(json.c_str(), stdout);
    return;
  }
  std::ofstream out(where, std::ios::binary | std::ios::trunc);
  if (!out || !(out << json) || !out.flush()) {
    throw IoError(where + ": cannot write the statistics file; check that the folder exists and "
                          "is writable");
  }
}

namespace {

// Frames a sequence renders before the frame-time controller is judged (the hit rate).
constexpr std::size_t kSettleFrames = 5;
// Page size when a model held whole is cut into pages for --memory / --progressive.
constexpr std::uint64_t kInMemoryPageBytes = 64 * 1024;
constexpr std::uint32_t kInMemoryPageLevels = 4;
// A single image of a paged model: at most this many load rounds (each loads one more level).
constexpr int kMaxSettleRounds = 1000;

std::string frame_path(const std::string& dir, std::size_t index) {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%05zu.png", index);
  return (std::filesystem::path(dir) / name).string();
}

void check_sequence_options(const RenderOptions& o) {
  if (o.frame_ms > 0 && o.orbit_frames == 0) {
    throw OptionError("--frame-ms holds a frame time over a sequence of frames; add --path orbit:N "
                      "(N frames around the model)");
  }
  if (o.orbit_frames > 0 && (o.view.eye || o.view.target)) {
    throw OptionError("--path orbit:N moves the camera around the orbit; it cannot be combined "
                      "with --eye/--target (use --view, --distance and --up)");
  }
  if (!o.frames_out.empty() && o.orbit_frames == 0 && o.refine_frames == 0 &&
      o.progressive_frames == 0) {
    throw OptionError("--frames-out writes the frames of a sequence; add --path orbit:N, "
                      "--refine K or --progressive N");
  }
  if (o.progressive_frames > 0 && (o.orbit_frames > 0 || o.frame_ms > 0)) {
    throw OptionError("--progressive N renders N frames at one view while pages load; it cannot "
                      "be combined with --path or --frame-ms (use --refine K to refine after it)");
  }
  if (!o.frames_out.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(o.frames_out, ec);
    if (ec) {
      throw IoError(o.frames_out + ": cannot create the frames folder (" + ec.message() +
                    "); give a writable path to --frames-out");
    }
  }
}

// Draws one frame with either level-of-detail scheme; `detail` is the QSplat threshold or the
// SPT error bound (pixels).
class FrameRenderer {
 public:
  FrameRenderer(const RenderOptions& o, const Model& model, ThreadPool& pool,
                Progress& progress)
      : o_(o), tree_(model.tree()), mesh_(model.source()), pool_(pool) {
    if (o.mode == RenderMode::Reference) {
      if (o.lod == LodScheme::Spt) {
        throw OptionError("--mode reference draws the mesh's triangles; it cannot be combined with "
                          "--lod spt");
      }
      if (!mesh_.is_mesh()) {
        throw OptionError(o.input + ": --mode reference draws a mesh's triangles, and this input " +
                          (model.kind() != ModelKind::Scan
                               ? std::string("is a splat model")
                               : std::string("has no faces")) +
                          "; give the source mesh (.ply, .obj)");
      }
    }
    if (o.mode == RenderMode::Quality && o.lod == LodScheme::Spt) {
      throw OptionError("--mode quality draws the QSplat hierarchy's splats; it cannot be combined "
                        "with --lod spt (drop --lod spt, or use --mode fast)");
    }
    if (o.mode == RenderMode::Quality) validate_quality_settings(o.quality);
    if (model.pages() || o.memory_cap > 0 || o.progressive_frames > 0) {
      if (o.lod == LodScheme::Spt || o.mode == RenderMode::Reference) {
        throw OptionError(std::string(model.pages() ? o.input + " is rendered page by page"
                                                    : "--memory and --progressive render page "
                                                      "by page") +
                          ": the QSplat hierarchy in the fast or quality mode; drop " +
                          (o.lod == LodScheme::Spt ? "--lod spt" : "--mode reference"));
      }
      const PageSource* source = model.pages();
      if (!source) {
        // A model held whole (a .ptl v1 file, a scan): cut into pages in memory, so that the
        // behaviour can be seen; the cap bounds the pages the renderer keeps, not the mapping.
        owned_pages_ = paginate(tree_, kInMemoryPageBytes, kInMemoryPageLevels);
        source = owned_pages_.get();
      }
      paged_.emplace(*source, o.memory_cap > 0 ? o.memory_cap : UINT64_MAX, pool);
      page_source_ = source;
    }
    if (o.lod == LodScheme::Spt) {
      spt_ = build_sequential_point_tree(sphere_tree_leaves(tree_), pool, progress);
    }
  }
  float initial_detail() const {
    return o_.lod == LodScheme::Spt ? o_.epsilon_px : o_.settings.threshold_px;
  }
  // `fast_only`: a paged model in the quality mode draws a fast frame (the same selection).
  void draw(const Camera& camera, float detail, Frame& frame, bool fast_only = false) {
    RenderSettings settings = o_.settings;
    if (o_.lod == LodScheme::Spt) {
      render_spt(spt_, camera, settings,
                 {.epsilon_px = detail, .chunk_culling = !o_.no_chunk_culling}, pool_, frame,
                 &spt_stats_);
    } else if (paged_) {
      settings.threshold_px = detail;
      if (o_.mode == RenderMode::Quality && !fast_only) {
        paged_->render_quality(camera, settings, o_.quality, pool_, frame, quality_scratch_);
      } else {
        paged_->render(camera, settings, pool_, frame);
      }
    } else if (o_.mode == RenderMode::Reference) {
      render_mesh_reference(mesh_, camera, settings, frame);
    } else if (o_.mode == RenderMode::Quality) {
      settings.threshold_px = detail;
      render_quality(tree_, camera, settings, o_.quality, pool_, frame, quality_scratch_);
    } else {
      settings.threshold_px = detail;
      render(tree_, camera, settings, pool_, frame);
    }
  }
  // After a frame has been recorded: loads the pages it asked for (paged models). Returns the
  // number of pages loaded.
  // --progressive has the loader thread read between frames and waits for it (deterministic
  // frames); a camera path hands the pages to the loader thread, as a viewer does, and the
  // frames show what has arrived.
  std::size_t after_frame() {
    if (!paged_) return 0;
    if (o_.progressive_frames > 0) {
      // The loader thread reads the pages, as a viewer's does; waiting for it keeps the frames
      // reproducible (each shows exactly --read-per-frame more of the model).
      const std::size_t handed = paged_->request_in_background(SIZE_MAX, o_.read_per_frame);
      paged_->wait_for_loader();
      return handed;
    }
    if (o_.orbit_frames > 0 || o_.refine_frames > 0) return paged_->request_in_background();
    return paged_->load_requested(pool_);
  }
  // Draws the view until a paged model has loaded all it needs (or all the cap allows).
  void draw_settled(const Camera& camera, float detail, Frame& frame) {
    // A paged quality image loads its pages with fast frames (the same selection, so the same
    // pages) and is drawn once at the end.
    const bool quality_last = paged_ && o_.mode == RenderMode::Quality;
    for (int round = 0; round < kMaxSettleRounds; ++round) {
      draw(camera, detail, frame, quality_last);
      if (!paged_ || paged_->complete() || after_frame() == 0) break;
    }
    if (quality_last) draw(camera, detail, frame);
  }
  bool paged() const { return paged_.has_value(); }
  // Fills the paged-model fields of a frame record.
  void annotate(FrameRecord& r) const {
    if (!paged_) return;
    r.bytes_read = static_cast<std::int64_t>(paged_->stats().bytes_read);
    r.resident_bytes = static_cast<std::int64_t>(paged_->stats().resident_bytes);
  }

  // Extra --stats lines for the last frame.
  std::string extra_json() const {
    if (paged_) {
      const PagedRenderStats& p = paged_->stats();
      std::uint64_t file_bytes = page_source_->open_bytes();
      for (std::uint32_t i = 0; i < page_source_->page_count(); ++i) {
        file_bytes += page_source_->page_storage_bytes(i);
      }
      char buf[768];
      std::snprintf(buf, sizeof buf,
                    "  \"lod\": \"qsplat\",\n  \"mode\": \"%s\",\n  \"paged\": true,\n"
                    "  \"pages\": %u,\n  \"model_bytes\": %llu,\n  \"memory_cap\": %llu,\n"
                    "  \"bytes_read\": %llu,\n  \"resident_bytes\": %llu,\n"
                    "  \"resident_bytes_peak\": %llu,\n  \"pages_loaded\": %llu,\n"
                    "  \"pages_evicted\": %llu,\n  \"complete\": %s,\n",
                    o_.mode == RenderMode::Quality ? "quality" : "fast",
                    page_source_->page_count(), static_cast<unsigned long long>(file_bytes),
                    static_cast<unsigned long long>(o_.memory_cap),
                    static_cast<unsigned long long>(p.bytes_read),
                    static_cast<unsigned long long>(p.resident_bytes),
                    static_cast<unsigned long long>(p.resident_bytes_peak),
                    static_cast<unsigned long long>(p.pages_loaded),
                    static_cast<unsigned long long>(p.pages_evicted),
                    paged_->complete() ? "true" : "false");
      return buf;
    }
    if (o_.mode == RenderMode::Quality) {
      char buf[256];
      std::snprintf(buf, sizeof buf,
                    "  \"lod\": \"qsplat\",\n  \"mode\": \"quality\",\n  \"reconstruction\": \"%s\",\n"
                    "  \"opacity\": %g,\n",
                    o_.quality.reconstruction == Reconstruction::ZRange ? "zrange" : "zthreshold",
                    double(o_.quality.opacity));
      return buf;
    }
    if (o_.mode == RenderMode::Reference) return "  \"mode\": \"reference\",\n";
    if (o_.lod != LodScheme::Spt) return "  \"lod\": \"qsplat\",\n  \"mode\": \"fast\",\n";
    char buf[512];
    std::snprintf(buf, sizeof buf,
                  "  \"lod\": \"spt\",\n  \"mode\": \"fast\",\n  \"list_length\": %llu,\n  \"entries_scanned\": %llu,\n"
                  "  \"fraction_scanned\": %.4f,\n  \"chunks\": %llu,\n  \"chunks_culled\": %llu,\n",
                  static_cast<unsigned long long>(spt_stats_.entries_total),
                  static_cast<unsigned long long>(spt_stats_.entries_scanned),
                  spt_stats_.entries_total
                      ? double(spt_stats_.entries_scanned) / double(spt_stats_.entries_total)
                      : 0.0,
                  static_cast<unsigned long long>(spt_stats_.chunks_total),
                  static_cast<unsigned long long>(spt_stats_.chunks_culled));
    return buf;
  }

 private:
  const RenderOptions& o_;
  const SphereTreeView& tree_;
  const PointSet& mesh_;
  ThreadPool& pool_;
  SequentialPointTree spt_;
  SptSelectionStats spt_stats_;
  QualityScratch quality_scratch_;
  std::unique_ptr<PageSource> owned_pages_;
  const PageSource* page_source_ = nullptr;
  std::optional<PagedRenderer> paged_;
};

// Renders the path (and/or the idle refinement) a viewer would show; returns every frame's record
// and leaves the last frame in `frame`.
std::vector<FrameRecord> render_sequence(const RenderOptions& o, const SphereTreeView& tree,
                                         FrameRenderer& renderer, Frame& frame) {
  check_sequence_options(o);
  const float start = renderer.initial_detail();
  const float finest = std::min(1.0f, start);
  std::optional<FrameTimeController> control;
  if (o.frame_ms > 0) {
    control.emplace(FrameControlOptions{.target_ms = o.frame_ms, .finest = finest}, start);
  }
  std::vector<FrameRecord> records;
  ViewOptions view = o.view;
  auto draw = [&](const char* phase, float detail) {
    renderer.draw(make_camera(view, tree), detail, frame);
    records.push_back({phase, view.azimuth_deg, detail, frame.stats});
    renderer.annotate(records.back());
    if (!o.frames_out.empty()) {
      write_png_rgb8(frame_path(o.frames_out, records.size() - 1), frame.width, frame.height,
                     frame.color);
    }
    renderer.after_frame();
  };
  for (unsigned i = 0; i < o.progressive_frames; ++i) draw("progressive", start);
  for (unsigned i = 0; i < o.orbit_frames; ++i) {
    view.azimuth_deg = o.view.azimuth_deg + 360.0f * static_cast<float>(i) /
                                                static_cast<float>(o.orbit_frames);
    draw("path", control ? control->parameter() : start);
    if (control) control->report(frame.stats.ms_total);
  }
  if (o.refine_frames > 0) {
    const float from = control ? control->parameter() : start;
    for (float detail : refinement_sequence(from, finest, o.refine_frames)) draw("refine", detail);
  }
  return records;
}

}  // namespace

int run_render(const RenderOptions& o) {
  ThreadPool pool(o.threads);
  TerminalProgress progress(!o.quiet && TerminalProgress::stderr_is_terminal());
  const bool paging_asked = o.memory_cap > 0 || o.progressive_frames > 0;
  const bool paging_possible = o.mode == RenderMode::Fast && o.lod == LodScheme::QSplat;
  const Model model = open_model(
      o.input,
      {.prepare = o.prepare,
       .columns = o.columns,
       .keep_source = o.mode == RenderMode::Reference,
       .paging = paging_asked ? Paging::Always
                              : (paging_possible ? Paging::Auto : Paging::Never)},
      pool, progress);
  FrameRenderer renderer(o, model, pool, progress);
  Frame frame;
  const bool sequence = o.orbit_frames > 0 || o.refine_frames > 0 || o.frame_ms > 0 ||
                        o.progressive_frames > 0 || !o.frames_out.empty();
  std::vector<FrameRecord> records;
  if (sequence) {
    records = render_sequence(o, model.tree(), renderer, frame);
  } else {
    renderer.draw_settled(make_camera(o.view, model.tree()), renderer.initial_detail(), frame);
  }
  write_png_rgb8(o.output, frame.width, frame.height, frame.color);
  if (!o.depth_output.empty()) {
    const auto depth16 = depth_to_gray16(frame);
    write_png_gray16(o.depth_output, frame.width, frame.height, depth16);
  }
  const float finest = std::min(1.0f, renderer.initial_detail());
  if (!o.stats_output.empty()) {
    const std::string extra = renderer.extra_json();
    write_text(o.stats_output,
               sequence ? sequence_to_json(records, o.frame_ms, kSettleFrames, finest, extra)
                        : stats_to_json(frame.stats, extra));
  }
  if (o.quiet || o.stats_output == "-") return 0;
  if (sequence) {
    double total = 0;
    for (const FrameRecord& r : records) total += r.stats.ms_total;
    std::printf("rendered %s: %zu frames at %dx%d, mean %.2f ms/frame", o.input.c_str(),
                records.size(), frame.width, frame.height, total / double(records.size()));
    if (o.frame_ms > 0) {
      std::printf(", %.0f%% of frames after the first %zu within 20%% of %.1f ms",
                  100.0 * hit_rate(records, o.frame_ms, kSettleFrames, finest), kSettleFrames,
                  o.frame_ms);
    }
    std::printf("; last frame -> %s%s%s\n", o.output.c_str(),
                o.frames_out.empty() ? "" : ", all frames -> ", o.frames_out.c_str());
    return 0;
  }
  std::printf("rendered %s: %dx%d, %llu splats, %.2f ms (select %.2f, raster %.2f) -> %s\n",
              o.input.c_str(), frame.width, frame.height,
              static_cast<unsigned long long>(frame.stats.splats), frame.stats.ms_total,
              frame.stats.ms_select, frame.stats.ms_raster, o.output.c_str());
  return 0;
}

}  // namespace pointillist::cli
