// A scene: instances of models, each placed by a transform (rotation, translation, uniform
// scale). A model used by several instances is opened once and shared. Scenes are written by
// hand as JSON files:
//   {"instances": [
//     {"model": "dragon.ptl", "translate": [0, 0, 0], "rotate_deg": [0, 45, 0], "scale": 1.0},
//     {"model": "bunny.ptl", "translate": [2.5, 0, 0]}
//   ]}
// A model point p goes to translate + scale · Rz·Ry·Rx · p (rotations in degrees about the
// model's own origin, x first); every field but "model" is optional; model paths are relative
// to the scene file.
#pragma once

#include <memory>
#include <span>
#include <string>
#include <vector>

#include "pointillist/core/math.hpp"
#include "pointillist/pipeline/model.hpp"
#include "pointillist/render/renderer.hpp"

namespace pointillist {

// The transform translate + scale · Rz·Ry·Rx · p (angles in degrees). Throws OptionError for a
// scale that is not a positive finite number or a non-finite angle or translation.
InstanceTransform make_transform(Vec3f translate, Vec3f rotate_deg, float scale);

class Scene {
 public:
  // Adds an instance of `model` (kept alive by the scene).
  void add(std::shared_ptr<const Model> model, const InstanceTransform& transform = {});
  std::span<const SceneInstance> instances() const { return instances_; }
  // The distinct models, in order of first use.
  const std::vector<std::shared_ptr<const Model>>& models() const { return models_; }
  std::size_t size() const { return instances_.size(); }
  // The sphere an orbit camera frames: for one untransformed instance its model's view sphere;
  // otherwise centred on the box around every instance's (transformed) bounds, with the radius
  // reaching every instance's transformed view sphere.
  Sphere view_sphere() const;
  // The up axis an orbit camera keeps: the first instance's model's (+Z for LAS scans, else
  // +Y), turned by that instance's rotation.
  Vec3f up() const;

 private:
  std::vector<std::shared_ptr<const Model>> models_;
  std::vector<SceneInstance> instances_;
};

// One untransformed instance of each path's model (each opened once, even when named twice);
// several scans (inputs that are not .ptl or .qs models) are merged into one model (open_scans),
// placed where the first of them is listed.
Scene scene_of_models(std::span<const std::string> paths, const OpenModelOptions& options,
                      ThreadPool& pool, Progress& progress);

// Reads a scene file (above) and opens its models. Throws FormatError naming the file and the
// field (e.g. "scene.json: instances[2].scale: must be a positive number, found -1") for bad
// JSON, unknown fields, wrong types and bad transforms; IoError when the file cannot be read;
// and what opening a model throws (a missing model names the instance).
Scene read_scene(const std::string& path, const OpenModelOptions& options, ThreadPool& pool,
                 Progress& progress);

// True when `path` names a scene file (.json).
bool is_scene_file(const std::string& path);

}  // namespace pointillist
