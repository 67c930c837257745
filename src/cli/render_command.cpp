// `pointillist render`: opens the models (or a scene file), then the library's Renderer draws a
// settled image or a frame sequence; writes the PNG, the depth image and the statistics.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "commands.hpp"
#include "terminal_progress.hpp"
#include "util.hpp"
#include "pointillist/core/atomic_file.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/io/camera_path.hpp"
#include "pointillist/io/pfm.hpp"
#include "pointillist/io/png.hpp"
#include "pointillist/pipeline/report.hpp"
#include "pointillist/pipeline/scene.hpp"
#include "pointillist/render/depth_image.hpp"
#include "pointillist/render/sequence.hpp"

namespace pointillist::cli {

Camera make_camera(const ViewOptions& v, const Sphere& view_sphere, Vec3f model_up) {
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
    c.ortho_height = v.ortho_height;
    return c;
  }
  Camera c = orbit_camera(view_sphere, {.azimuth_deg = v.azimuth_deg,
                                        .elevation_deg = v.elevation_deg,
                                        .distance = v.distance,
                                        .fov_deg = v.fov_deg,
                                        .width = v.width,
                                        .height = v.height,
                                        .up = v.up.value_or(model_up)});
  c.ortho_height = v.ortho_height;
  return c;
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

std::string frame_path(const std::string& dir, std::size_t index) {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%05zu.png", index);
  return (std::filesystem::path(dir) / name).string();
}

SequenceOptions sequence_options(const RenderOptions& o, std::vector<Camera> path) {
  return {.progressive_frames = o.progressive_frames,
          .read_per_frame = o.read_per_frame,
          .orbit_frames = o.orbit_frames,
          .path = std::move(path),
          .frame_ms = o.frame_ms,
          .refine_frames = o.refine_frames};
}

// The cameras of --path FILE (none without one): the file's fov unless --fov was given, --up
// (else +Y) for frames that give no up vector.
std::vector<Camera> path_file_cameras(const RenderOptions& o) {
  if (o.path_file.empty()) return {};
  const CameraPath path = read_camera_path(o.path_file);
  const float fov_deg = o.fov_given || !path.fov_deg ? o.view.fov_deg : *path.fov_deg;
  return path_cameras(path, o.path_file, fov_deg, o.view.width, o.view.height,
                      o.view.up.value_or(Vec3f{0, 1, 0}));
}

// Checks what only the command line can get wrong (the library checks the rest).
void check_options(const RenderOptions& o) {
  std::vector<std::string> inputs = o.inputs;
  if (!o.path_file.empty()) inputs.push_back(o.path_file);
  check_outputs(inputs, {{"-o", o.output}, {"--depth", o.depth_output},
                         {"--stats", o.stats_output}});
  for (const auto& [option, path] : {std::pair<const char*, const std::string&>{"-o", o.output},
                                     {"--depth", o.depth_output}}) {
    const std::string ext = lowercase_extension(path);
    const bool depth_pfm = std::string(option) == "--depth" && ext == ".pfm";
    if (!path.empty() && ext != ".png" && !depth_pfm) {
      throw OptionError(std::string(option) + " " + path +
                        (std::string(option) == "--depth"
                             ? ": the depth image is a PNG (16-bit, scaled to the frame's depth "
                               "range) or a PFM (float depth in scene units); give a path ending "
                               "in .png or .pfm"
                             : ": render writes PNG images; give a path ending in .png"));
    }
  }
  if (o.orbit_frames > 0 && (o.view.eye || o.view.target)) {
    throw OptionError("--path orbit:N moves the camera around the orbit; it cannot be combined "
                      "with --eye/--target (use --view, --distance and --up)");
  }
  if (!o.path_file.empty() && (o.view.eye || o.view.target)) {
    throw OptionError("--path " + o.path_file + ": the camera path file places the camera; it "
                      "cannot be combined with --eye/--target");
  }
  if (!o.frames_out.empty() && o.orbit_frames == 0 && o.path_file.empty() &&
      o.refine_frames == 0 && o.progressive_frames == 0) {
    throw OptionError("--frames-out writes the frames of a sequence; add --path orbit:N, "
                      "--path FILE, --refine K or --progressive N");
  }
  if (o.inputs.size() > 1) {
    for (const std::string& in : o.inputs) {
      if (is_scene_file(in)) {
        throw OptionError(in + ": a scene file is rendered on its own; list its models in it, or "
                               "give the models without it");
      }
    }
  }
}

void create_frames_folder(const RenderOptions& o) {
  if (o.frames_out.empty()) return;
  std::error_code ec;
  std::filesystem::create_directories(o.frames_out, ec);
  if (ec) {
    throw IoError(o.frames_out + ": cannot create the frames folder (" + ec.message() +
                  "); give a writable path to --frames-out");
  }
}

}  // namespace

int run_render(const RenderOptions& o) {
  check_options(o);
  const SequenceOptions sequence_opts = sequence_options(o, path_file_cameras(o));
  check_sequence_options(sequence_opts);
  create_frames_folder(o);
  for (const std::string& w : o.warnings) {
    std::fprintf(stderr, "pointillist render: warning: %s\n", w.c_str());
  }
  ThreadPool pool(o.threads);
  TerminalProgress progress(!o.quiet && TerminalProgress::stderr_is_terminal());
  const bool paging_asked = o.memory_cap > 0 || o.progressive_frames > 0;
  const bool paging_possible =
      o.frame.rasterizer != Rasterizer::Reference && o.frame.lod == LodScheme::QSplat;
  OpenModelOptions open;
  open.prepare = o.prepare;
  open.columns = o.columns;
  open.keep_source = o.frame.rasterizer == Rasterizer::Reference;
  open.paging = paging_asked ? Paging::Always : (paging_possible ? Paging::Auto : Paging::Never);
  open.frames = std::max<std::uint64_t>(
      1, std::uint64_t(o.orbit_frames) + sequence_opts.path.size() + o.refine_frames);
  open.frame_pixels = std::uint64_t(o.view.width) * std::uint64_t(o.view.height);
  open.features = o.features;
  open.stored_features = o.frame.features;
  if (o.features) open.paging = Paging::Never;  // features need the hierarchy held whole
  // Occlusion culling culls inside models held whole, a paged model only as a whole: decode
  // them unless paging is asked for.
  if (o.frame.occlusion.method != OcclusionMethod::None && !paging_asked) {
    open.paging = Paging::Never;
  }
  const Scene scene = o.inputs.size() == 1 && is_scene_file(o.inputs[0])
                          ? read_scene(o.inputs[0], open, pool, progress)
                          : scene_of_models(o.inputs, open, pool, progress);
  std::vector<std::string> models;  // a scene file's models are inputs too
  for (const auto& m : scene.models()) {
    models.push_back(m->path());
    if (!o.frame.features || m->features() == nullptr) continue;
    const std::string noisy = noisy_features_warning(m->features()->stats, m->features()->options);
    if (!noisy.empty()) {
      std::fprintf(stderr, "pointillist render: warning: %s: %s\n", m->path().c_str(), noisy.c_str());
    }
  }
  check_outputs(models, {{"-o", o.output}, {"--depth", o.depth_output},
                         {"--stats", o.stats_output}});
  const Sphere view_sphere = scene.view_sphere();
  const Vec3f up = scene.up();
  Renderer renderer({.page_all = paging_asked, .memory_cap = o.memory_cap});
  Frame frame;
  const bool sequence = o.orbit_frames > 0 || !sequence_opts.path.empty() ||
                        o.refine_frames > 0 || o.frame_ms > 0 || o.progressive_frames > 0 ||
                        !o.frames_out.empty();
  std::vector<SequenceFrame> frames;
  if (sequence) {
    ViewOptions view = o.view;
    frames = render_sequence(
        renderer, scene.instances(),
        [&](float azimuth) {
          view.azimuth_deg = azimuth;
          return make_camera(view, view_sphere, up);
        },
        o.view.azimuth_deg, o.settings, o.frame, sequence_opts, pool, frame,
        [&](const Frame& f, std::size_t index) {
          if (!o.frames_out.empty()) {
            write_png_rgb8(frame_path(o.frames_out, index), f.width, f.height, f.color);
          }
        });
  } else {
    render_settled(renderer, scene.instances(), make_camera(o.view, view_sphere, up), o.settings,
                   o.frame, pool, frame);
  }
  write_png_rgb8(o.output, frame.width, frame.height, frame.color);
  if (!o.depth_output.empty()) {
    const std::string ext = lowercase_extension(o.depth_output);
    if (ext == ".pfm") {
      write_pfm(o.depth_output, frame.width, frame.height, frame.depth);
    } else {
      const auto depth16 = depth_to_gray16(frame);
      write_png_gray16(o.depth_output, frame.width, frame.height, depth16);
    }
  }
  const float finest = std::min(1.0f, initial_detail(o.settings, o.frame));
  if (!o.stats_output.empty()) {
    write_text(o.stats_output,
               render_report_json({.scene = &scene, .renderer = &renderer, .frame = o.frame,
                                   .memory_cap = o.memory_cap, .last = frame.stats,
                                   .sequence = sequence, .frames = frames,
                                   .target_ms = o.frame_ms, .settle = kSettleFrames,
                                   .finest = finest}));
  }
  if (o.quiet || o.stats_output == "-") return 0;
  const std::string names = input_names(o.inputs);
  if (sequence) {
    double total = 0;
    for (const SequenceFrame& r : frames) total += r.stats.ms_total;
    std::printf("rendered %s: %zu frames at %dx%d, mean %.2f ms/frame", names.c_str(),
                frames.size(), frame.width, frame.height, total / double(frames.size()));
    if (o.frame_ms > 0) {
      std::printf(", %.0f%% of frames after the first %zu within 20%% of %.1f ms",
                  100.0 * hit_rate(frames, o.frame_ms, kSettleFrames, finest), kSettleFrames,
                  o.frame_ms);
    }
    std::printf("; last frame -> %s%s%s\n", o.output.c_str(),
                o.frames_out.empty() ? "" : ", all frames -> ", o.frames_out.c_str());
    return 0;
  }
  std::printf("rendered %s: %dx%d, %llu splats, %.2f ms (select %.2f, raster %.2f) -> %s\n",
              names.c_str(), frame.width, frame.height,
              static_cast<unsigned long long>(frame.stats.splats), frame.stats.ms_total,
              frame.stats.ms_select, frame.stats.ms_raster, o.output.c_str());
  return 0;
}

}  // namespace pointillist::cli
