// Writes an occlusion-culling acceptance scene (occlusion_scenes.hpp) to disk: the scene file,
// the models it generates (.ptl files built like `convert` builds them) and its camera path
// files, all beside each other.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "pointillist/core/progress.hpp"
#include "pointillist/core/thread_pool.hpp"
#include "pointillist/pipeline/occlusion_scenes.hpp"

namespace pointillist {

struct GenerateSceneOptions {
  OcclusionScene scene = OcclusionScene::Wall;
  // The scene file, DIR/NAME.json. Beside it go NAME-wall.ptl or NAME-panel.ptl (the grid
  // models), NAME-statue.ptl (without `models`) and the path files NAME.path, or for the city
  // NAME-walk.path, NAME-static.path, NAME-fly.path and NAME-turn.path.
  std::string output;
  // The scanned models (any model or scan `render` opens), used in turn; each is opened once to
  // read its bounds, view sphere and up axis. Empty: a statue is generated (statue_scene).
  std::vector<std::string> models;
  std::size_t statue_points = 20'000;  // samples of the generated statue (>= 16)
  std::uint64_t seed = 1;              // of the statue's samples
  // Multiplies the grid spacing of the wall and the façade panels: 1 is the specification's
  // (the wall has 1,002,501 points); 10 gives a wall of 201 × 51 points, for tests.
  float spacing_scale = 1.0f;
};

struct GeneratedModel {
  std::string path;            // as the scene file names it (relative to it when possible)
  std::uint64_t points = 0;    // samples (leaves of its hierarchy)
  std::size_t instances = 0;   // instances of it in the scene
  bool generated = false;      // written by generate_scene (else one of `models`)
};

struct GeneratedScene {
  std::size_t instance_count = 0;
  std::size_t scanned_instance_count = 0;
  std::vector<GeneratedModel> models;   // grid models, then the scanned models (or the statue)
  std::vector<std::string> path_files;  // as written
  std::vector<std::size_t> path_frames; // frames of each path file
};

// Writes the scene (see GenerateSceneOptions): the models first, then the path files, then
// the scene file, each atomically. Throws OptionError for an output not ending in .json, bad
// options, or an output that would replace an input or another output; IoError naming a model
// of `models` that does not exist; and what opening the models, building and writing throw.
GeneratedScene generate_scene(const GenerateSceneOptions& options, ThreadPool& pool,
                              Progress& progress = Progress::none());

}  // namespace pointillist
