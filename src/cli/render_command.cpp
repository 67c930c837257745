#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "cli/commands.hpp"
#include "cli/model_loading.hpp"
#include "cli/stats_json.hpp"
#include "cli/terminal_progress.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/io/png.hpp"
#include "pointillist/render/depth_image.hpp"

namespace pointillist::cli {

Camera make_camera(const ViewOptions& v, const SphereTreeView& tree) {
  const bool explicit_eye = v.eye || v.target || v.up;
  if (explicit_eye) {
    if (!v.eye || !v.target) {
      throw OptionError("--eye and --target must be given together (--up is optional, default 0,1,0)");
    }
    Camera c;
    c.eye = *v.eye;
    c.target = *v.target;
    c.up = v.up.value_or(Vec3f{0, 1, 0});
    c.fov_deg = v.fov_deg;
    c.width = v.width;
    c.height = v.height;
    return c;
  }
  return orbit_camera(tree.view_sphere, {.azimuth_deg = v.azimuth_deg,
                                         .elevation_deg = v.elevation_deg,
                                         .distance = v.distance,
                                         .fov_deg = v.fov_deg,
                                         .width = v.width,
                                         .height = v.height});
}

void write_stats(const std::string& where, const RenderStats& s) {
  const std::string json = stats_to_json(s);
  if (where == "-") {
    std::fputs(json.c_str(), stdout);
    return;
  }
  std::ofstream out(where, std::ios::binary | std::ios::trunc);
  if (!out || !(out << json) || !out.flush()) {
    throw IoError(where + ": cannot write the statistics file; check that the folder exists and "
                          "is writable");
  }
}

int run_render(const RenderOptions& o) {
  ThreadPool pool(o.threads);
  TerminalProgress progress(!o.quiet && TerminalProgress::stderr_is_terminal());
  const LoadedModel model = LoadedModel::open(o.input, o.prepare, pool, progress);
  const Camera camera = make_camera(o.view, model.tree());
  Frame frame;
  render(model.tree(), camera, o.settings, pool, frame);
  write_png_rgb8(o.output, frame.width, frame.height, frame.color);
  if (!o.depth_output.empty()) {
    const auto depth16 = depth_to_gray16(frame);
    write_png_gray16(o.depth_output, frame.width, frame.height, depth16);
  }
  if (!o.stats_output.empty()) write_stats(o.stats_output, frame.stats);
  if (!o.quiet && o.stats_output != "-") {
    std::printf("rendered %s: %dx%d, %llu splats, %.2f ms (select %.2f, raster %.2f) -> %s\n",
                o.input.c_str(), frame.width, frame.height,
                static_cast<unsigned long long>(frame.stats.splats), frame.stats.ms_total,
                frame.stats.ms_select, frame.stats.ms_raster, o.output.c_str());
  }
  return 0;
}

}  // namespace pointillist::cli
