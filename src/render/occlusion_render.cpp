// The renderer with occlusion culling (renderer.hpp, occlusion.hpp): a hierarchy over the scene
// (a BVH over the instances, then each model's sphere tree down to culling leaves), traversed
// front to back by stop-and-wait, CHC or CHC++; the culling leaves found visible are selected
// and drawn batch by batch into the frame, whose depth the queries test through a max-depth
// pyramid. The fast rasterizer's image depends only on the set of splats drawn (ties go to the
// smaller colour), and only splats strictly behind what is drawn are skipped, so the image is
// the same bits as without culling.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>

#include "frame_pass.hpp"
#include "raster/quality_occluders.hpp"
#include "renderer_state.hpp"
#include "select/stream_features.hpp"
#include "select/subtree_selection.hpp"
#include "shading.hpp"
#include "pointillist/core/error.hpp"

namespace pointillist {

using namespace render_detail;


namespace {

using Clock = std::chrono::steady_clock;
// Culling-hierarchy nodes of a scene at most (about 1 GB of hierarchy and per-frame state).
constexpr std::uint64_t kMaxCullNodes = std::uint64_t{1} << 24;

}  // namespace

void Renderer::render_occluded(std::span<const SceneInstance> scene, const Camera& camera,
                               const RenderSettings& settings, const FrameSettings& fs,
                               ThreadPool& pool, Frame& frame) {
  const auto start = Clock::now();
  const OcclusionSettings& os = fs.occlusion;
  if (os.leaf_points == 0) {
    throw OptionError("occlusion culling leaves of 0 points are invalid; give at least 1");
  }
  if (!(settings.threshold_px > 0.0f) || !std::isfinite(settings.threshold_px)) {
    throw OptionError("splat size threshold " + std::to_string(settings.threshold_px) +
                      " px is invalid; give a positive number of pixels (1 draws every detail)");
  }
  const CameraFrame cam = make_camera_frame(camera);
  size_frame(frame, cam);
  OcclusionStats ostats;
  // Quality mode: culling draws each visible leaf's splats as occluders (an upper bound on each
  // pixel's reconstruction bound, quality_occluders.hpp), then the quality rasterizer draws the
  // visible leaves once more in the order of no culling, so that its sums are the same.
  const bool quality = fs.rasterizer == Rasterizer::Quality;
  if (scene.empty()) {  // nothing to draw: the background
    frame.splats.chunk_count = 0;
    begin_splats(cam, settings, pool, frame.scratch, frame.depth);
    finish_splats(cam, pool, frame.scratch, frame.color, frame.depth);
    fill_stats(frame, {}, cam, pool.thread_count(), start, start, Clock::now());
    return;
  }

  const bool spt = fs.lod == LodScheme::Spt;
  // The models' cull trees and the scene's hierarchy (rebuilt when the scene changes).
  std::vector<ModelState*> states(scene.size());
  for (std::size_t i = 0; i < scene.size(); ++i) {
    ModelState& st = state_for(*scene[i].model, pool, fs);
    if (st.frame != frame_number_) {
      last_frame_.push_back(&st);
      // A paged model starts its frame here: every selection of its instances adds to it.
      if (st.paged) st.paged->begin_frame();
    }
    st.frame = frame_number_;
    if (spt) {
      if (!st.spt_cull_tree) st.spt_cull_tree = build_spt_cull_tree(*st.spt);
    } else if (st.paged) {
      // A paged model is one culling leaf: hidden, it selects nothing and requests no pages.
      if (!st.cull_tree) {
        st.cull_tree.emplace();
        st.cull_tree->nodes.push_back(
            {0, UINT32_MAX, 0, 0, 1,
             static_cast<std::uint32_t>(std::min<std::uint64_t>(
                 st.paged->summary().leaf_count, UINT32_MAX))});
      }
    } else if (!st.cull_tree || st.cull_tree->leaf_points != os.leaf_points) {
      st.cull_tree = build_cull_tree(scene[i].model->tree.nodes, os.leaf_points);
    }
    states[i] = &st;
  }
  const auto paged = [&](std::uint32_t i) { return !spt && states[i]->paged.has_value(); };
  // The cull tree of instance i's model, and a node's sphere in model space.
  const auto cull_tree = [&](std::uint32_t i) -> const ModelCullTree& {
    return spt ? *states[i]->spt_cull_tree : *states[i]->cull_tree;
  };
  const auto model_bound = [&](std::uint32_t i, const ModelCullTree::Node& mn) -> Sphere {
    if (paged(i)) return states[i]->paged->root_sphere();
    if (!spt) {
      const SphereNode& n = scene[i].model->tree.nodes[mn.tree_node];
      return {n.center, n.radius};
    }
    const SequentialPointTree& t = *states[i]->spt;
    return mn.tree_node >= kSptTopList ? spt_top_bounds(t) : t.chunks[mn.tree_node].bounds;
  };
  if (!cull_ || !cull_->matches(scene, os.leaf_points, fs.lod)) {
    // The hierarchy holds every instance's cull tree: bound its size before building it.
    std::uint64_t total = 2 * scene.size();
    for (std::uint32_t i = 0; i < scene.size(); ++i) total += cull_tree(i).nodes.size();
    if (total > kMaxCullNodes) {
      throw OptionError("occlusion culling would need a hierarchy of " + std::to_string(total) +
                        " nodes over " + std::to_string(scene.size()) +
                        " instances (at most " + std::to_string(kMaxCullNodes) +
                        "); give a larger --cull-leaf (now " + std::to_string(os.leaf_points) +
                        " points)");
    }
    cull_ = std::make_unique<SceneCull>();
    SceneCull& c = *cull_;
    c.leaf_points = os.leaf_points;
    c.lod = fs.lod;
    for (const SceneInstance& inst : scene) c.scene.emplace_back(inst.model, inst.transform);
    build_scene_hierarchy(scene, cull_tree, model_bound, c);
  }
  SceneCull& c = *cull_;

  // Per-instance views (model space), made when an instance is first reached in the frame.
  std::vector<InstanceView>& views = c.views;
  views.resize(scene.size());
  for (InstanceView& v : views) v.ready = false;
  bool any_colors = false, any_features = false;
  for (const SceneInstance& inst : scene) {
    any_colors = any_colors || inst.model->tree.has_colors;
    any_features = any_features || inst.model->tree.features;
  }
  const bool features = fs.features && any_features;
  const bool with_discs = features || quality;
  // Sharp features in quality mode: how far behind a sure occluder the bound of a pixel's front
  // surface may lie (quality_occluders.hpp). The renderer refuses the lists and pages, whose
  // drawn radii this does not bound.
  quality_detail::FeatureOccluderBound feature_bound;
  if (quality && features) {
    float leaf_radius = 0;
    for (std::uint32_t i = 0; i < scene.size(); ++i) {
      ModelState& st = *states[i];
      if (!st.largest_leaf) st.largest_leaf = largest_leaf_radius(st.model->tree);
      leaf_radius = std::max(leaf_radius, *st.largest_leaf * scene[i].transform.scale);
    }
    feature_bound = quality_detail::feature_occluder_bound(fs.quality, fs.splat_scale,
                                                           settings.threshold_px, cam, leaf_radius);
  }
  {
    std::uint32_t id_base = 0;
    for (std::size_t i = 0; i < scene.size(); ++i) {
      views[i].id_base = id_base;
      if (const TreeFeatures* f = scene[i].model->tree.features) id_base += f->surface_count;
    }
  }
  const std::uint8_t root_tests =
      static_cast<std::uint8_t>((settings.frustum_culling ? kTestFrustum : 0) |
                                (settings.culls_backfaces() ? kTestBackface : 0));
  const auto view_of = [&](std::uint32_t i) -> InstanceView& {
    InstanceView& iv = views[i];
    if (!iv.ready) {
      iv.identity = scene[i].transform.is_identity();
      iv.cam = iv.identity ? cam : model_camera_frame(camera, cam, scene[i].transform);
      iv.shader.emplace(settings, iv.cam);
      iv.v = make_view_constants(*iv.shader, iv.cam, settings, with_discs);
      iv.ready = true;
    }
    return iv;
  };

  // Per node of this frame: the tests left when it is reached (its parent's result) and after.
  std::vector<std::uint8_t>& tests_in = c.tests_in;
  std::vector<std::uint8_t>& tests_out = c.tests_out;
  tests_in.assign(c.h.nodes.size(), root_tests);
  tests_out.assign(c.h.nodes.size(), root_tests);
  c.weight.resize(c.h.nodes.size());
  Counters counters;
  const float min_splats = static_cast<float>(os.min_query_splats);
  CullCallbacks callbacks;
  callbacks.visit = [&](std::uint32_t n) {
    CullCallbacks::Visit out;
    const CullHierarchy::Node& hn = c.h.nodes[n];
    const SceneCull::Meta& m = c.meta[n];
    const Vec3f d = hn.bound.center - cam.eye;
    const float z = dot(d, cam.forward);
    out.distance = std::max(0.0f, length(d) - hn.bound.radius);
    out.near = z - hn.bound.radius <= 0.0f;
    const bool paged_leaf = m.instance != UINT32_MAX && paged(m.instance);
    if (m.instance == UINT32_MAX || paged_leaf) {
      // A BVH node or a paged model: culled when outside a side plane of the view frustum or
      // behind the eye.
      if (settings.frustum_culling) {
        if (z <= -hn.bound.radius) return out;
        for (const Plane& p : cam.planes) {
          if (p.distance(hn.bound.center) <= -hn.bound.radius) return out;
        }
      }
      out.kind = paged_leaf ? CullCallbacks::Kind::Leaf : CullCallbacks::Kind::Interior;
      if (paged_leaf) c.weight[n] = static_cast<float>(cull_tree(m.instance).nodes[0].points);
      return out;
    }
    InstanceView& iv = view_of(m.instance);
    const ModelCullTree& t = cull_tree(m.instance);
    const ModelCullTree::Node& mn = t.nodes[m.local];
    if (spt) {
      // The model's root holds its ranges; the top list is always scanned; a chunk outside
      // the view is skipped as the plain selection skips it.
      c.weight[n] = static_cast<float>(mn.points);
      if (m.local == 0) {
        out.kind = CullCallbacks::Kind::Interior;
      } else if (mn.tree_node < kSptTopList && fs.spt_chunk_culling &&
                 settings.frustum_culling &&
                 spt_chunk_outside(iv.cam, states[m.instance]->spt->chunks[mn.tree_node].bounds)) {
        return out;
      } else {
        out.kind = CullCallbacks::Kind::Leaf;
      }
      return out;
    }
    const SphereNode& node = scene[m.instance].model->tree.nodes[mn.tree_node];
    const std::uint32_t parent = hn.parent;
    std::uint8_t tests = (m.local == 0 || parent == UINT32_MAX) ? root_tests : tests_out[parent];
    tests_in[n] = tests;
    Vec3f dm;
    float zm;
    const Decision decision = visit(node, iv.v, tests, counters, dm, zm);
    tests_out[n] = tests;
    if (decision == Decision::Cull) return out;
    if (decision == Decision::Draw) {
      out.kind = CullCallbacks::Kind::Leaf;  // the detail stops here: one splat
      out.small = true;
      c.weight[n] = 1.0f;
      return out;
    }
    out.kind = mn.child_count == 0 ? CullCallbacks::Kind::Leaf : CullCallbacks::Kind::Interior;
    // Splats expected: at most its points, about (projected size / threshold)² of them.
    c.weight[n] = static_cast<float>(mn.points);
    if (zm > 0) {
      const float across = node.radius * iv.v.size_per_radius / (zm * settings.threshold_px);
      c.weight[n] = std::min(c.weight[n], across * across);
      out.small = c.weight[n] < min_splats;
    }
    return out;
  };
  // R6: the spheres of the descendants down to tight_depth levels, while they are not much
  // larger in total than the node's own (Σ r² ≤ ratio · r²).
  std::vector<std::uint32_t> level, next;
  callbacks.bounds = [&](std::uint32_t n, std::vector<QueryBound>& out) {
    const SceneCull::Meta& m = c.meta[n];
    if (m.instance != UINT32_MAX && (spt || paged(m.instance))) {
      out.push_back(c.h.nodes[n].bound);  // an SPT range, a paged model: its one sphere
      return;
    }
    if (m.instance == UINT32_MAX) {
      // A BVH node: its children's spheres, levels down while they are not much larger in
      // total (an instance's root stands for its model).
      level.assign(1, n);
      for (unsigned depth = 0; depth < os.tight_depth; ++depth) {
        next.clear();
        double area = 0, own = 0;
        for (const std::uint32_t k : level) {
          const CullHierarchy::Node& p = c.h.nodes[k];
          own += double(p.bound.radius) * p.bound.radius;
          if (c.meta[k].instance != UINT32_MAX || p.child_count == 0) {
            next.push_back(k);
            area += double(p.bound.radius) * p.bound.radius;
            continue;
          }
          for (std::uint32_t j = 0; j < p.child_count; ++j) {
            const std::uint32_t ch = c.h.children[p.first_child + j];
            next.push_back(ch);
            area += double(c.h.nodes[ch].bound.radius) * c.h.nodes[ch].bound.radius;
          }
        }
        if (area > os.tight_area_ratio * own) break;
        level.swap(next);
      }
      for (const std::uint32_t k : level) out.push_back(c.h.nodes[k].bound);
      return;
    }
    const auto& nodes = scene[m.instance].model->tree.nodes;
    const InstanceTransform& tf = scene[m.instance].transform;
    const std::uint32_t root = cull_tree(m.instance).nodes[m.local].tree_node;
    level.assign(1, root);
    for (unsigned depth = 0; depth < os.tight_depth; ++depth) {
      next.clear();
      double area = 0, own = 0;
      for (const std::uint32_t k : level) {
        const SphereNode& p = nodes[k];
        own += double(p.radius) * p.radius;
        if (p.child_count == 0) {
          next.push_back(k);
          area += double(p.radius) * p.radius;
          continue;
        }
        for (std::uint32_t j = 0; j < p.child_count; ++j) {
          next.push_back(p.first_child + j);
          area += double(nodes[p.first_child + j].radius) * nodes[p.first_child + j].radius;
        }
      }
      if (area > os.tight_area_ratio * own) break;
      level.swap(next);
    }
    for (const std::uint32_t k : level) {
      const Sphere s = world_sphere(tf, nodes[k]);
      out.push_back({s.center, s.radius});
    }
  };

  // Drawing a batch of visible leaves: each selected into its own chunk, in parallel, then
  // rasterized into the frame.
  SplatStream& stream = frame.splats;
  stream.chunk_count = 0;
  stream.with_discs = with_discs;
  stream.has_colors = any_colors;
  stream.has_features = features;
  double ms_select = 0, ms_raster = 0;
  std::vector<Counters> task_counters;
  std::vector<SptSelectionStats> spt_counters;
  std::vector<std::vector<std::uint32_t>> group_ends;  // quality: each leaf's end in its chunk
  std::vector<SoftwareQueries::Rect> rects;
  std::vector<std::uint8_t>& instance_drawn = c.instance_drawn;
  instance_drawn.assign(scene.size(), 0);
  if (quality) {
    std::fill(frame.depth.begin(), frame.depth.end(), std::numeric_limits<float>::infinity());
  } else {
    begin_splats(cam, settings, pool, frame.scratch, frame.depth);
  }
  c.pyramid.reset(frame.depth, cam.width, cam.height);
  // A batch's leaves are selected in groups (one chunk each, in parallel): leaves of one instance
  // up to about kGroupSplats expected splats together, so a thousand leaves drawn as one coarse
  // splat each do not make a thousand chunks. The fast rasterizer's image does not depend on
  // how the splats are grouped or ordered.
  constexpr float kGroupSplats = 4096.0f;
  std::vector<std::uint32_t> order, paged_leaves;
  std::vector<std::pair<std::size_t, std::size_t>> groups;
  // Leaves in the order of the selection without culling: by instance, then depth first (an
  // instance's nodes are numbered depth first).
  const auto canonical = [&](std::uint32_t a, std::uint32_t b) {
    return c.meta[a].instance < c.meta[b].instance ||
           (c.meta[a].instance == c.meta[b].instance && a < b);
  };
  // Quality mode: every leaf drawn this frame, and where its splats are in the stream.
  std::vector<std::pair<std::uint32_t, quality_detail::StreamPiece>>& drawn = c.drawn;
  drawn.clear();
  // How a chunk of instance `instance` is made ready for the rasterizers (place_chunk).
  const auto placement = [&](std::uint32_t instance, bool colored, const TreeFeatures* f,
                             bool from_pages) {
    const InstanceView& iv = views[instance];
    ChunkPlacement p;
    p.instance = instance;
    p.transform = iv.identity ? nullptr : &scene[instance].transform;
    p.features = features;
    p.from_pages = from_pages;
    p.tree_features = f;
    p.id_base = iv.id_base;
    p.base_color = any_colors && !colored;
    p.splat_scale = fs.splat_scale;
    p.with_discs = with_discs;
    return p;
  };
  // A paged model's visible instance: its selection (which requests the pages it needs) moved
  // behind the stream's chunks; in the fast mode each chunk's pixel rectangle goes to `rects`,
  // in the quality mode each chunk is a piece of leaf n.
  const QueryFootprint footprint =
      quality ? quality_detail::quality_query_footprint(fs.quality, fs.splat_scale)
              : QueryFootprint{std::max(1.0f, fs.splat_scale)};
  // Inside a visible paged model, each subtree in another page is tested against what is drawn
  // so far (the pyramid of the batches before this one: a subset of the frame's occluders), so
  // a hidden page is neither drawn nor requested.
  std::atomic<std::uint64_t> paged_tiles{0};
  const auto select_paged = [&](std::uint32_t n) {
    const std::uint32_t instance = c.meta[n].instance;
    ModelState& st = *states[instance];
    const bool page_features = features && st.pages->features();
    scratch_stream_.with_discs = with_discs;
    const InstancePyramidTest test{&c.pyramid, &cam, &scene[instance].transform, &footprint,
                                   &paged_tiles};
    const SubtreeOcclusion occlusion = test.occlusion();
    const SelectionStats sel = st.paged->select(views[instance].cam, settings, pool,
                                                scratch_stream_, true, page_features, &occlusion);
    counters.visited += sel.nodes_visited;
    counters.culled_frustum += sel.culled_frustum;
    counters.culled_backface += sel.culled_backface;
    ostats.paged_subtrees_culled += sel.culled_occluded;
    const ChunkPlacement place =
        placement(instance, scratch_stream_.has_colors, nullptr, page_features);
    for (std::size_t k = 0; k < scratch_stream_.chunk_count; ++k) {
      place_chunk(scratch_stream_.chunks[k], place, settings);
    }
    for (std::size_t at = append_chunks(stream, scratch_stream_); at < stream.chunk_count; ++at) {
      const SplatChunk& placed = stream.chunks[at];
      if (quality) {
        drawn.push_back({n, {static_cast<std::uint32_t>(at), 0,
                             static_cast<std::uint32_t>(placed.count)}});
      } else {
        rects.push_back(chunk_pixel_rect(placed, cam));
      }
    }
  };
  // Selects the leaves of `order` (in canonical order) into chunks appended to the stream, in
  // that order, adds the selection's counts to the frame's and, in the fast mode, writes the
  // pixel rectangles the chunks may touch to `rects`; returns the first chunk.
  const auto select_order = [&]() {
    groups.clear();
    float weight = 0;
    for (std::size_t k = 0; k < order.size(); ++k) {
      const std::uint32_t n = order[k];
      view_of(c.meta[n].instance);
      instance_drawn[c.meta[n].instance] = 1;
      if (groups.empty() || c.meta[n].instance != c.meta[order[k - 1]].instance ||
          weight + c.weight[n] > kGroupSplats) {
        groups.emplace_back(k, k);
        weight = 0;
      }
      groups.back().second = k + 1;
      weight += c.weight[n];
    }
    const std::size_t first = stream.chunk_count;
    if (stream.chunks.size() < first + groups.size()) stream.chunks.resize(first + groups.size());
    const bool with_rects = !quality;
    task_counters.assign(groups.size(), {});
    spt_counters.assign(groups.size(), {});
    if (group_ends.size() < groups.size()) group_ends.resize(groups.size());
    rects.assign(groups.size(), {});
    pool.run(groups.size(), [&](std::size_t g) {
      const std::uint32_t instance = c.meta[order[groups[g].first]].instance;
      const SceneInstance& inst = scene[instance];
      const InstanceView& iv = views[instance];
      SplatChunk& chunk = stream.chunks[first + g];
      const ModelState& st = *states[instance];
      group_ends[g].clear();
      if (spt) {
        chunk.count = 0;
        for (std::size_t k = groups[g].first; k < groups[g].second; ++k) {
          const ModelCullTree::Node& mn = st.spt_cull_tree->nodes[c.meta[order[k]].local];
          const SequentialPointTree& t = *st.spt;
          if (mn.tree_node == kSptTopList) {
            select_spt_range(t, 0, t.top_end, spt_top_bounds(t), iv.cam, settings, fs.epsilon_px,
                             *iv.shader, with_discs, chunk, spt_counters[g]);
          } else if (mn.tree_node < kSptTopList) {
            const SptChunk& sc = t.chunks[mn.tree_node];
            select_spt_range(t, sc.begin, sc.end, sc.bounds, iv.cam, settings, fs.epsilon_px,
                             *iv.shader, with_discs, chunk, spt_counters[g]);
          }
          if (quality) group_ends[g].push_back(static_cast<std::uint32_t>(chunk.count));
        }
      } else {
        thread_local std::vector<SubtreeRoot> roots;
        roots.clear();
        for (std::size_t k = groups[g].first; k < groups[g].second; ++k) {
          const std::uint32_t n = order[k];
          roots.push_back({st.cull_tree->nodes[c.meta[n].local].tree_node, tests_in[n]});
        }
        select_subtrees(inst.model->tree.nodes, roots, iv.v, inst.model->tree.has_colors, chunk,
                        task_counters[g], quality ? &group_ends[g] : nullptr);
      }
      const TreeFeatures* f =
          spt ? (st.spt_features ? &*st.spt_features : nullptr) : inst.model->tree.features;
      place_chunk(chunk,
                  placement(instance, spt ? st.spt->has_colors : inst.model->tree.has_colors, f,
                            false),
                  settings);
      if (with_rects) rects[g] = chunk_pixel_rect(chunk, cam);
    });
    stream.chunk_count = first + groups.size();
    for (std::size_t g = 0; g < groups.size(); ++g) {
      spt_stats_ += spt_counters[g];
      counters.visited += task_counters[g].visited;
      counters.culled_frustum += task_counters[g].culled_frustum;
      counters.culled_backface += task_counters[g].culled_backface;
    }
    return first;
  };
  const SoftwareQueries::Draw draw = [&](std::span<const std::uint32_t> batch, bool last) {
    const auto t0 = Clock::now();
    order.assign(batch.begin(), batch.end());
    std::sort(order.begin(), order.end(), canonical);
    // Paged models select on the pool themselves: one after the other, after the groups.
    const auto split = std::stable_partition(order.begin(), order.end(), [&](std::uint32_t n) {
      return !paged(c.meta[n].instance);
    });
    paged_leaves.assign(split, order.end());
    order.erase(split, order.end());
    const std::size_t first = select_order();
    if (quality) {
      // Where each leaf's splats are, for the quality pass.
      for (std::size_t g = 0; g < groups.size(); ++g) {
        std::uint32_t begin = 0;
        for (std::size_t k = groups[g].first; k < groups[g].second; ++k) {
          const std::uint32_t end = group_ends[g][k - groups[g].first];
          drawn.push_back({order[k], {static_cast<std::uint32_t>(first + g), begin, end}});
          begin = end;
        }
      }
    }
    ms_select += std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    SoftwareQueries::Rect dirty{cam.width, cam.height, 0, 0};
    // Draws the chunks from `drawn_to` on (quality: their setup and, with `occluders`, their
    // occluders; fast: the splats) and returns the pixels they may have changed.
    std::size_t drawn_to = first, rects_to = 0;
    const auto draw_new = [&](bool occluders) {
      SoftwareQueries::Rect d{cam.width, cam.height, 0, 0};
      if (quality) {
        d = quality_detail::draw_quality_occluders(stream, drawn_to, stream.chunk_count, cam,
                                                   settings, fs.quality, pool, quality_scratch_,
                                                   c.occluders, frame.depth, occluders,
                                                   feature_bound);
      } else {
        for (; rects_to < rects.size(); ++rects_to) d.add(rects[rects_to]);
        draw_splats(stream, drawn_to, stream.chunk_count, cam, settings, pool, frame.scratch,
                    frame.depth);
      }
      drawn_to = stream.chunk_count;
      return d;
    };
    if (!paged_leaves.empty()) {
      // Paged models select on the pool themselves, one after the other, near to far, each
      // after what the batch drew before it, so that their pages are tested against it.
      std::sort(paged_leaves.begin(), paged_leaves.end(), [&](std::uint32_t a, std::uint32_t b) {
        const float da = length(c.h.nodes[a].bound.center - cam.eye) - c.h.nodes[a].bound.radius;
        const float db = length(c.h.nodes[b].bound.center - cam.eye) - c.h.nodes[b].bound.radius;
        return da < db || (da == db && a < b);
      });
      for (const std::uint32_t n : paged_leaves) {
        const auto ts = Clock::now();
        const SoftwareQueries::Rect d = draw_new(true);
        dirty.add(d);
        if (!d.empty()) c.pyramid.refresh(d.x0, d.y0, d.x1, d.y1);
        const auto tp = Clock::now();
        ms_raster += std::chrono::duration<double, std::milli>(tp - ts).count();
        view_of(c.meta[n].instance);
        instance_drawn[c.meta[n].instance] = 1;
        select_paged(n);
        ms_select += std::chrono::duration<double, std::milli>(Clock::now() - tp).count();
      }
    }
    // The rest, and their occluders unless no query follows.
    const auto t1 = Clock::now();
    dirty.add(draw_new(!last));
    ms_raster += std::chrono::duration<double, std::milli>(Clock::now() - t1).count();
    return dirty;
  };
  SoftwareQueries queries(c.pyramid, cam, footprint, os.query_latency, draw, ostats);
  cull_frame(c.h, callbacks, os, queries, c.state, ostats);
  if (quality) {
    // The quality pass over the visible leaves' splats in the order of no culling (the setup of
    // every chunk is the occluder pass's).
    const auto t0 = Clock::now();
    std::sort(drawn.begin(), drawn.end(), [&](const auto& a, const auto& b) {
      return canonical(a.first, b.first) ||
             (a.first == b.first && a.second.chunk < b.second.chunk);  // a paged model's chunks
    });
    std::vector<quality_detail::StreamPiece>& pieces = c.pieces;
    pieces.clear();
    for (const auto& d : drawn) {
      const quality_detail::StreamPiece& p = d.second;
      if (p.end <= p.begin) continue;
      if (!pieces.empty() && pieces.back().chunk == p.chunk && pieces.back().end == p.begin) {
        pieces.back().end = p.end;  // the next leaf of the same group: one run
      } else {
        pieces.push_back(p);
      }
    }
    quality_detail::rasterize_quality_pieces(stream, pieces, cam, settings, fs.quality, pool,
                                             quality_scratch_, frame.color, frame.depth);
    ms_raster += std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  } else {
    finish_splats(cam, pool, frame.scratch, frame.color, frame.depth);
  }

  SelectionStats selection;
  selection.splats = stream.size();
  selection.nodes_visited = counters.visited;
  selection.culled_frustum = counters.culled_frustum;
  selection.culled_backface = counters.culled_backface;
  for (const std::uint8_t d : instance_drawn) ostats.instances_drawn += d;
  const auto done = Clock::now();
  fill_stats(frame, selection, cam, pool.thread_count(), start, start, done);
  frame.stats.ms_select = ms_select;
  frame.stats.ms_raster = ms_raster;
  ostats.tiles_tested += paged_tiles;
  frame.stats.occlusion = ostats;
  if (features) {
    RenderStats& s = frame.stats;
    for (std::size_t ch = 0; ch < stream.chunk_count; ++ch) {
      const SplatChunk& chunk = stream.chunks[ch];
      for (std::size_t i = 0; i < chunk.count; ++i) {
        s.clipped_splats += clip_count(chunk.clip_code[i]) != 0;
      }
    }
    s.clipped_fragments = frame.scratch.clipped_fragments;
    s.clip_pinholes_filled = frame.scratch.pinholes_filled;
  }
}

}  // namespace pointillist
