// `pointillist view`: opens the models (or a scene file) as `render` does and shows them in a
// window (viewer module): the camera follows the mouse at a held frame rate, the view refines when
// it stops, keys toggle the modes, `s` writes a screenshot and prints its `render` command.
#include <chrono>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "commands.hpp"
#include "options.hpp"
#include "terminal_progress.hpp"
#include "util.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/pipeline/scene.hpp"
#include "pointillist/viewer/sdl_window.hpp"
#include "pointillist/viewer/viewer.hpp"

namespace pointillist::cli {
namespace {

struct ViewCommandOptions {
  std::vector<std::string> inputs;
  ViewOptions view;
  CameraText camera;
  RenderSettings settings;
  FrameSettings frame;
  std::string background = "0,0,0", memory, events, log_frames, screenshots = ".";
  std::vector<std::string> edl;
  double fps = 30;
  unsigned refine = 8;
  bool features = false, no_features = false;
  bool whole = false;  // --whole: decode every .ptl whole
  PrepareOptions prepare;
  std::string columns;
  unsigned threads = 0;
  bool quiet = false;
};

// .ptl files larger than this are drawn page by page (about 5 million points).
constexpr std::uintmax_t kPagedViewBytes = 32u << 20;

// The options given to `view` that `render` needs as they are to draw the same image.
const char* const kPassedToRender[] = {"--background", "--memory", "--features", "--normals",
                                       "--k", "--drop-outliers", "--outlier-ratio", "--columns"};

std::vector<std::string> render_words(const CLI::App& cmd, const ViewCommandOptions& o) {
  std::vector<std::string> words = {"pointillist", "render"};
  for (const std::string& in : o.inputs) words.push_back(in);
  for (const char* name : kPassedToRender) {
    const CLI::Option* opt = cmd.get_option_no_throw(name);
    if (!opt || opt->count() == 0) continue;
    words.push_back(name);
    for (const std::string& r : opt->results()) {
      if (opt->get_expected_min() > 0) words.push_back(r);
    }
  }
  return words;
}

int run_view(const CLI::App& cmd, ViewCommandOptions& o) {
  const auto start = std::chrono::steady_clock::now();
  parse_camera_options(o.camera, o.view);
  o.settings.background = parse_rgb8(o.background, "--background");
  if (cmd.count("--edl") > 0) o.settings.edl_strength = parse_edl(o.edl);
  if (o.features && o.no_features) {
    throw OptionError("--features and --no-features contradict each other; give one");
  }
  o.frame.features = !o.no_features;
  std::vector<ScriptStep> script;
  if (!o.events.empty()) script = read_event_script(o.events);
  const std::uint64_t memory_cap = o.memory.empty() ? 0 : parse_bytes(o.memory, "--memory");
  if (o.inputs.size() > 1) {
    for (const std::string& in : o.inputs) {
      if (is_scene_file(in)) {
        throw OptionError(in + ": a scene file is viewed on its own; list its models in it, or "
                               "give the models without it");
      }
    }
  }
  std::error_code ec;
  if (!std::filesystem::is_directory(o.screenshots, ec)) {
    throw OptionError("--screenshots " + o.screenshots + ": not a folder; give an existing folder");
  }
  ThreadPool pool(o.threads);
  TerminalProgress progress(!o.quiet && TerminalProgress::stderr_is_terminal());
  OpenModelOptions open;
  open.prepare = o.prepare;
  open.columns = o.columns;
  open.paging = memory_cap > 0 ? Paging::Always : Paging::Auto;
  // A large .ptl is drawn page by page: its first frame comes at once (0.46 s for a 20 M-point
  // file against 12.7 s to decode it whole) and frames are as fast. Smaller ones are decoded
  // whole (in under a second), so that SPT and occlusion culling can be switched on.
  bool large = false;
  for (const std::string& in : o.inputs) {
    large = large || (is_model_file(in) && std::filesystem::file_size(in, ec) > kPagedViewBytes);
  }
  open.frames = large && !o.whole ? 1 : 1000;
  if (o.whole && memory_cap == 0) open.paging = Paging::Never;
  open.frame_pixels = std::uint64_t(o.view.width) * std::uint64_t(o.view.height);
  if (o.features) {
    open.features = FeatureOptions{};
    open.paging = Paging::Never;
  }
  open.stored_features = o.frame.features;
  if (o.frame.hybrid) o.frame.lod = LodScheme::Spt;
  if ((o.frame.occlusion.method != OcclusionMethod::None || o.frame.lod == LodScheme::Spt) &&
      memory_cap == 0) {
    open.paging = Paging::Never;
  }
  const Scene scene = o.inputs.size() == 1 && is_scene_file(o.inputs[0])
                          ? read_scene(o.inputs[0], open, pool, progress)
                          : scene_of_models(o.inputs, open, pool, progress);
  const Sphere sphere = scene.view_sphere();
  const Vec3f up = o.view.up && !o.view.eye ? *o.view.up : scene.up();
  Navigator navigator(make_camera(o.view, sphere, scene.up()), sphere, up);
  Renderer renderer({.page_all = memory_cap > 0, .memory_cap = memory_cap});

  ViewerOptions v;
  v.settings = o.settings;
  v.frame = o.frame;
  v.fps = o.fps;
  v.refine_frames = o.refine;
  v.name = input_names(o.inputs, /*file_names=*/true);
  v.render_command = render_words(cmd, o);
  v.screenshot_dir = o.screenshots;
  v.script = std::move(script);
  v.scripted = !o.events.empty();
  v.log_frames = o.log_frames;
  v.quiet = o.quiet;
  v.start = start;
  const std::unique_ptr<Window> window =
      open_sdl_window("Pointillist \xe2\x80\x94 " + v.name, o.view.width, o.view.height);
  run_viewer(renderer, scene.instances(), navigator, *window, pool, v, stdout);
  return 0;
}

}  // namespace

Command add_view_command(CLI::App& app) {
  auto o = std::make_shared<ViewCommandOptions>();
  auto* cmd = app.add_subcommand(
      "view",
      "Show models (.ptl, .qs, or scans built in memory) or a scene file in a window: drag to "
      "turn, wheel to zoom, keys for the modes (h lists them), s for a screenshot and its render "
      "command");
  cmd->add_option("inputs", o->inputs,
                  "Models or scans (several are shown together), or one scene file (.json)")
      ->required()
      ->check(CLI::ExistingFile);
  add_camera_options(cmd, o->view, o->camera);
  add_enum<Rasterizer>(cmd, "--mode", o->frame.rasterizer,
                       {{"fast", Rasterizer::Fast}, {"quality", Rasterizer::Quality}},
                       "Start in fast or quality mode (key m switches)", "fast")
      ->group(kGroupLook);
  add_enum<SplatShape>(cmd, "--splat", o->settings.shape,
                       {{"square", SplatShape::Square},
                        {"circle", SplatShape::Circle},
                        {"ellipse", SplatShape::Ellipse}},
                       "Splat kernel to start with (key k cycles)", "circle")
      ->group(kGroupLook);
  cmd->add_option("--radius-scale", o->frame.splat_scale,
                  "Draw every splat S times its size (keys plus and minus change it)")
      ->default_val(1.0f)
      ->check(CLI::Range(0.01f, 100.0f))
      ->group(kGroupLook);
  cmd->add_option("--background", o->background, "Background color R,G,B (0-255)")
      ->group(kGroupLook);
  add_edl_and_two_sided(cmd, o->settings, o->edl);
  cmd->add_flag("--features", o->features,
                "Find the sharp features of scans and draw them (stored ones are drawn anyway)")
      ->group(kGroupLook);
  cmd->add_flag("--no-features", o->no_features, "Draw without sharp features (key f switches)")
      ->group(kGroupLook);
  add_enum<LodScheme>(cmd, "--lod", o->frame.lod,
                      {{"qsplat", LodScheme::QSplat}, {"spt", LodScheme::Spt}},
                      "Level-of-detail scheme to start with (key l switches)", "qsplat")
      ->group(kGroupDetail);
  cmd->add_option("--threshold", o->settings.threshold_px,
                  "QSplat full detail: projected splat diameter where refinement stops, pixels")
      ->default_val(1.0f)
      ->check(CLI::Range(0.01f, 1000.0f))
      ->group(kGroupDetail);
  cmd->add_option("--epsilon", o->frame.epsilon_px, "SPT full detail: geometric error, pixels")
      ->default_val(1.0f)
      ->check(CLI::Range(0.001f, 1000.0f))
      ->group(kGroupDetail);
  cmd->add_flag("--hybrid", o->frame.hybrid,
                "Meshes: draw triangles near the eye instead of the points they cover (with "
                "the SPT; key p switches)")
      ->group(kGroupDetail);
  cmd->add_option("--fps", o->fps,
                  "Frame rate held while the camera moves (the detail drops to hold it)")
      ->default_val(30.0)
      ->check(CLI::Range(1.0, 240.0))
      ->group(kGroupDetail);
  cmd->add_option("--refine", o->refine,
                  "Frames from the moving detail to full detail once the camera stops")
      ->default_val(8u)
      ->check(CLI::Range(1u, 1000u))
      ->group(kGroupDetail);
  add_enum<OcclusionMethod>(cmd, "--occlusion", o->frame.occlusion.method,
                            {{"none", OcclusionMethod::None},
                             {"chc++", OcclusionMethod::ChcPlusPlus}},
                            "Occlusion culling to start with (key c switches); models held whole",
                            "none")
      ->group(kGroupDetail);
  cmd->add_flag("--whole", o->whole,
                 "Decode every model whole, also .ptl files over 32 MiB (viewed page by page "
                 "otherwise): slower to open, and SPT and occlusion culling can be switched on")
      ->group(kGroupPaging);
  cmd->add_option("--memory", o->memory,
                  "Draw page by page keeping at most this much of the models in memory (e.g. "
                  "512M); pages stream in on a loader thread while frames keep coming")
      ->group(kGroupPaging);
  constexpr const char* kGroupViewer = "Viewer";
  cmd->add_option("--screenshots", o->screenshots,
                  "Folder for the screenshots of key s (pointillist-view-NNN.png)")
      ->group(kGroupViewer);
  cmd->add_option("--events", o->events,
                  "Play a scripted input file instead of waiting for a person (one event a "
                  "line: wait MS, settle, key NAME, drag left|right|middle X0 Y0 X1 Y1 [FRAMES], "
                  "wheel X Y CLICKS, click BUTTON X Y [COUNT], resize W H, screenshot FILE, "
                  "quit; see README)")
      ->check(CLI::ExistingFile)
      ->group(kGroupViewer);
  cmd->add_option("--log-frames", o->log_frames,
                  "Write one CSV line per frame (time, phase, detail, render and frame ms, "
                  "input latency, splats, resident memory, pages loaded)")
      ->group(kGroupViewer);
  add_prepare_options(cmd, o->prepare, /*with_radius_scale=*/false);
  add_columns(cmd, o->columns);
  add_threads(cmd, o->threads);
  cmd->add_flag("-q,--quiet", o->quiet, "No progress bars, help or screenshot lines");
  return {cmd, [o, cmd] { return run_view(*cmd, *o); }};
}

}  // namespace pointillist::cli
