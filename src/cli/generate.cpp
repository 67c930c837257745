#include <cstdio>

#include "commands.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/io/ply.hpp"
#include "pointillist/scene/analytic.hpp"

namespace pointillist::cli {

int run_generate(const GenerateOptions& o) {
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
  SurfaceSamples samples = sample_scene(scene, o.points, o.seed);
  if (o.with_normals) samples.points.normals = samples.true_normals;
  write_ply(o.output, samples.points);
  if (!o.quiet) {
    std::printf("generated %zu samples of the %s scene%s -> %s\n", samples.points.size(),
                o.scene.c_str(), o.with_normals ? " with exact normals" : "", o.output.c_str());
  }
  return 0;
}

}  // namespace pointillist::cli
