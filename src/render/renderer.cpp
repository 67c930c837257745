// The renderer's one entry point (see renderer.hpp): per instance, selection by the chosen
// level-of-detail scheme into the frame's stream; then one rasterization of the whole stream.
#include "pointillist/render/renderer.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>

#include "frame_pass.hpp"
#include "raster/triangle_draw.hpp"
#include "renderer_state.hpp"
#include "select/stream_features.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/render/eye_dome.hpp"
#include "pointillist/render/mesh_reference.hpp"
#include "pointillist/render/paged.hpp"
#include "pointillist/render/selection.hpp"

namespace pointillist {

using namespace render_detail;

bool InstanceTransform::is_identity() const {
  return translate == Vec3f{0, 0, 0} && scale == 1.0f && rotation[0] == Vec3f{1, 0, 0} &&
         rotation[1] == Vec3f{0, 1, 0} && rotation[2] == Vec3f{0, 0, 1};
}

// Hybrid mode: each instance's selected triangles, and the triangle rasterizer's buffers.
struct Renderer::TriangleState {
  std::vector<std::vector<std::uint32_t>> selected;  // per instance
  std::vector<TriangleBatch> batches;
  TriangleScratch scratch;
};

Renderer::Renderer(const RendererOptions& options)
    : options_(options), triangles_(std::make_unique<TriangleState>()) {}
Renderer::~Renderer() = default;

Renderer::ModelState& Renderer::state_for(const RenderModel& model, ThreadPool& pool,
                                          const FrameSettings& fs) {
  std::unique_ptr<ModelState>& slot = states_[&model];
  if (!slot) {
    slot = std::make_unique<ModelState>();
    ModelState* state = slot.get();
    state->model = &model;
    if (model.pages || options_.page_all) {
      state->pages = model.pages;
      if (!state->pages) {
        // A model held whole: cut into pages in memory, so that paging can be watched; the cap
        // bounds the pages the renderer keeps, not the model's own memory.
        state->owned_pages = paginate(model.tree, kInMemoryPageBytes, kInMemoryPageLevels);
        state->pages = state->owned_pages.get();
      }
      state->paged.emplace(*state->pages,
                           options_.memory_cap > 0 ? options_.memory_cap : UINT64_MAX, pool);
      state->model_bytes = state->pages->open_bytes();
      for (std::uint32_t i = 0; i < state->pages->page_count(); ++i) {
        state->model_bytes += state->pages->page_storage_bytes(i);
      }
    }
  }
  ModelState* state = slot.get();
  const bool hybrid = fs.lod == LodScheme::Spt && fs.hybrid && !model.triangles.empty();
  const bool hybrid_stale =
      hybrid && (!state->hybrid ||
                 state->hybrid->triangle_px_per_epsilon != fs.triangle_px_per_epsilon);
  if ((fs.lod == LodScheme::Spt && !state->spt) || hybrid_stale) {
    const PointSet leaves = sphere_tree_leaves(model.tree);
    if (!state->spt) {
      state->spt = build_sequential_point_tree(leaves, pool);
      if (model.tree.features) {
        state->spt_features = spt_features(*state->spt, model.tree.nodes, *model.tree.features);
      }
    }
    if (hybrid_stale) {
      state->hybrid = build_hybrid_lod(*state->spt, leaves, model.triangles,
                                       {.triangle_px_per_epsilon = fs.triangle_px_per_epsilon});
    }
  }
  return *state;
}

void Renderer::render(std::span<const SceneInstance> scene, const Camera& camera,
                      const RenderSettings& settings, const FrameSettings& fs, ThreadPool& pool,
                      Frame& frame) {
  if (fs.rasterizer == Rasterizer::Reference) {
    if (fs.lod == LodScheme::Spt) {
      throw OptionError("--mode reference draws the mesh's triangles; it cannot be combined with "
                        "--lod spt");
    }
  }
  if (fs.hybrid) {
    const char* drop = fs.lod != LodScheme::Spt                       ? "or add --lod spt"
                       : fs.rasterizer != Rasterizer::Fast            ? "or --mode"
                       : fs.occlusion.method != OcclusionMethod::None ? "or --occlusion"
                                                                      : nullptr;
    if (drop) {
      throw OptionError(std::string("--hybrid draws a mesh's triangles beside the points of a "
                                    "Sequential Point Tree with the fast rasterizer; drop "
                                    "--hybrid ") +
                        drop);
    }
    const bool any = std::any_of(scene.begin(), scene.end(), [](const SceneInstance& i) {
      return !i.model->triangles.empty();
    });
    if (!any) {
      throw OptionError((scene.empty() ? std::string("the scene") : scene[0].model->name) +
                        ": --hybrid draws a mesh's triangles, and no model here has any; give "
                        "a mesh (.ply, .obj) or a .ptl converted from one, or drop --hybrid");
    }
  }
  if (fs.rasterizer == Rasterizer::Quality) validate_quality_settings(fs.quality);
  if (!(fs.splat_scale > 0.0f) || !std::isfinite(fs.splat_scale)) {
    throw OptionError("splat scale " + std::to_string(fs.splat_scale) +
                      " is invalid; give a positive number (1 draws splats at their size)");
  }
  for (const SceneInstance& inst : scene) {
    const RenderModel& m = *inst.model;
    if (fs.rasterizer == Rasterizer::Reference && !(m.mesh && m.mesh->is_mesh())) {
      throw OptionError(m.name + ": --mode reference draws a mesh's triangles, and this input " +
                        (m.mesh ? "has no faces" : "is a splat model") +
                        "; give the source mesh (.ply, .obj)");
    }
    if ((m.pages || options_.page_all) &&
        (fs.lod == LodScheme::Spt || fs.rasterizer == Rasterizer::Reference)) {
      throw OptionError(std::string(m.pages ? m.name + " is rendered page by page"
                                            : "--memory and --progressive render page by page") +
                        ": the QSplat hierarchy in the fast or quality mode; drop " +
                        (fs.lod == LodScheme::Spt ? "--lod spt" : "--mode reference"));
    }
  }

  const bool occlusion = fs.occlusion.method != OcclusionMethod::None;
  if (occlusion) {
    const bool quality = fs.rasterizer == Rasterizer::Quality;
    const char* drop = fs.rasterizer == Rasterizer::Reference ? "--mode reference"
                       : quality && fs.quality.opacity < 1.0f
                           ? "--opacity below 1 (what shows through is not hidden)"
                           : nullptr;
    // With sharp features the quality occluders bound the drawn radii by the QSplat rule
    // (quality_occluders.hpp): not the Sequential Point Tree's lists, nor pages drawn coarser
    // while they load.
    for (const SceneInstance& inst : scene) {
      if (!drop && quality && fs.features && model_features(*inst.model) &&
          (fs.lod == LodScheme::Spt || inst.model->pages || options_.page_all)) {
        drop = fs.lod == LodScheme::Spt
                   ? "--lod spt with sharp features in --mode quality (or add --no-features)"
                   : "paging of models with sharp features in --mode quality (add --no-features)";
      }
    }
    if (drop) {
      throw OptionError(std::string("occlusion culling (--occlusion ") +
                        name(fs.occlusion.method) +
                        ") works with the fast mode, and the quality mode of opaque surfaces "
                        "(with sharp features: models held whole, --lod qsplat); drop " +
                        drop + ", or --occlusion");
    }
  }
  last_frame_.clear();
  spt_stats_ = {};
  triangles_selected_ = triangle_entries_scanned_ = 0;
  triangles_->batches.clear();
  ++frame_number_;
  frame.splats.trim();
  scratch_stream_.trim();
  if (occlusion) {
    render_occluded(scene, camera, settings, fs, pool, frame);
  } else if (fs.rasterizer == Rasterizer::Reference) {
    render_mesh_reference(scene, camera, settings, frame);
  } else {
    const bool quality = fs.rasterizer == Rasterizer::Quality;
    render_detail::frame_pass(camera, settings, quality ? &fs.quality : nullptr,
                              &quality_scratch_, pool, frame,
                              [&](const CameraFrame& world, SplatStream& stream) {
                                return select(scene, camera, world, settings, fs, pool, stream);
                              });
    if (!triangles_->batches.empty()) {
      // The hybrid mode's triangles, into the splats' image (timed as rasterization).
      const auto start = Clock::now();
      frame.stats.triangles =
          draw_triangles(triangles_->batches, make_camera_frame(camera), settings, pool,
                         triangles_->scratch, frame.color, frame.depth);
      const double ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
      frame.stats.ms_raster += ms;
      frame.stats.ms_total += ms;
    }
  }
  if (settings.edl_strength != 0.0f) apply_eye_dome_lighting(frame, settings.edl_strength, pool);
}

// Selection, instance after instance; the first instance selects straight into the frame's
// stream, the others into a scratch stream whose chunks are then moved behind.
SelectionStats Renderer::select(std::span<const SceneInstance> scene, const Camera& camera,
                                const CameraFrame& world, const RenderSettings& settings,
                                const FrameSettings& fs, ThreadPool& pool, SplatStream& stream) {
  stream.chunk_count = 0;
  stream.has_colors = false;
  SelectionStats total;
  bool any_colors = false, any_features = false;
  for (const SceneInstance& inst : scene) {
    any_colors = any_colors || inst.model->tree.has_colors;
    any_features = any_features || model_features(*inst.model);
  }
  // Sharp features (node ids index the features: the hierarchy's nodes, or the SPT's entries);
  // the clip test needs the discs in both rasterizers.
  const bool features = fs.features && any_features;
  if (features) stream.with_discs = true;
  const bool with_discs = stream.with_discs;
  std::uint32_t id_base = 0;
  for (std::size_t i = 0; i < scene.size(); ++i) {
    const SceneInstance& inst = scene[i];
    ModelState& state = state_for(*inst.model, pool, fs);
    const bool first_use = state.frame != frame_number_;
    state.frame = frame_number_;
    if (first_use) last_frame_.push_back(&state);
    const bool identity = inst.transform.is_identity();
    const CameraFrame cam =
        identity ? world : model_camera_frame(camera, world, inst.transform);
    SplatStream& into = i == 0 ? stream : scratch_stream_;
    into.with_discs = with_discs;
    into.chunk_count = 0;
    SelectionStats selected;
    // Hybrid lists drawn for this instance (state_for built them when the model has triangles).
    const bool hybrid = fs.lod == LodScheme::Spt && fs.hybrid && state.hybrid &&
                        !inst.model->triangles.empty();
    if (fs.lod == LodScheme::Spt) {
      SptSelectionStats spt;
      select_splats_spt(*state.spt, cam, settings,
                        {.epsilon_px = fs.epsilon_px,
                         .chunk_culling = fs.spt_chunk_culling,
                         .suppress_below =
                             hybrid ? std::span<const float>(state.hybrid->suppress_below)
                                          : std::span<const float>()},
                        pool, into, spt);
      selected = spt.as_selection();
      spt_stats_ += spt;
      if (hybrid) {
        TriangleState& ts = *triangles_;
        if (ts.selected.size() <= i) ts.selected.resize(i + 1);
        ts.selected[i].clear();
        TriangleSelectionStats tri;
        select_triangles(*state.hybrid, cam, settings, fs.epsilon_px, pool, ts.selected[i], tri);
        triangles_selected_ += tri.triangles;
        triangle_entries_scanned_ += tri.scanned;
        ts.batches.push_back({&*state.hybrid, identity ? nullptr : &inst.transform,
                              ts.selected[i]});
      }
    } else if (state.paged) {
      selected = state.paged->select(cam, settings, pool, into, !first_use,
                                     features && state.pages->features());
    } else {
      select_splats(inst.model->tree, cam, settings, pool, into, selected);
    }
    add(total, selected);
    const TreeFeatures* model_f = model_features(*inst.model);
    ChunkPlacement place;
    place.instance = static_cast<std::uint32_t>(i);
    place.transform = identity ? nullptr : &inst.transform;
    place.features = features;
    // Paged models fill their features from the pages during selection (or none: mixed,
    // unclipped); the others look them up by node.
    place.from_pages = fs.lod == LodScheme::QSplat && state.paged && state.pages->features();
    place.tree_features = fs.lod == LodScheme::Spt
                              ? (state.spt_features ? &*state.spt_features : nullptr)
                          : state.paged ? nullptr
                                        : inst.model->tree.features;
    place.id_base = id_base;
    place.base_color = any_colors && !into.has_colors;
    place.splat_scale = fs.splat_scale;
    place.with_discs = with_discs;
    for (std::size_t c = 0; c < into.chunk_count; ++c) {
      place_chunk(into.chunks[c], place, settings);
    }
    if (hybrid) {
      // Where splats and triangles of one surface overlap, the triangles show: each splat (a
      // disc flat at its centre's depth, which pokes half out of a curved or tilted surface) is
      // drawn one radius deeper. Surfaces farther apart than a splat radius keep their order.
      for (std::size_t c = 0; c < into.chunk_count; ++c) {
        SplatChunk& ch = into.chunks[c];
        for (std::size_t k = 0; k < ch.count; ++k) {
          const float radius_px = 0.5f * ch.size_px[k];
          ch.depth[k] += world.ortho ? radius_px / world.focal_px
                                     : ch.depth[k] * radius_px / world.focal_px;
        }
      }
    }
    if (model_f) id_base += model_f->surface_count;
    if (i > 0) append_chunks(stream, into);
  }
  stream.has_colors = any_colors;
  stream.has_features = features;
  return total;
}

std::size_t Renderer::load_requested(ThreadPool& pool, std::size_t max_pages,
                                     std::uint64_t max_storage_bytes) {
  std::size_t n = 0;
  for (ModelState* s : last_frame_) {
    if (s->paged) n += s->paged->load_requested(pool, max_pages, max_storage_bytes);
  }
  return n;
}

std::size_t Renderer::request_in_background(std::size_t max_pages,
                                            std::uint64_t max_storage_bytes) {
  std::size_t n = 0;
  for (ModelState* s : last_frame_) {
    if (s->paged) n += s->paged->request_in_background(max_pages, max_storage_bytes);
  }
  return n;
}

void Renderer::wait_for_loader() {
  for (ModelState* s : last_frame_) {
    if (s->paged) s->paged->wait_for_loader();
  }
}

bool Renderer::complete() const {
  for (const ModelState* s : last_frame_) {
    if (s->paged && !s->paged->complete()) return false;
  }
  return true;
}

bool Renderer::loading() const {
  for (const ModelState* s : last_frame_) {
    if (s->paged && s->paged->loading()) return true;
  }
  return false;
}

bool Renderer::paging() const {
  for (const ModelState* s : last_frame_) {
    if (s->paged) return true;
  }
  return false;
}

bool Renderer::pages_any(std::span<const SceneInstance> scene) const {
  if (options_.page_all) return !scene.empty();
  return std::any_of(scene.begin(), scene.end(),
                     [](const SceneInstance& i) { return i.model->pages != nullptr; });
}

PagingStats Renderer::paging_stats() const {
  PagingStats p;
  for (const ModelState* s : last_frame_) {
    if (!s->paged) continue;
    p.paged = true;
    p.pages += s->pages->page_count();
    p.model_bytes += s->model_bytes;
    const PageCacheStats& c = s->paged->stats();
    p.cache.pages_requested += c.pages_requested;
    p.cache.bytes_read += c.bytes_read;
    p.cache.resident_bytes += c.resident_bytes;
    p.cache.resident_bytes_peak += c.resident_bytes_peak;
    p.cache.resident_pages += c.resident_pages;
    p.cache.resident_page_bytes += c.resident_page_bytes;
    p.cache.pages_loaded += c.pages_loaded;
    p.cache.pages_deepened += c.pages_deepened;
    p.cache.pages_evicted += c.pages_evicted;
    p.complete = p.complete && s->paged->complete();
  }
  return p;
}

}  // namespace pointillist
