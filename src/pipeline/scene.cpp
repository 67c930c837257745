// Scenes of model instances and their JSON files (see scene.hpp).
#include "pointillist/pipeline/scene.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <nlohmann/json.hpp>
#include <sstream>

#include "pointillist/core/error.hpp"

namespace pointillist {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {


// Rows of a 3×3 product a·b.
void multiply(const double a[3][3], const double b[3][3], double out[3][3]) {
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      out[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
    }
  }
}

std::string canonical_key(const std::string& path) {
  std::error_code ec;
  const fs::path p = fs::weakly_canonical(path, ec);
  return ec ? path : p.string();
}

// Opens each distinct path once.
class ModelCache {
 public:
  ModelCache(const OpenModelOptions& options, ThreadPool& pool, Progress& progress)
      : options_(options), pool_(pool), progress_(progress) {}
  std::shared_ptr<const Model> get(const std::string& path) {
    const std::string key = canonical_key(path);
    auto it = opened_.find(key);
    if (it != opened_.end()) return it->second;
    auto model = std::make_shared<const Model>(open_model(path, options_, pool_, progress_));
    opened_.emplace(key, model);
    return model;
  }

 private:
  const OpenModelOptions& options_;
  ThreadPool& pool_;
  Progress& progress_;
  std::map<std::string, std::shared_ptr<const Model>> opened_;
};

std::string type_name(const json& j) {
  if (j.is_array()) return "an array";
  if (j.is_object()) return "an object";
  if (j.is_string()) return "a string";
  if (j.is_number()) return "a number";
  if (j.is_boolean()) return "true/false";
  return "null";
}

std::string shown(const json& j) {
  std::string s = j.dump();
  if (s.size() > 40) s = s.substr(0, 37) + "...";
  return s;
}

Vec3f read_vec3(const json& j, const std::string& where) {
  if (!j.is_array() || j.size() != 3 || !j[0].is_number() || !j[1].is_number() ||
      !j[2].is_number()) {
    throw FormatError(where + ": must be an array of three numbers, found " + shown(j));
  }
  const Vec3f v{j[0].get<float>(), j[1].get<float>(), j[2].get<float>()};
  if (!is_finite(v)) throw FormatError(where + ": must be finite numbers, found " + shown(j));
  return v;
}

}  // namespace

InstanceTransform make_transform(Vec3f translate, Vec3f rotate_deg, float scale) {
  if (!(scale > 0.0f) || !std::isfinite(scale)) {
    throw OptionError("scale " + std::to_string(scale) + " must be a positive finite number");
  }
  if (!is_finite(translate) || !is_finite(rotate_deg)) {
    throw OptionError("translation and rotation must be finite numbers");
  }
  const double ax = rotate_deg.x * kPi / 180.0, ay = rotate_deg.y * kPi / 180.0,
               az = rotate_deg.z * kPi / 180.0;
  const double rx[3][3] = {{1, 0, 0}, {0, std::cos(ax), -std::sin(ax)},
                           {0, std::sin(ax), std::cos(ax)}};
  const double ry[3][3] = {{std::cos(ay), 0, std::sin(ay)}, {0, 1, 0},
                           {-std::sin(ay), 0, std::cos(ay)}};
  const double rz[3][3] = {{std::cos(az), -std::sin(az), 0}, {std::sin(az), std::cos(az), 0},
                           {0, 0, 1}};
  double zy[3][3], r[3][3];
  multiply(rz, ry, zy);
  multiply(zy, rx, r);
  InstanceTransform t;
  t.translate = translate;
  t.scale = scale;
  const bool no_rotation = rotate_deg == Vec3f{0, 0, 0};
  for (int i = 0; i < 3; ++i) {
    // No rotation keeps the exact identity (no 1 − 1e-17 from the cosines).
    if (!no_rotation) {
      t.rotation[i] = {static_cast<float>(r[i][0]), static_cast<float>(r[i][1]),
                       static_cast<float>(r[i][2])};
    }
  }
  return t;
}

void Scene::add(std::shared_ptr<const Model> model, const InstanceTransform& transform) {
  if (std::find(models_.begin(), models_.end(), model) == models_.end()) models_.push_back(model);
  instances_.push_back({&model->renderable(), transform});
}

Sphere Scene::view_sphere() const {
  if (instances_.empty()) return {};
  if (instances_.size() == 1 && instances_[0].transform.is_identity()) {
    return instances_[0].model->tree.view_sphere;
  }
  Aabb box;
  for (const SceneInstance& inst : instances_) {
    const Aabb& b = inst.model->tree.bounds;
    if (b.empty()) continue;
    for (int corner = 0; corner < 8; ++corner) {
      box.extend(inst.transform.apply({corner & 1 ? b.hi.x : b.lo.x,
                                       corner & 2 ? b.hi.y : b.lo.y,
                                       corner & 4 ? b.hi.z : b.lo.z}));
    }
  }
  if (box.empty()) return {};
  Sphere s{box.center(), 0.0f};
  for (const SceneInstance& inst : instances_) {
    const Sphere& v = inst.model->tree.view_sphere;
    s.radius = std::max(s.radius, distance(s.center, inst.transform.apply(v.center)) +
                                      inst.transform.scale * v.radius);
  }
  return s;
}

Vec3f Scene::up() const {
  if (instances_.empty()) return {0, 1, 0};
  const SceneInstance& first = instances_[0];
  return normalized(first.transform.rotate(first.model->tree.up));
}

Scene scene_of_models(std::span<const std::string> paths, const OpenModelOptions& options,
                      ThreadPool& pool, Progress& progress) {
  ModelCache cache(options, pool, progress);
  Scene scene;
  // Scans are merged into one model (as convert merges them): tiles of one survey then share
  // their normals and radii across borders, and a tile too small to prepare on its own is
  // prepared with its neighbours. Models are added one instance each, in order.
  std::vector<std::string> scans;
  std::set<std::string> seen;
  for (const std::string& p : paths) {
    if (!is_model_file(p) && seen.insert(canonical_key(p)).second) scans.push_back(p);
  }
  bool scans_added = scans.size() < 2;
  for (const std::string& p : paths) {
    if (is_model_file(p) || scans.size() < 2) {
      scene.add(cache.get(p));
    } else if (!scans_added) {
      scene.add(std::make_shared<const Model>(open_scans(scans, options, pool, progress)));
      scans_added = true;
    }
  }
  return scene;
}

bool is_scene_file(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext == ".json";
}

Scene read_scene(const std::string& path, const OpenModelOptions& options, ThreadPool& pool,
                 Progress& progress) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(path + ": cannot open the scene file; check the path");
  std::stringstream text;
  text << in.rdbuf();
  json doc;
  try {
    doc = json::parse(text.str());
  } catch (const json::parse_error& e) {
    throw FormatError(path + ": byte " + std::to_string(e.byte) + ": not valid JSON (" +
                      e.what() + "); a scene file is {\"instances\": [{\"model\": \"a.ptl\"}, ...]}");
  }
  if (!doc.is_object() || !doc.contains("instances")) {
    throw FormatError(path + ": a scene file is an object with \"instances\": [...], found " +
                      type_name(doc) + (doc.is_object() ? " without \"instances\"" : ""));
  }
  for (const auto& [key, value] : doc.items()) {
    if (key != "instances") {
      throw FormatError(path + ": unknown field \"" + key + "\"; a scene file has only "
                        "\"instances\"");
    }
  }
  const json& list = doc["instances"];
  if (!list.is_array() || list.empty()) {
    throw FormatError(path + ": instances: must be a non-empty array of instances, found " +
                      shown(list));
  }
  const fs::path base = fs::path(path).parent_path();
  ModelCache cache(options, pool, progress);
  Scene scene;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string where = path + ": instances[" + std::to_string(i) + "]";
    const json& inst = list[i];
    if (!inst.is_object()) {
      throw FormatError(where + ": must be an object such as {\"model\": \"a.ptl\"}, found " +
                        shown(inst));
    }
    for (const auto& [key, value] : inst.items()) {
      if (key != "model" && key != "translate" && key != "rotate_deg" && key != "scale") {
        throw FormatError(where + ": unknown field \"" + key +
                          "\"; use model, translate, rotate_deg, scale");
      }
    }
    if (!inst.contains("model") || !inst["model"].is_string() ||
        inst["model"].get<std::string>().empty()) {
      throw FormatError(where + ".model: must be the path of a model or scan (relative to the "
                        "scene file)" + (inst.contains("model") ? ", found " + shown(inst["model"])
                                                                 : std::string(", missing")));
    }
    const fs::path model_path = base / inst["model"].get<std::string>();
    const Vec3f translate =
        inst.contains("translate") ? read_vec3(inst["translate"], where + ".translate")
                                   : Vec3f{0, 0, 0};
    const Vec3f rotate =
        inst.contains("rotate_deg") ? read_vec3(inst["rotate_deg"], where + ".rotate_deg")
                                    : Vec3f{0, 0, 0};
    float scale = 1.0f;
    if (inst.contains("scale")) {
      const json& s = inst["scale"];
      if (!s.is_number() || !(s.get<double>() > 0) || !std::isfinite(s.get<double>())) {
        throw FormatError(where + ".scale: must be a positive number, found " + shown(s));
      }
      scale = s.get<float>();
    }
    if (!fs::exists(model_path)) {
      throw IoError(where + ".model: " + model_path.string() +
                    ": no such file (paths are relative to the scene file)");
    }
    scene.add(cache.get(model_path.string()), make_transform(translate, rotate, scale));
  }
  return scene;
}

}  // namespace pointillist
