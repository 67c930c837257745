// The `pointillist` subcommands: options structs filled by main.cpp, and the functions that run
// them. Each returns the process exit code; errors are thrown as pointillist::Error.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "pointillist/core/camera.hpp"
#include "pointillist/lod/quantization.hpp"
#include "pointillist/pipeline/convert.hpp"
#include "pointillist/prep/prepare.hpp"
#include "pointillist/render/quality.hpp"
#include "pointillist/render/render.hpp"
#include "pointillist/render/renderer.hpp"

namespace CLI {
class App;
}

namespace pointillist::cli {

// A subcommand registered on the command line: its CLI11 app (options bound to an options
// struct it owns) and what runs it once the line is parsed (returns the exit code).
struct Command {
  CLI::App* app = nullptr;
  std::function<int()> run;
};
Command add_convert_command(CLI::App& app);
// The MPI job this process belongs to when started by mpirun (set by main), or null.
ChunkJobs*& mpi_job();
Command add_render_command(CLI::App& app);
Command add_info_command(CLI::App& app);
Command add_demo_command(CLI::App& app);
Command add_generate_command(CLI::App& app);
Command add_compare_command(CLI::App& app);
Command add_view_command(CLI::App& app);
Command add_simplify_command(CLI::App& app);
Command add_compare_surface_command(CLI::App& app);

struct ConvertCommandOptions {
  std::vector<std::string> inputs;
  std::string output;
  ConvertOptions convert;  // what pipeline::convert does
  unsigned threads = 0;
  bool quiet = false;
};
int run_convert(const ConvertCommandOptions& options);

struct ViewOptions {
  int width = 1280, height = 720;
  float azimuth_deg = 0, elevation_deg = 0;
  float distance = 0;  // 0 = automatic
  float fov_deg = 30;
  float ortho_height = 0;  // > 0: orthographic, this many world units from top to bottom
  std::optional<Vec3f> eye, target, up;
};

struct RenderOptions {
  // Models or scans (drawn together in their shared world frame), or one scene file (.json).
  std::vector<std::string> inputs;
  std::string output;
  ViewOptions view;
  RenderSettings settings;
  FrameSettings frame;  // --lod, --epsilon, --no-chunk-culling, --mode, --reconstruction, --opacity
  std::string depth_output;  // empty = no depth image
  std::string stats_output;  // empty = none, "-" = stdout
  PrepareOptions prepare;    // for point/mesh file inputs (built in memory)
  std::string columns;       // --columns for text inputs
  unsigned threads = 0;
  bool quiet = false;
  // Frame sequences (see README "Frame sequences"): 0 = off.
  unsigned orbit_frames = 0;  // --path orbit:N
  std::string path_file;      // --path FILE: a camera path file (io/camera_path.hpp)
  bool fov_given = false;     // --fov was on the command line (it wins over a path file's fov)
  double frame_ms = 0;        // --frame-ms T: hold this frame time
  unsigned refine_frames = 0; // --refine K
  std::string frames_out;     // --frames-out DIR: write every frame there
  // Paged rendering (README "Models larger than memory"): 0 = off / no cap.
  std::uint64_t memory_cap = 0;     // --memory BYTES
  unsigned progressive_frames = 0;  // --progressive N
  std::uint64_t read_per_frame = 1u << 20;  // --read-per-frame BYTES (progressive loading)
  std::vector<std::string> warnings;  // options given that do not apply (printed by run_render)
  // Sharp features (README "Sharp edges and intersecting surfaces"): compute them in memory.
  std::optional<FeatureOptions> features;
};
int run_render(const RenderOptions& options);

// The camera of `view` for a model or scene: the orbit around `view_sphere` keeping `model_up`
// up (unless --up says otherwise), or the explicit eye/target/up. Throws OptionError when only
// one of --eye/--target is given.
Camera make_camera(const ViewOptions& view, const Sphere& view_sphere,
                   Vec3f model_up = {0, 1, 0});

struct InfoOptions {
  std::string input;
  std::string columns;     // --columns for text inputs
  unsigned threads = 0;
  bool spt = false;        // --spt: build the Sequential Point Tree and report its list
  bool features = false;   // --features: compute the sharp features and report them
  FeatureOptions feature;
  ViewOptions view;        // for the SPT report: the view whose scanned fraction is given
  float epsilon_px = 1.0f;
};
int run_info(const InfoOptions& options);

struct DemoOptions {
  std::string out_dir = "demo-out";
  std::size_t points = 400'000;
  unsigned threads = 0;
  bool quiet = false;
};
int run_demo(const DemoOptions& options);

struct GenerateOptions {
  std::string output;
  std::string scene = "demo";  // demo, sphere, torus, cube; T*; wall, city, field, row
  std::size_t points = 1'000'000;
  bool points_given = false;  // --points given (wall|city|field|row: else a 20,000-point statue)
  // wall|city|field|row (pipeline/generate_scene.hpp): the scanned models, and the factor on
  // the wall's and panels' grid spacing.
  std::vector<std::string> models;
  float spacing_scale = 1.0f;
  std::uint64_t seed = 1;
  bool with_normals = false;  // write the exact normals too
  bool colors = false;        // write colours from the exact normals (analytic scenes)
  std::string sampling = "j";  // test scenes T*: j or r
  // Test scenes T*: also write the exact label image here (empty = none), seen with `view` (as
  // `render` would see the written .ply) on `background`.
  std::string reference_output;
  std::string reference_depth_output;  // with it: its depth (PFM, scene units; empty = none)
  std::string reference_normals_output;  // with it: its normals (PNG, normal colours; empty = none)
  ViewOptions view;
  Rgb8 background{0, 0, 0};
  std::vector<std::string> warnings;  // options given that do not apply (printed by run_generate)
  unsigned threads = 0;
  bool quiet = false;
};
int run_generate(const GenerateOptions& options);

struct CompareOptions {
  std::string reference;
  std::string test;
  std::optional<Rgb8> background;  // unset = the reference's top-left pixel
  std::string json_output;         // empty = none, "-" = stdout (instead of the text)
  bool labels = false;             // --labels: the label metrics too (eval/label_metrics.hpp)
  int label_tolerance = 2;         // levels per channel at which a pixel still shows a face
  // --labels --depth REF.pfm TEST.pfm --see-through-gap G: the SEE-THROUGH count.
  std::vector<std::string> depth_images;
  float see_through_gap = 0;
  // --labels --normals REF.png TEST.png: the NORMAL ERROR (normal colours).
  std::vector<std::string> normal_images;
};
int run_compare(const CompareOptions& options);

}  // namespace pointillist::cli
