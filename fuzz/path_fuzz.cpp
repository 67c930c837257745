// libFuzzer harness for camera path files (render --path): parse_camera_path must fail only with
// a FormatError naming the file, what it reads must write back and read again to the same
// frames, and the cameras it gives must render a small scene with occlusion culling (stop-and-
// wait and CHC++, fast and quality modes) to the image of no culling, bit for bit, whatever the
// eye positions, targets and up vectors: hostile cameras are where culling's bounds and the
// quality occluder pass are most likely to go wrong.
#include <cstring>
#include <string_view>
#include <vector>

#include "fuzz_support.hpp"
#include "pointillist/io/camera_path.hpp"
#include "pointillist/lod/sphere_tree.hpp"
#include "pointillist/pipeline/scene.hpp"

using namespace pointillist;

namespace {

constexpr const char* kName = "fuzz.path";
constexpr std::size_t kMaxFrames = 3;  // frames rendered per input (each in four ways)

// A wall with two small grids behind and one in front: something to hide, something hidden.
struct TinyScene {
  ThreadPool pool{1};
  SphereTree wall_tree, block_tree;
  RenderModel wall, block;
  std::vector<SceneInstance> instances;
  TinyScene() {
    const auto grid = [](int nx, int ny, float step) {
      PointSet p;
      for (int j = 0; j < ny; ++j) {
        for (int i = 0; i < nx; ++i) {
          p.positions.push_back({step * float(i) - 0.5f * step * float(nx), step * float(j), 0});
          p.normals.push_back({0, 0, 1});
          p.radii.push_back(0.75f * step);
          p.colors.push_back({static_cast<std::uint8_t>(17 * i), static_cast<std::uint8_t>(9 * j),
                              90});
        }
      }
      return p;
    };
    wall_tree = build_sphere_tree(grid(40, 20, 0.1f), pool);
    block_tree = build_sphere_tree(grid(10, 10, 0.05f), pool);
    wall.tree = wall_tree.view();
    wall.name = "wall";
    block.tree = block_tree.view();
    block.name = "block";
    instances.push_back({&wall, {}});
    instances.push_back({&block, make_transform({-0.5f, 0.5f, -1.0f}, {0, 30, 0}, 1.0f)});
    instances.push_back({&block, make_transform({0.8f, 0.4f, -2.0f}, {0, -20, 0}, 1.5f)});
    instances.push_back({&block, make_transform({0.0f, 0.3f, 1.0f}, {10, 0, 0}, 0.5f)});
  }
};

void render_all_ways(TinyScene& scene, const Camera& camera) {
  for (Rasterizer mode : {Rasterizer::Fast, Rasterizer::Quality}) {
    FrameSettings none;
    none.rasterizer = mode;
    Renderer plain;
    Frame want;
    plain.render(scene.instances, camera, {}, none, scene.pool, want);
    for (OcclusionMethod m : {OcclusionMethod::StopAndWait, OcclusionMethod::ChcPlusPlus}) {
      FrameSettings fs = none;
      fs.occlusion.method = m;
      fs.occlusion.leaf_points = 16;
      Renderer culled;
      Frame got;
      culled.render(scene.instances, camera, {}, fs, scene.pool, got);
      if (got.color.size() != want.color.size() ||
          std::memcmp(got.color.data(), want.color.data(), want.color.size() * sizeof(Rgb8)) !=
              0 ||
          std::memcmp(got.depth.data(), want.depth.data(), want.depth.size() * sizeof(float)) !=
              0) {
        fuzz::finding(std::string("occlusion culling (") + name(m) + (mode == Rasterizer::Fast
                                                                          ? ", fast"
                                                                          : ", quality") +
                      ") changed the image");
      }
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static TinyScene scene;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  CameraPath path;
  try {
    path = parse_camera_path(text, kName);
  } catch (const FormatError& e) {
    if (std::string(e.what()).find(kName) == std::string::npos) {
      fuzz::finding(std::string("FormatError without the file's name: ") + e.what());
    }
    return 0;
  }
  if (path.frames.empty()) fuzz::finding("a path without frames was accepted");
  // What it read writes back and reads again to the same frames.
  const CameraPath again = parse_camera_path(format_camera_path(path), kName);
  if (again.frames.size() != path.frames.size() || again.fov_deg != path.fov_deg) {
    fuzz::finding("the written path reads back different");
  }
  for (std::size_t k = 0; k < path.frames.size(); ++k) {
    const CameraPathFrame& a = path.frames[k];
    const CameraPathFrame& b = again.frames[k];
    if (!(a.eye == b.eye) || !(a.target == b.target) || a.up.has_value() != b.up.has_value() ||
        (a.up && !(*a.up == *b.up))) {
      fuzz::finding("frame " + std::to_string(k) + " reads back different");
    }
  }
  CameraPath head = path;
  if (head.frames.size() > kMaxFrames) head.frames.resize(kMaxFrames);
  std::vector<Camera> cameras;
  try {
    cameras = path_cameras(head, kName, path.fov_deg.value_or(40.0f), 24, 18);
  } catch (const FormatError& e) {
    if (std::string(e.what()).find(kName) == std::string::npos) {
      fuzz::finding(std::string("FormatError without the file's name: ") + e.what());
    }
    return 0;
  }
  for (const Camera& camera : cameras) render_all_ways(scene, camera);
  return 0;
}
