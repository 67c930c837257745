// The options of `pointillist render`, grouped as --help shows them.
#include <memory>
#include <string>
#include <vector>

#include "commands.hpp"
#include "pointillist/core/error.hpp"
#include "options.hpp"
#include "pointillist/pipeline/model.hpp"

namespace pointillist::cli {
namespace {

// Text options parsed after CLI11 has read the line.
struct RenderText {
  CameraText camera;
  std::string background = "0,0,0", path, memory, read_per_frame;
  bool unlit = false, normal_colors = false;
  std::vector<std::string> edl;  // --edl [STRENGTH]
  bool no_chunk_culling = false;
  bool features = false, no_features = false;
  FeatureOptions feature;
  CLI::Option* sharp_threshold = nullptr;
  std::vector<std::string> chc_off;
};

void add_look(CLI::App* cmd, RenderOptions& o, RenderText& t) {
  add_enum<Rasterizer>(cmd, "--mode", o.frame.rasterizer,
                       {{"fast", Rasterizer::Fast},
                        {"quality", Rasterizer::Quality},
                        {"reference", Rasterizer::Reference}},
                       "fast (opaque splats), quality (perspective-correct Gaussian surface "
                       "splatting with per-pixel shading), or reference (a mesh input's "
                       "triangles, z-buffered, same camera and shading)",
                       "fast")
      ->group(kGroupLook);
  add_enum<SplatShape>(cmd, "--splat", o.settings.shape,
                       {{"square", SplatShape::Square},
                        {"circle", SplatShape::Circle},
                        {"ellipse", SplatShape::Ellipse}},
                       "Splat kernel: square, circle, ellipse", "circle")
      ->group(kGroupLook);
  cmd->add_option("--radius-scale", o.frame.splat_scale,
                  "Draw every splat S times its size (a point-size control; the level of "
                  "detail is unchanged)")
      ->default_val(1.0f)
      ->check(CLI::Range(0.01f, 100.0f))
      ->group(kGroupLook);
  cmd->add_option("--background", t.background, "Background color R,G,B (0-255)")
      ->group(kGroupLook);
  cmd->add_flag("--unlit", t.unlit,
                "Show each splat's own colour, unshaded (ambient 1, no diffuse or specular): "
                "the face colours of generate --scene T*, for compare --labels")
      ->group(kGroupLook);
  cmd->add_flag("--normal-colors", t.normal_colors,
                "Show each pixel's eye-space normal instead of shading it, as (R,G,B) = "
                "255*(n+1)/2 (x right, y up, z toward the viewer): a normal map, for looking at "
                "normals and for compare --normals")
      ->excludes("--unlit")
      ->group(kGroupLook);
  add_edl_and_two_sided(cmd, o.settings, t.edl);
  add_enum<Reconstruction>(cmd, "--reconstruction", o.frame.quality.reconstruction,
                           {{"zrange", Reconstruction::ZRange},
                            {"zthreshold", Reconstruction::ZThreshold}},
                           "With --mode quality: which fragments of a pixel blend, zrange "
                           "(depth intervals overlap) or zthreshold (within a fixed depth of "
                           "the front)",
                           "zrange")
      ->group(kGroupLook);
  cmd->add_option("--opacity", o.frame.quality.opacity,
                  "With --mode quality: opacity of every surface, composited front to back "
                  "(1 = opaque)")
      ->default_val(1.0f)
      ->check(CLI::Range(0.001f, 1.0f))
      ->group(kGroupLook);
}

void add_features(CLI::App* cmd, RenderText& t) {
  constexpr const char* kGroup = "Sharp edges and intersecting surfaces";
  cmd->add_flag("--features", t.features,
                "Find sharp edges, corners and intersecting surfaces of the models held whole "
                "and draw them: discs clipped at creases, each pixel blended from one surface")
      ->group(kGroup);
  cmd->add_flag("--no-features", t.no_features, "Draw without the sharp features (to compare)")
      ->group(kGroup);
  t.sharp_threshold = add_sharp_threshold(cmd, t.feature)->group(kGroup);
  add_enum<EdgeTest>(cmd, "--edge-test", t.feature.edge_test,
                     {{"side", EdgeTest::Side}, {"linsen", EdgeTest::Linsen}},
                     "With --features: how a crease is told from an intersection: side (per "
                     "pair, whether the surface lies on both sides of the other's plane) or "
                     "linsen (the dissertation's angular gap test)",
                     "side")
      ->group(kGroup);
  add_enum<ClipRule>(cmd, "--clip-rule", t.feature.clip_rule,
                     {{"classified", ClipRule::Classified},
                      {"dissertation", ClipRule::Dissertation},
                      {"independent", ClipRule::Independent},
                      {"nearest", ClipRule::NearestPartner}},
                     "With --features: how several clip planes combine: classified "
                     "(Pointillist's rule), dissertation (Ivo's eqs. 4.13-4.15), independent "
                     "(each plane on its own) or nearest (the nearest partner only)",
                     "classified")
      ->group(kGroup);
}

void add_occlusion(CLI::App* cmd, RenderOptions& o, RenderText& t) {
  constexpr const char* kGroup = "Occlusion culling";
  OcclusionSettings& oc = o.frame.occlusion;
  add_enum<OcclusionMethod>(cmd, "--occlusion", oc.method,
                            {{"none", OcclusionMethod::None},
                             {"stop-and-wait", OcclusionMethod::StopAndWait},
                             {"chc", OcclusionMethod::Chc},
                             {"chc++", OcclusionMethod::ChcPlusPlus}},
                            "Skip what is hidden behind what is already drawn (the same image): "
                            "none, stop-and-wait (query each node and wait), chc (coherent "
                            "hierarchical culling) or chc++ (with batched queries, multiqueries, "
                            "spread re-queries and tight bounds). Fast and quality modes (quality: opaque, "
                            "without sharp features); a paged model is culled whole",
                            "none")
      ->group(kGroup);
  cmd->add_option("--query-latency", oc.query_latency,
                  "With --occlusion: a query's answer is usable only after K more flushes of "
                  "the render queue (emulates a GPU's latency; 0 = at once)")
      ->default_val(0u)
      ->check(CLI::Range(0u, 1000u))
      ->group(kGroup);
  cmd->add_option("--cull-leaf", oc.leaf_points,
                  "With --occlusion: cull each model's hierarchy down to subtrees of at most N "
                  "points")
      ->default_val(4096u)
      ->check(CLI::Range(1u, 1u << 30))
      ->group(kGroup);
  cmd->add_option("--chc-batch", oc.batch,
                  "With --occlusion chc++: previously hidden nodes queried together (R1)")
      ->default_val(50u)
      ->check(CLI::Range(1u, 100000u))
      ->group(kGroup);
  cmd->add_option("--chc-requery", oc.requery_frames,
                  "With --occlusion chc or chc++: frames between queries of a visible leaf")
      ->default_val(5u)
      ->check(CLI::Range(0u, 100000u))
      ->group(kGroup);
  cmd->add_option("--chc-doublings", oc.requery_doublings,
                  "With --occlusion chc++: a visible leaf's re-query interval doubles after each "
                  "query that finds it still visible, up to this many times (0: the paper's "
                  "fixed interval)")
      ->default_val(2u)
      ->check(CLI::Range(0u, 16u))
      ->group(kGroup);
  cmd->add_option("--chc-off", t.chc_off,
                  "With --occlusion chc++: switch rules off (to measure them): batching, "
                  "multiqueries, split, random, tight")
      ->delimiter(',')
      ->check(CLI::IsMember({"batching", "multiqueries", "split", "random", "tight"}))
      ->group(kGroup);
}

void add_detail(CLI::App* cmd, RenderOptions& o, RenderText& t) {
  add_enum<LodScheme>(cmd, "--lod", o.frame.lod,
                      {{"qsplat", LodScheme::QSplat}, {"spt", LodScheme::Spt}},
                      "Level-of-detail scheme: qsplat (hierarchy traversal) or spt (Sequential "
                      "Point Tree, one sequential pass)",
                      "qsplat")
      ->group(kGroupDetail);
  cmd->add_option("--threshold", o.settings.threshold_px,
                  "QSplat: stop refining at this projected splat diameter, pixels")
      ->default_val(1.0f)
      ->check(CLI::Range(0.01f, 1000.0f))
      ->group(kGroupDetail);
  cmd->add_option("--epsilon", o.frame.epsilon_px,
                  "With --lod spt: allowed geometric error in pixels (1 = full detail)")
      ->default_val(1.0f)
      ->check(CLI::Range(0.001f, 1000.0f))
      ->group(kGroupDetail);
  cmd->add_flag("--no-chunk-culling", t.no_chunk_culling,
                "With --lod spt: scan every chunk's list even when the chunk is outside the "
                "view (to measure what chunk culling saves)")
      ->group(kGroupDetail);
  cmd->add_flag("--hybrid", o.frame.hybrid,
                "With --lod spt, for meshes: draw the mesh's triangles near the eye instead of "
                "the points they cover (hybrid point/polygon rendering)")
      ->group(kGroupDetail);
  cmd->add_option("--triangle-px", o.frame.triangle_px_per_epsilon,
                  "With --hybrid: a triangle replaces points while its longest edge is longer "
                  "than this many times --epsilon pixels")
      ->default_val(4.0f)
      ->check(CLI::Range(0.01f, 10000.0f))
      ->group(kGroupDetail);
}

void add_sequences_and_paging(CLI::App* cmd, RenderOptions& o, RenderText& t) {
  cmd->add_option("--path", t.path,
                  "Render a sequence of frames along a camera path: orbit:N = N frames around "
                  "the model (azimuth +0..360 degrees from --view), or a camera path file (one "
                  "frame a line: eye x y z, target x y z [, up x y z]; an optional 'fov DEG' "
                  "line, which --fov overrides)")
      ->group(kGroupSequence);
  cmd->add_option("--frame-ms", o.frame_ms,
                  "With --path: adjust the level of detail frame to frame to hold T ms per frame")
      ->check(CLI::Range(0.1, 100000.0))
      ->group(kGroupSequence);
  cmd->add_option("--refine", o.refine_frames,
                  "Then render K frames refining to full detail, as a viewer does when the "
                  "camera stops")
      ->check(CLI::Range(1u, 100000u))
      ->group(kGroupSequence);
  cmd->add_option("--frames-out", o.frames_out,
                  "Write every frame of a sequence to DIR/frame_NNNNN.png")
      ->group(kGroupSequence);
  cmd->add_option("--memory", t.memory,
                  "Render page by page keeping at most this much of the model in memory (e.g. "
                  "512M); coarser where the cap bites")
      ->group(kGroupPaging);
  cmd->add_option("--progressive", o.progressive_frames,
                  "Render N frames at the view while the model's pages load, as a viewer shows "
                  "a model streaming in")
      ->check(CLI::Range(1u, 100000u))
      ->group(kGroupPaging);
  cmd->add_option("--read-per-frame", t.read_per_frame,
                  "With --progressive: bytes of the model read between two frames (default 1M, "
                  "a disk at 30 MB/s shown at 30 frames/s)")
      ->group(kGroupPaging);
}

// Options given that cannot apply to this command line, as warnings.
std::vector<std::string> ignored_options(const CLI::App& cmd, const RenderOptions& o,
                                         const RenderText& t) {
  std::vector<std::string> w;
  const auto given = [&](const char* name) { return cmd.count(name) > 0; };
  const auto ignored = [&](const char* name, const std::string& why) {
    if (given(name)) w.push_back(std::string(name) + " is ignored: " + why);
  };
  const bool spt = o.frame.lod == LodScheme::Spt;
  const bool quality = o.frame.rasterizer == Rasterizer::Quality;
  if (o.frame.occlusion.method == OcclusionMethod::None) {
    for (const char* name : {"--query-latency", "--cull-leaf", "--chc-batch", "--chc-requery",
                             "--chc-doublings", "--chc-off"}) {
      ignored(name, "it applies with --occlusion");
    }
  } else if (o.frame.occlusion.method != OcclusionMethod::ChcPlusPlus) {
    for (const char* name : {"--chc-batch", "--chc-doublings", "--chc-off"}) {
      ignored(name, "it applies with --occlusion chc++");
    }
  }
  if (spt) ignored("--threshold", "it is the QSplat traversal's detail; --lod spt uses --epsilon");
  if (!spt) {
    ignored("--epsilon", "it is the Sequential Point Tree's detail; add --lod spt");
    ignored("--no-chunk-culling", "it applies to --lod spt");
  }
  if (!o.frame.hybrid) ignored("--triangle-px", "it applies with --hybrid");
  if (!t.features) {
    for (const char* name : {"--sharp-threshold", "--edge-test", "--clip-rule"}) {
      ignored(name, "it applies with --features");
    }
  }
  if (!quality) {
    ignored("--reconstruction", "it applies to --mode quality");
    ignored("--opacity", "it applies to --mode quality");
  }
  if (o.progressive_frames == 0) ignored("--read-per-frame", "it applies to --progressive");
  bool all_models = true;
  for (const std::string& in : o.inputs) all_models = all_models && is_model_file(in);
  if (all_models) {
    for (const char* name : {"--normals", "--k", "--drop-outliers", "--outlier-ratio",
                             "--columns"}) {
      ignored(name, "it prepares scans, and the inputs are splat models");
    }
  }
  if (!t.camera.eye.empty() || !t.camera.target.empty()) {
    ignored("--view", "--eye/--target place the camera");
    ignored("--distance", "--eye/--target place the camera");
  } else if (!t.path.empty() && !is_orbit_path(t.path)) {
    ignored("--view", "the camera path file places the camera");
    ignored("--distance", "the camera path file places the camera");
  }
  return w;
}

}  // namespace

Command add_render_command(CLI::App& app) {
  auto o = std::make_shared<RenderOptions>();
  auto t = std::make_shared<RenderText>();
  auto* cmd = app.add_subcommand(
      "render", "Render models (.ptl, .qs, or scans built in memory) or a scene file to PNG");
  cmd->add_option("inputs", o->inputs,
                  "Models or scans (several are drawn together), or one scene file (.json)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("-o,--output", o->output, "Output PNG")->required()->group(kGroupOutput);
  cmd->add_option("--depth", o->depth_output,
                  "Also write the depth image: D.png 16-bit, scaled to the frame's depth range; "
                  "D.pfm float depth along the view direction in scene units (compare --depth)")
      ->group(kGroupOutput);
  cmd->add_option("--stats", o->stats_output, "Write statistics as JSON (- = stdout)")
      ->group(kGroupOutput);
  add_camera_options(cmd, o->view, t->camera);
  add_look(cmd, *o, *t);
  add_detail(cmd, *o, *t);
  add_features(cmd, *t);
  add_occlusion(cmd, *o, *t);
  add_sequences_and_paging(cmd, *o, *t);
  add_prepare_options(cmd, o->prepare, /*with_radius_scale=*/false);
  add_columns(cmd, o->columns);
  add_threads(cmd, o->threads);
  cmd->add_flag("-q,--quiet", o->quiet, "No progress bars and no summary");
  return {cmd, [o, t, cmd] {
            o->warnings = ignored_options(*cmd, *o, *t);
            o->frame.spt_chunk_culling = !t->no_chunk_culling;
            if (t->features && t->no_features) {
              throw OptionError("--features and --no-features contradict each other; give one");
            }
            if (t->features) {
              t->feature.radius_scale = o->frame.quality.radius_scale;
              t->feature.adapt_threshold = t->sharp_threshold->count() == 0;
              o->features = t->feature;
            }
            o->frame.features = !t->no_features;
            for (const std::string& rule : t->chc_off) {
              OcclusionSettings& oc = o->frame.occlusion;
              (rule == "batching"       ? oc.batching
               : rule == "multiqueries" ? oc.multiqueries
               : rule == "split"        ? oc.split_failed
               : rule == "random"       ? oc.randomized
                                        : oc.tight_bounds) = false;
            }
            parse_camera_options(t->camera, o->view);
            o->settings.background = parse_rgb8(t->background, "--background");
            if (cmd->count("--edl") > 0) o->settings.edl_strength = parse_edl(t->edl);
            if (t->normal_colors) {
              if (o->settings.edl_strength > 0) {
                throw OptionError("--normal-colors draws normals, which eye-dome lighting would "
                                  "darken; leave out --edl");
              }
              o->settings.normal_colors = true;
            }
            if (t->unlit) {
              o->settings.ambient = 1.0f;
              o->settings.diffuse = 0.0f;
              o->settings.specular = 0.0f;
            }
            if (is_orbit_path(t->path)) {
              o->orbit_frames = parse_orbit_path(t->path);
            } else if (!t->path.empty()) {
              o->path_file = checked_path_file(t->path);
            }
            o->fov_given = cmd->count("--fov") > 0;
            if (!t->memory.empty()) o->memory_cap = parse_bytes(t->memory, "--memory");
            if (!t->read_per_frame.empty()) {
              o->read_per_frame = parse_bytes(t->read_per_frame, "--read-per-frame");
            }
            return run_render(*o);
          }};
}

}  // namespace pointillist::cli
