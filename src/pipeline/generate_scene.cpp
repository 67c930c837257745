// Writing the occlusion-culling acceptance scenes (see generate_scene.hpp).
#include "pointillist/pipeline/generate_scene.hpp"

#include <array>
#include <charconv>
#include <cstdio>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>

#include "pointillist/core/atomic_file.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/pipeline/convert.hpp"
#include "pointillist/pipeline/model.hpp"
#include "pointillist/scene/analytic.hpp"

namespace pointillist {
namespace fs = std::filesystem;
namespace {

// What a scanned model contributes to the placement of its instances.
struct ModelShape {
  std::string path;  // as the scene file names it
  Aabb bounds;
  Sphere view_sphere;
  Vec3f up;
  std::uint64_t points = 0;
};

// `file` as a path relative to `dir` (both taken from the working folder), or absolute when
// there is none (another drive, say).
std::string relative_to(const fs::path& file, const fs::path& dir) {
  const fs::path abs_file = fs::absolute(file).lexically_normal();
  const fs::path abs_dir = fs::absolute(dir.empty() ? fs::path(".") : dir).lexically_normal();
  const fs::path rel = abs_file.lexically_relative(abs_dir);
  return rel.empty() ? abs_file.string() : rel.generic_string();
}

// The float as the JSON number of its shortest decimal form (0.6f is written 0.6, not
// 0.6000000238418579), which reads back to the same float; 0 without a sign.
double tidy(float v) {
  if (v == 0.0f) return 0.0;
  std::array<char, 32> buf;
  const auto [end, ec] = std::to_chars(buf.data(), buf.data() + buf.size(), v);
  double d = v;
  if (ec == std::errc()) std::from_chars(buf.data(), end, d);
  return d;
}

nlohmann::json triple(Vec3f v) { return nlohmann::json::array({tidy(v.x), tidy(v.y), tidy(v.z)}); }

ModelShape open_shape(const std::string& path, const std::string& relative, ThreadPool& pool,
                      Progress& progress) {
  if (!fs::exists(path)) {
    throw IoError(path + ": no such model file (a scanned model of the scene); check the path");
  }
  OpenModelOptions open;
  open.paging = Paging::Always;  // only the header's bounds are needed, not the nodes
  open.stored_features = false;
  const Model model = open_model(path, open, pool, progress);
  const SphereTreeView& tree = model.tree();
  if (tree.bounds.empty() || !(tree.view_sphere.radius > 0.0f)) {
    throw Error(path + ": the model has no extent (its samples are all at one point), so it "
                "cannot be scaled to radius 1; give another model");
  }
  return {relative, tree.bounds, tree.view_sphere, tree.up, tree.leaf_count};
}

// Each of `paths` opened once (a path named twice gives the same shape twice).
std::vector<ModelShape> open_shapes(const std::vector<std::string>& paths, const fs::path& dir,
                                    ThreadPool& pool, Progress& progress) {
  std::vector<ModelShape> shapes;
  std::map<std::string, ModelShape> opened;
  for (const std::string& path : paths) {
    const std::string key = fs::weakly_canonical(path).string();
    if (!opened.count(key)) {
      opened.emplace(key, open_shape(path, relative_to(path, dir), pool, progress));
    }
    shapes.push_back(opened.at(key));
  }
  return shapes;
}

// Writes `points` as a .ptl model, as `convert` would; returns the samples written.
std::uint64_t write_model(PointSet points, const std::string& source, const std::string& path,
                          ThreadPool& pool, Progress& progress) {
  const std::string sources[] = {source};
  return convert_points(std::move(points), sources, path, {}, pool, progress).output_points;
}

std::string grid_source(const GridRectangle& g) {
  char text[160];
  std::snprintf(text, sizeof text,
                "generate --scene: %s, x %g..%g, y %g..%g, z 0, %u x %u points at spacing %g",
                g.name.c_str(), double(g.x0), double(g.x1), double(g.y0), double(g.y1),
                grid_columns(g), grid_rows(g), double(g.spacing));
  return text;
}

// The scene file's instances, one a line; counts each model's instances into `result`, whose
// models are the grids (in layout order) and then the scanned models; `entry[k]` is scanned
// model k's index there.
std::string instances_json(const SceneLayout& layout, const std::vector<ModelShape>& scanned,
                           const std::vector<std::size_t>& entry, GeneratedScene& result) {
  std::string instances;
  for (const LayoutInstance& inst : layout.instances) {
    nlohmann::ordered_json j;
    if (inst.grid >= 0) {
      GeneratedModel& model = result.models[static_cast<std::size_t>(inst.grid)];
      ++model.instances;
      j["model"] = model.path;
      j["translate"] = triple(inst.position);
      if (inst.yaw_deg != 0.0f) j["rotate_deg"] = triple({0, inst.yaw_deg, 0});
    } else {
      const std::size_t slot = result.scanned_instance_count++ % scanned.size();
      const ModelShape& m = scanned[slot];
      ++result.models[entry[slot]].instances;
      const Placement p =
          stand_on_ground(m.bounds, m.view_sphere, m.up, inst.position, inst.yaw_deg);
      j["model"] = m.path;
      j["translate"] = triple(p.translate);
      j["rotate_deg"] = triple(p.rotate_deg);
      j["scale"] = tidy(p.scale);
    }
    instances += (instances.empty() ? "  " : ",\n  ") + j.dump();
    ++result.instance_count;
  }
  return instances;
}

void check_options(const GenerateSceneOptions& o) {
  if (fs::path(o.output).extension() != ".json" || fs::path(o.output).stem().empty()) {
    throw OptionError("-o " + o.output + ": a scene file is JSON; give a path ending in .json "
                      "(its models and camera paths are written beside it)");
  }
  if (o.statue_points < 16) {
    throw OptionError("--points " + std::to_string(o.statue_points) +
                      ": the generated statue needs at least 16 points");
  }
}

}  // namespace

GeneratedScene generate_scene(const GenerateSceneOptions& o, ThreadPool& pool,
                              Progress& progress) {
  check_options(o);
  const SceneLayout layout = occlusion_scene_layout(o.scene, o.spacing_scale);
  const fs::path dir = fs::path(o.output).parent_path();
  const std::string name = fs::path(o.output).stem().string();
  const auto beside = [&](const std::string& file) { return (dir / file).string(); };
  const std::string statue_path = beside(name + "-statue.ptl");
  std::vector<std::pair<std::string, std::string>> outputs = {{"-o", o.output}};
  for (const GridRectangle& g : layout.grids) {
    outputs.push_back({"generated model", beside(name + "-" + g.name + ".ptl")});
  }
  if (o.models.empty()) outputs.push_back({"generated model", statue_path});
  for (const LayoutPath& p : layout.paths) {
    outputs.push_back({"camera path", beside(name + p.suffix + ".path")});
  }
  check_outputs(o.models, outputs);
  // Every given model is opened before anything is written, so a bad one leaves no files.
  std::vector<ModelShape> scanned = open_shapes(o.models, dir, pool, progress);
  if (!dir.empty()) {
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec) {
      throw IoError(dir.string() + ": cannot create the scene's folder (" + ec.message() + ")");
    }
  }

  GeneratedScene result;
  for (const GridRectangle& g : layout.grids) {
    const std::string path = beside(name + "-" + g.name + ".ptl");
    const std::uint64_t points = write_model(sample_grid(g), grid_source(g), path, pool, progress);
    result.models.push_back({relative_to(path, dir), points, 0, true});
  }
  if (scanned.empty()) {
    SurfaceSamples s = sample_scene(statue_scene(), o.statue_points, o.seed);
    s.points.normals = std::move(s.true_normals);
    write_model(std::move(s.points),
                "generate --scene: statue (statue_scene), seed " + std::to_string(o.seed),
                statue_path, pool, progress);
    scanned.push_back(open_shape(statue_path, relative_to(statue_path, dir), pool, progress));
  }
  // Each scanned model's entry in result.models (a model named twice is listed once).
  const std::size_t first_scanned = result.models.size();
  std::vector<std::size_t> entry;
  for (const ModelShape& m : scanned) {
    std::size_t e = first_scanned;
    while (e < result.models.size() && result.models[e].path != m.path) ++e;
    if (e == result.models.size()) result.models.push_back({m.path, m.points, 0, o.models.empty()});
    entry.push_back(e);
  }
  const std::string instances = instances_json(layout, scanned, entry, result);

  for (const LayoutPath& p : layout.paths) {
    const std::string path = beside(name + p.suffix + ".path");
    write_camera_path(path, p.path,
                      "pointillist generate --scene " + std::string(occlusion_scene_name(o.scene)) +
                          ": " + p.description +
                          "\none frame a line: eye x y z, target x y z (up +Y)");
    result.path_files.push_back(path);
    result.path_frames.push_back(p.path.frames.size());
  }
  AtomicFile scene_file(o.output);
  scene_file.write("{\"instances\": [\n" + instances + "\n]}\n");
  scene_file.commit();
  return result;
}

}  // namespace pointillist
