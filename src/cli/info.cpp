#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "commands.hpp"
#include "options.hpp"
#include "util.hpp"
#include "pointillist/format/ptl.hpp"
#include "pointillist/format/ptl_v2.hpp"
#include "pointillist/pipeline/model.hpp"
#include "pointillist/lod/sequential_point_tree.hpp"
#include "pointillist/render/spt_render.hpp"

namespace pointillist::cli {

namespace {

// "PLY", "LAS", "OBJ" or "text" from the file name (as read_point_file dispatches).
std::string input_format_name(const std::string& path) {
  std::string lower = path;
  for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (lower.size() > 3 && lower.ends_with(".gz")) lower.resize(lower.size() - 3);
  if (lower.ends_with(".ply")) return "PLY";
  if (lower.ends_with(".las")) return "LAS";
  if (lower.ends_with(".obj")) return "OBJ";
  return "text";
}

double share(std::uint64_t part, std::uint64_t whole) {
  return whole ? 100.0 * double(part) / double(whole) : 0.0;
}

// The dissertation's Tables 6.1-6.3 for this model, and what Pointillist adds.
void print_feature_stats(const FeatureStats& s, const FeatureOptions& o) {
  const auto u = [](std::uint64_t v) { return static_cast<unsigned long long>(v); };
  std::printf("sharp features (w_s %.2f, edge test %s, drawn radius %.2f x splat radius):\n",
              o.sharp_threshold, o.edge_test == EdgeTest::Side ? "side" : "linsen",
              o.radius_scale);
  if (s.spread_deg > 0) {
    std::printf("  spread:      3/4 of the neighbour pairs' normals differ by at most %.1f degrees",
                s.spread_deg);
    if (s.threshold_raised) {
      std::printf(" (a rough surface: the threshold was raised to %.1f times that)", kSpreadFactor);
    }
    std::printf("\n");
  }
  std::printf("  graph:       %llu edges, m = %.2f edges a splat (bounding spheres, eq. 3.1)\n",
              u(s.edges), s.mean_degree());
  std::printf("  sharp edges: %llu (%.2f%% of edges); discs really crossing: %llu (%.2f%% of "
              "sharp edges); antiparallel: %llu\n",
              u(s.sharp_edges), share(s.sharp_edges, s.edges), u(s.crossing_edges),
              share(s.crossing_edges, s.sharp_edges), u(s.antiparallel_edges));
  std::printf("  splats:      %llu; candidates %llu (%.2f%%); clipped %llu (%.2f%% of "
              "candidates); crossings passed through (intersections) %llu\n",
              u(s.splats), u(s.candidates), share(s.candidates, s.splats), u(s.clipped),
              share(s.clipped, s.candidates), u(s.pass_through));
  std::printf("  planes per clipped splat:");
  for (std::size_t k = 1; k < s.plane_histogram.size(); ++k) {
    if (s.plane_histogram[k]) std::printf(" %zu: %llu", k, u(s.plane_histogram[k]));
  }
  std::printf("%s\n", s.capped ? (" (" + std::to_string(s.capped) + " capped at 16)").c_str() : "");
  std::printf("  rules:       eqs. 4.13-4.15 undefined for %llu splats; nearest-plane rule for "
              "%llu\n", u(s.undefined_4_15), u(s.nearest_rule));
  std::printf("  surfaces:    %llu segments, %llu with at least 0.5%% of the splats\n",
              u(s.segments), u(s.large_segments));
}

}  // namespace

int run_info(const InfoOptions& o) {
  ThreadPool pool(o.threads);
  OpenModelOptions open;
  open.columns = o.columns;
  open.paging = o.spt ? Paging::Never : Paging::Auto;
  if (o.features) {
    open.features = o.feature;
    open.paging = Paging::Never;
  }
  const Model model = open_model(o.input, open, pool, Progress::none());
  const SphereTreeView& t = model.tree();
  const Model::ScanInput& in = model.scan_input();
  std::array<std::uint64_t, 5> children{};
  for (const SphereNode& n : t.nodes) children[n.child_count <= 4 ? n.child_count : 0]++;
  const double leaves = double(t.leaf_count);

  std::printf("file:        %s\n", o.input.c_str());
  const PtlV2File* v2 = model.ptl_v2();
  if (v2) {
    const std::uint64_t records = v2->node_count();
    std::printf("format:      Pointillist model (.ptl) version 2: quantized %s-byte nodes in %u "
                "pages, leaf trims in %s, memory-mapped%s\n",
                v2->has_colors() ? "6" : "4", v2->page_count(),
                v2->leaf_trim() == quant::LeafTrim::Sixteenths ? "sixteenths" : "eighths",
                v2->has_triangles() ? ", with the mesh's faces" : "");
    std::printf("opened:      %s\n", model.paging_reason().c_str());
    if (t.nodes.empty()) {
      std::printf("points:      %llu (leaves)\n", static_cast<unsigned long long>(t.leaf_count));
      std::printf("nodes:       %llu (%.3f per point)\n", static_cast<unsigned long long>(records),
                  leaves > 0 ? double(records) / leaves : 0.0);
    }
  } else if (model.ptl_v1()) {
    std::printf("format:      Pointillist model (.ptl) version %u, memory-mapped\n",
                model.ptl_v1()->version());
  } else if (model.kind() == ModelKind::Qsplat) {
    std::printf("format:      QSplat model (.qs 1.1), decoded into memory\n");
  } else {
    std::printf("format:      %s %s, %zu input points%s (hierarchy built in memory)\n",
                input_format_name(o.input).c_str(),
                in.is_mesh ? "mesh" : "point cloud", in.points,
                in.is_mesh ? " (vertices used by faces kept)" : "");
  }
  if (!t.nodes.empty()) {
    std::printf("points:      %llu (leaves)\n", static_cast<unsigned long long>(t.leaf_count));
    std::printf("nodes:       %zu (%.3f per point; children 2/3/4: %llu/%llu/%llu)\n",
                t.nodes.size(), leaves > 0 ? double(t.nodes.size()) / leaves : 0.0,
                static_cast<unsigned long long>(children[2]),
                static_cast<unsigned long long>(children[3]),
                static_cast<unsigned long long>(children[4]));
  }
  std::printf("depth:       %u levels below the root\n", t.depth);
  if (model.kind() != ModelKind::Scan) {
    std::printf("attributes:  position, normal, normal cone, radius%s\n",
                t.has_colors ? ", color" : "");
  } else {
    std::printf("attributes:  in file: position%s%s%s%s; computed: %s%s\n",
                in.has_normals ? ", normal" : "", in.has_colors ? ", color" : "",
                in.has_radii ? ", radius" : "", in.is_mesh ? ", faces" : "",
                in.has_normals ? "" : "normal, ", in.has_radii ? "-" : "radius");
  }
  const std::array<double, 3>& org = t.origin;
  if (org != std::array<double, 3>{}) {
    // Georeferenced: the box in the scan's own (world) coordinates, and the local frame.
    std::printf("bounds:      min (%.3f, %.3f, %.3f)  max (%.3f, %.3f, %.3f) (world)\n",
                org[0] + t.bounds.lo.x, org[1] + t.bounds.lo.y, org[2] + t.bounds.lo.z,
                org[0] + t.bounds.hi.x, org[1] + t.bounds.hi.y, org[2] + t.bounds.hi.z);
    std::printf("origin:      (%.3f, %.3f, %.3f); positions are stored relative to it\n", org[0],
                org[1], org[2]);
  } else {
    std::printf("bounds:      min (%g, %g, %g)  max (%g, %g, %g)\n", t.bounds.lo.x,
                t.bounds.lo.y, t.bounds.lo.z, t.bounds.hi.x, t.bounds.hi.y, t.bounds.hi.z);
  }
  std::printf("up axis:     (%g, %g, %g)%s\n", t.up.x, t.up.y, t.up.z,
              t.up == Vec3f{0, 0, 1} ? " (Z up, as LAS scans)" : "");
  if (v2) {
    const Sphere& root = v2->root_sphere();
    std::printf("sphere:      centre (%g, %g, %g), radius %g (root of the hierarchy)\n",
                root.center.x, root.center.y, root.center.z, root.radius);
  } else if (!t.nodes.empty()) {
    const SphereNode& root = t.nodes[0];
    std::printf("sphere:      centre (%g, %g, %g), radius %g (root of the hierarchy)\n",
                root.center.x, root.center.y, root.center.z, root.radius);
  }
  std::printf("view sphere: centre (%g, %g, %g), radius %g (used by --view)\n",
              t.view_sphere.center.x, t.view_sphere.center.y, t.view_sphere.center.z,
              t.view_sphere.radius);
  if (!t.nodes.empty()) {
    // Splat radii of the leaves (compare's --see-through-gap is 2 mean radii in the spec).
    double sum = 0;
    float lo = INFINITY, hi = 0;
    std::uint64_t count = 0;
    for (const SphereNode& n : t.nodes) {
      if (n.child_count != 0) continue;
      sum += n.radius, lo = std::min(lo, n.radius), hi = std::max(hi, n.radius), ++count;
    }
    if (count > 0) {
      std::printf("splat radii: mean %g, min %g, max %g (leaves)\n", sum / double(count), lo, hi);
    }
  }
  std::printf("file size:   %s (%.2f bytes/point)\n",
              human_bytes(double(model.file_size())).c_str(),
              leaves > 0 ? double(model.file_size()) / leaves : 0.0);
  if (const TreeFeatures* f = model.features()) print_feature_stats(f->stats, f->options);
  if (o.spt) {
    const SequentialPointTree spt = build_sequential_point_tree(sphere_tree_leaves(t), pool);
    std::printf("sequential point tree (built in memory, chunk level %u):\n", spt.chunk_level);
    std::printf("  list:      %zu entries (%.3f per point), top list %u, %zu chunks\n",
                spt.node_count(), leaves > 0 ? double(spt.node_count()) / leaves : 0.0, spt.top_end,
                spt.chunks.size());
    const Camera camera = make_camera(o.view, t.view_sphere, t.up);
    SplatStream stream;
    SptSelectionStats s;
    select_splats_spt(spt, make_camera_frame(camera), RenderSettings{}, {.epsilon_px = o.epsilon_px},
                      pool, stream, s);
    SptSelectionStats unculled;
    select_splats_spt(spt, make_camera_frame(camera), RenderSettings{},
                      {.epsilon_px = o.epsilon_px, .chunk_culling = false}, pool, stream, unculled);
    std::printf("  view %g,%g at %dx%d, epsilon %g px: scans %llu entries (%.1f%% of the list; "
                "%.1f%% without chunk culling), draws %llu splats, culls %llu of %llu chunks\n",
                o.view.azimuth_deg, o.view.elevation_deg, o.view.width, o.view.height, o.epsilon_px,
                static_cast<unsigned long long>(s.entries_scanned),
                100.0 * double(s.entries_scanned) / double(std::max<std::uint64_t>(1, s.entries_total)),
                100.0 * double(unculled.entries_scanned) /
                    double(std::max<std::uint64_t>(1, unculled.entries_total)),
                static_cast<unsigned long long>(s.splats),
                static_cast<unsigned long long>(s.chunks_culled),
                static_cast<unsigned long long>(s.chunks_total));
  }
  if (!model.metadata().empty()) {
    std::printf("metadata:\n");
    std::size_t start = 0;
    while (start < model.metadata().size()) {
      std::size_t end = model.metadata().find('\n', start);
      if (end == std::string::npos) end = model.metadata().size();
      std::printf("  %s\n", model.metadata().substr(start, end - start).c_str());
      start = end + 1;
    }
  }
  return 0;
}

Command add_info_command(CLI::App& app) {
  auto o = std::make_shared<InfoOptions>();
  auto view = std::make_shared<std::string>(), size = std::make_shared<std::string>("1280x720");
  auto* cmd = app.add_subcommand("info", "Describe a model or scan file");
  cmd->add_option("input", o->input, "Model or scan file")->required()->check(CLI::ExistingFile);
  add_threads(cmd, o->threads);
  add_columns(cmd, o->columns);
  cmd->add_flag("--features", o->features,
                "Find the sharp features in memory and print their statistics (the "
                "dissertation's tables: graph, sharp edges, crossings, clipped splats, surfaces)");
  CLI::Option* threshold = add_sharp_threshold(cmd, o->feature);
  cmd->add_flag("--spt", o->spt,
                "Also build the Sequential Point Tree and report its list and the share of it "
                "one view scans");
  cmd->add_option("--view", *view, "With --spt: orbit view AZ,EL (default 0,0)");
  cmd->add_option("--size", *size, "With --spt: image size WxH")->default_str("1280x720");
  cmd->add_option("--distance", o->view.distance,
                  "With --spt: eye distance in model radii (default: whole model in view)");
  cmd->add_option("--epsilon", o->epsilon_px, "With --spt: error bound, pixels")
      ->default_val(1.0f)
      ->check(CLI::Range(0.001f, 1000.0f));
  return {cmd, [o, view, size, threshold] {
            parse_size_and_view(*size, *view, o->view);
            o->feature.adapt_threshold = threshold->count() == 0;
            return run_info(*o);
          }};
}

}  // namespace pointillist::cli
