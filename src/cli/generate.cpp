// `pointillist generate`: point clouds sampled from the analytic scenes, the sharp-features
// test scenes with their exact label reference image, and the occlusion-culling scenes of many
// instances (scene file, models, camera paths).
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "commands.hpp"
#include "options.hpp"
#include "terminal_progress.hpp"
#include "util.hpp"
#include "pointillist/core/atomic_file.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/core/normal_color.hpp"
#include "pointillist/io/ply.hpp"
#include "pointillist/io/pfm.hpp"
#include "pointillist/io/png.hpp"
#include "pointillist/pipeline/generate_scene.hpp"
#include "pointillist/prep/radii.hpp"
#include "pointillist/scene/analytic.hpp"
#include "pointillist/scene/csg.hpp"

namespace pointillist::cli {

namespace {

// The exact ray-cast image of the scene, unlit: each pixel the palette colour of its face's
// surface (`group`, csg_surface_groups), the background where the ray misses. The camera is the one `render` builds for the generated
// .ply with the same camera options: the orbit around the samples' view sphere (the centre of
// their bounding box and the largest distance to a sample, as the hierarchy built from the file
// computes it), +Y up (the samples record no other up axis).
struct Reference {
  std::vector<Rgb8> pixels;
  std::vector<float> depth;  // along the view direction, +inf where the ray misses
  std::vector<Rgb8> normals; // encode_normal_color of the eye-space normal, background on misses
};
Reference reference_image(const GenerateOptions& o, const CsgScene& scene,
                          const PointSet& samples, std::span<const std::uint32_t> group) {
  const Camera camera = make_camera(o.view, view_sphere(samples.positions), samples.up);
  CsgImage image = ray_cast_csg_image(scene, camera);
  const CameraFrame eye = make_camera_frame(camera);
  std::vector<Rgb8> pixels(image.label.size(), o.background), normals(pixels);
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    if (image.label[i] == kNoLabel) continue;
    pixels[i] = kLabelPalette[group[image.label[i]] % 8];
    normals[i] = encode_normal_color(eye.eye_direction(image.normal[i]));
  }
  return {std::move(pixels), std::move(image.depth), std::move(normals)};
}

// A CSG test scene of the sharp-features spec: exact normals, a colour per face; J-mode samples
// also get the dissertation's radius (the mean distance to the 5 nearest), R-mode ones none
// (scan preparation gives them Pointillist's default).
int generate_csg(const GenerateOptions& o) {
  const CsgScene scene = csg_scene(o.scene);
  const bool jittered = o.sampling == "j";
  CsgSamples s = sample_csg(scene, jittered ? SamplingMode::Jittered : SamplingMode::Random, o.seed);
  // A colour per surface of the result: faces of two primitives on one plane (the step's front)
  // are one surface, so they share it, as they blend when drawn.
  const std::vector<std::uint32_t> group = csg_surface_groups(scene, s);
  for (std::uint32_t label : s.labels) s.points.colors.push_back(kLabelPalette[group[label] % 8]);
  if (jittered) {
    ThreadPool pool(o.threads);
    CloudRadiusOptions radius;
    radius.coverage = 1.0f;
    s.points.radii = cloud_radii(s.points.positions, pool, Progress::none(), radius);
  }
  // The image first: a bad camera option then leaves no file behind.
  const Reference reference =
      o.reference_output.empty() ? Reference{} : reference_image(o, scene, s.points, group);
  write_ply(o.output, s.points);
  if (!o.reference_output.empty()) {
    write_png_rgb8(o.reference_output, o.view.width, o.view.height, reference.pixels);
  }
  if (!o.reference_depth_output.empty()) {
    write_pfm(o.reference_depth_output, o.view.width, o.view.height, reference.depth);
  }
  if (!o.reference_normals_output.empty()) {
    write_png_rgb8(o.reference_normals_output, o.view.width, o.view.height, reference.normals);
  }
  if (!o.quiet) {
    char normals[96] = "exact normals";
    if (scene.normal_noise_degrees > 0 || scene.position_noise > 0) {
      std::snprintf(normals, sizeof normals, "normals tilted by %g degrees and positions by %g h (sigma)",
                    scene.normal_noise_degrees, scene.position_noise);
    }
    std::printf("generated %zu samples of test scene %s (%s sampling, %s, a colour per face) -> "
                "%s\n",
                s.points.size(), o.scene.c_str(), jittered ? "jittered grid" : "random", normals,
                o.output.c_str());
    if (!o.reference_output.empty()) {
      std::printf("exact label reference (ray cast, unlit, a colour per face) %dx%d -> %s\n",
                  o.view.width, o.view.height, o.reference_output.c_str());
    }
    if (!o.reference_normals_output.empty()) {
      std::printf("exact normals (eye space, normal colours) -> %s\n",
                  o.reference_normals_output.c_str());
    }
  }
  return 0;
}

bool is_occlusion_scene(const std::string& scene) {
  return scene == "wall" || scene == "city" || scene == "field" || scene == "row";
}

// A scene of many instances for occlusion culling: the scene file, its models and camera paths.
int generate_occlusion_scene(const GenerateOptions& o) {
  GenerateSceneOptions g;
  g.scene = o.scene == "wall"   ? OcclusionScene::Wall
            : o.scene == "city" ? OcclusionScene::City
            : o.scene == "field" ? OcclusionScene::Field
                                 : OcclusionScene::Row;
  g.output = o.output;
  g.models = o.models;
  g.statue_points = o.points_given ? o.points : GenerateSceneOptions{}.statue_points;
  g.seed = o.seed;
  g.spacing_scale = o.spacing_scale;
  ThreadPool pool(o.threads);
  TerminalProgress progress(!o.quiet && TerminalProgress::stderr_is_terminal());
  const GeneratedScene r = generate_scene(g, pool, progress);
  if (o.quiet) return 0;
  std::string models, paths;
  for (const GeneratedModel& m : r.models) {
    models += (models.empty() ? "" : ", ") + m.path + " " + std::to_string(m.points) +
              " points x" + std::to_string(m.instances);
  }
  for (std::size_t i = 0; i < r.path_files.size(); ++i) {
    paths += (paths.empty() ? "" : ", ") +
             std::filesystem::path(r.path_files[i]).filename().string() + " " +
             std::to_string(r.path_frames[i]) + " frames";
  }
  std::printf("generated the %s scene: %zu instances, %zu of them scanned models; models: %s; "
              "paths: %s -> %s\n",
              o.scene.c_str(), r.instance_count, r.scanned_instance_count, models.c_str(),
              paths.c_str(), o.output.c_str());
  return 0;
}

void check_options(const GenerateOptions& o) {
  check_outputs({}, {{"-o", o.output},
                     {"--reference", o.reference_output},
                     {"--reference-depth", o.reference_depth_output},
                     {"--reference-normals", o.reference_normals_output}});
  if (!o.reference_normals_output.empty()) {
    if (o.reference_output.empty()) {
      throw OptionError("--reference-normals writes the normals of the --reference image; give "
                        "--reference R.png too");
    }
    if (lowercase_extension(o.reference_normals_output) != ".png") {
      throw OptionError("--reference-normals " + o.reference_normals_output +
                        ": the normal image is a PNG (render --normal-colors' encoding); give a "
                        "path ending in .png");
    }
  }
  if (!o.reference_depth_output.empty()) {
    if (o.reference_output.empty()) {
      throw OptionError("--reference-depth writes the depth of the --reference image; give "
                        "--reference R.png too");
    }
    const std::string ext = lowercase_extension(o.reference_depth_output);
    if (ext != ".pfm") {
      throw OptionError("--reference-depth " + o.reference_depth_output +
                        ": the depth image is a PFM (float depth in scene units); give a path "
                        "ending in .pfm");
    }
  }
  if (is_occlusion_scene(o.scene) && !o.reference_output.empty()) {
    throw OptionError("--reference writes the exact image of a sharp-features test scene (T*); "
                      "it does not apply to --scene " + o.scene);
  }
  if (o.reference_output.empty()) return;
  if (o.scene.empty() || o.scene[0] != 'T') {
    throw OptionError("--reference writes the exact label image of a sharp-features test scene; "
                      "give --scene T1 (or another T*), not '" + o.scene + "'");
  }
  const std::string ext = lowercase_extension(o.reference_output);
  if (ext != ".png") {
    throw OptionError("--reference " + o.reference_output +
                      ": the reference is a PNG image; give a path ending in .png");
  }
}

}  // namespace

int run_generate(const GenerateOptions& o) {
  keep_freed_memory();
  check_options(o);
  for (const std::string& w : o.warnings) {
    std::fprintf(stderr, "pointillist generate: warning: %s\n", w.c_str());
  }
  if (!o.scene.empty() && o.scene[0] == 'T') return generate_csg(o);
  if (is_occlusion_scene(o.scene)) return generate_occlusion_scene(o);
  AnalyticScene scene;
  if (o.scene == "demo") {
    scene = demo_scene();
  } else if (o.scene == "sphere") {
    scene = sphere_scene();
  } else if (o.scene == "torus") {
    scene = torus_scene();
  } else if (o.scene == "cube") {
    scene = cube_scene();
  } else {
    throw OptionError("generate: unknown scene '" + o.scene + "'; use demo, sphere, torus or cube");
  }
  // Batches of 16 M samples (constant memory, any count): the first from --seed, so clouds up
  // to 16 M points are those one draw gives; each further batch from a seed of its own.
  constexpr std::size_t kBatch = std::size_t{16} << 20;
  const std::uint64_t record = 12 + (o.with_normals ? 12 : 0) + (o.colors ? 3 : 0);
  {
    std::error_code error;
    const std::filesystem::path folder =
        std::filesystem::absolute(std::filesystem::path(o.output)).parent_path();
    const auto space = std::filesystem::space(folder, error);
    const std::uint64_t need = record * o.points + 4096;
    if (!error && space.available < need) {
      throw IoError(o.output + ": " + std::to_string(o.points) + " points need about " +
                    std::to_string(need / 1000000) + " MB, and " +
                    std::to_string(space.available / 1000000) +
                    " MB are free there; free some space or write to another disk");
    }
  }
  PointSet layout;
  layout.positions.resize(1);
  if (o.with_normals) layout.normals.resize(1);
  if (o.colors) layout.colors.resize(1);
  PlyPointWriter writer(o.output, layout, o.points);
  TerminalProgress progress(!o.quiet && o.points > kBatch &&
                            TerminalProgress::stderr_is_terminal());
  {
    ProgressPhase phase(progress, "generate", o.points);
    for (std::size_t first = 0, b = 0; first < o.points; first += kBatch, ++b) {
      const std::uint64_t seed = b == 0 ? o.seed : o.seed ^ (b * 0x9E3779B97F4A7C15ull);
      SurfaceSamples samples = sample_scene(scene, std::min(kBatch, o.points - first), seed);
      if (o.with_normals) samples.points.normals = samples.true_normals;
      if (o.colors) {
        // Colour by the exact normal: smooth, different on every face.
        samples.points.colors.reserve(samples.points.size());
        for (const Vec3f& n : samples.true_normals) {
          samples.points.colors.push_back({std::uint8_t(127.5f + 127.0f * n.x),
                                           std::uint8_t(127.5f + 127.0f * n.y),
                                           std::uint8_t(127.5f + 127.0f * n.z)});
        }
      }
      writer.write(samples.points);
      phase.advance(samples.points.size());
    }
  }
  writer.commit();
  if (!o.quiet) {
    std::printf("generated %zu samples of the %s scene%s%s -> %s\n", o.points, o.scene.c_str(),
                o.with_normals ? " with exact normals" : "", o.colors ? " and colours" : "",
                o.output.c_str());
  }
  return 0;
}

Command add_generate_command(CLI::App& app) {
  auto o = std::make_shared<GenerateOptions>();
  auto* cmd = app.add_subcommand(
      "generate", "Write a point cloud sampled from an analytic scene (for tests and benchmarks), "
                  "or a scene of many instances with its models and camera paths");
  cmd->add_option("-o,--output", o->output,
                  "Output .ply; for wall, city, field and row the scene file DIR/NAME.json (its "
                  "models and camera path files are written beside it)")
      ->required();
  std::vector<std::string> scenes = {"demo", "sphere", "torus", "cube"};
  for (const std::string& id : csg_scene_ids()) scenes.push_back(id);
  for (const char* id : {"T12", "T14"}) scenes.push_back(id);  // T12-90, T14-2
  for (const char* id : {"wall", "city", "field", "row"}) scenes.push_back(id);
  cmd->add_option("--scene", o->scene,
                  "demo, sphere, torus or cube; or a sharp-features test scene T1 (cube), T2 "
                  "(cube of mixed density), T3 (cylinder), T4 (plate with a hole), T5/T6 "
                  "(union/intersection of two spheres), T7 (bitten cube), T8 (step), T9 (two "
                  "interpenetrating spheres), T10 (crossed cylinders), T11 (thin slab), "
                  "T12-20|30|45|60|90|120|150|165 (wedge of two strips at that dihedral angle), "
                  "T13 (sphere), T14-2|5 (cube with 2 or 5 degrees of normal noise), T15 (open "
                  "crease); or a scene of many instances for occlusion culling: wall, city, "
                  "field, row")
      ->default_val("demo")
      ->check(CLI::IsMember(scenes));
  cmd->add_option("--models", o->models,
                  "wall|city|field|row: the scanned models A,B,C (.ptl, .qs or scans), used in "
                  "turn, each scaled to radius 1 and stood on y = 0 (default: a generated "
                  "statue of --points points, 20000 unless given)")
      ->delimiter(',');
  cmd->add_option("--spacing-scale", o->spacing_scale,
                  "wall|city: multiply the grid spacing of the wall and the facade panels "
                  "(1 = the specification's 0.02 and 0.05; 10 makes them 100 times smaller)")
      ->default_val(1.0f)
      ->check(CLI::Range(0.01f, 1000.0f));
  cmd->add_option("--sampling", o->sampling,
                  "Test scenes T*: j (jittered grid at the scene's spacing, radius = mean "
                  "distance to 5 nearest) or r (as many random samples, default radii)")
      ->default_val("j")
      ->check(CLI::IsMember({"j", "r"}));
  cmd->add_option("--points", o->points,
                  "Number of samples (test scenes T*: set by the scene; wall|city|field|row: of "
                  "the generated statue, default 20000)")
      ->default_val(1000000)
      ->check(CLI::Range(std::size_t{1}, std::size_t{2'000'000'000}));
  cmd->add_option("--seed", o->seed, "Random seed")->default_val(1);
  cmd->add_flag("--with-normals", o->with_normals, "Also write exact normals");
  cmd->add_flag("--colors", o->colors,
                "Also write colours (from the exact normal); demo, sphere, torus, cube");
  cmd->add_option("--reference", o->reference_output,
                  "Test scenes T*: also write the exact ray-cast image of the scene, unlit, each "
                  "pixel its face's colour, with the camera `render` uses for the .ply and the "
                  "same camera options")
      ->group(kGroupOutput);
  cmd->add_option("--reference-depth", o->reference_depth_output,
                  "With --reference: also its depth along the view direction, a PFM in scene "
                  "units (compare --labels --depth)")
      ->group(kGroupOutput);
  cmd->add_option("--reference-normals", o->reference_normals_output,
                  "With --reference: also its exact normals as render --normal-colors draws "
                  "them, a PNG (compare --labels --normals)")
      ->group(kGroupOutput);
  auto camera = std::make_shared<CameraText>();
  add_camera_options(cmd, o->view, *camera);
  auto background = std::make_shared<std::string>("0,0,0");
  cmd->add_option("--background", *background,
                  "With --reference: background color R,G,B (0-255; render's default 0,0,0)")
      ->group(kGroupCamera);
  add_threads(cmd, o->threads);
  cmd->add_flag("-q,--quiet", o->quiet, "No summary line");
  return {cmd, [o, camera, background, cmd] {
            parse_camera_options(*camera, o->view);
            o->background = parse_rgb8(*background, "--background");
            o->points_given = cmd->count("--points") > 0;
            const bool occlusion = is_occlusion_scene(o->scene);
            if (!occlusion && cmd->count("--models") > 0) {
              o->warnings.push_back("--models is ignored: it applies to --scene "
                                    "wall|city|field|row");
            }
            if (o->scene != "wall" && o->scene != "city" && cmd->count("--spacing-scale") > 0) {
              o->warnings.push_back("--spacing-scale is ignored: it applies to --scene wall|city "
                                    "(the scenes with grid models)");
            }
            if (occlusion && cmd->count("--models") > 0 && cmd->count("--points") > 0) {
              o->warnings.push_back("--points is ignored: it sizes the generated statue, and "
                                    "--models gives the models");
            }
            if (cmd->count("--colors") > 0 && (occlusion || o->scene[0] == 'T')) {
              o->warnings.push_back("--colors is ignored: it applies to --scene demo|sphere|"
                                    "torus|cube (the test scenes colour each face)");
            }
            if (occlusion) {
              for (const char* name : {"--with-normals", "--sampling"}) {
                if (cmd->count(name) > 0) {
                  o->warnings.push_back(std::string(name) + " is ignored: it applies to point "
                                        "clouds, not to --scene " + o->scene);
                }
              }
            }
            if (o->reference_output.empty()) {
              for (const char* name : {"--size", "--view", "--distance", "--fov", "--eye",
                                       "--target", "--up", "--background"}) {
                if (cmd->count(name) > 0) {
                  o->warnings.push_back(std::string(name) +
                                        " is ignored: it applies to the --reference image");
                }
              }
            }
            return run_generate(*o);
          }};
}

}  // namespace pointillist::cli
