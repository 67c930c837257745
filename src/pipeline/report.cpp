#include "pointillist/pipeline/report.hpp"

#include <cmath>
#include <nlohmann/json.hpp>

namespace pointillist {
namespace {

using Json = nlohmann::ordered_json;

double ms(double v) { return std::round(v * 1000.0) / 1000.0; }

const char* kind_name(ModelKind k) {
  switch (k) {
    case ModelKind::Scan: return "scan";
    case ModelKind::PtlV1: return "ptl v1";
    case ModelKind::PtlV2: return "ptl v2";
    case ModelKind::Qsplat: return "qs";
  }
  return "?";
}

Json occlusion_json(const OcclusionSettings& o, const OcclusionStats& s) {
  return {{"method", name(o.method)},
          {"query_latency", o.query_latency},
          {"culling_nodes_visited", s.nodes_visited},
          {"leaves_drawn", s.leaves_drawn},
          {"leaves_culled", s.leaves_culled},
          {"instances_drawn", s.instances_drawn},
          {"queries_single", s.queries_single},
          {"queries_multi", s.queries_multi},
          {"multiquery_nodes", s.multiquery_nodes},
          {"multiquery_failed", s.multiquery_failed},
          {"v_queries", s.v_queries},
          {"queries_skipped_nav", s.queries_skipped},
          {"flushes", s.flushes},
          {"stalls", s.stalls},
          {"hiz_tiles_tested", s.tiles_tested},
          {"paged_subtrees_culled", s.paged_subtrees_culled},
          {"ms_query", ms(s.ms_query)},
          {"ms_hiz", ms(s.ms_hiz)}};
}

}  // namespace

std::string render_report_json(const RenderReport& r) {
  const RenderStats& s = r.last;
  const FrameSettings& f = r.frame;
  Json j;
  j["splats"] = s.splats;
  j["nodes_visited"] = s.nodes_visited;
  j["culled_frustum"] = s.culled_frustum;
  j["culled_backface"] = s.culled_backface;
  if (r.frame.features) {
    // Sharp features drawn in the last frame (zeros when no model has them).
    j["clipped_splats"] = s.clipped_splats;
    j["clipped_fragments"] = s.clipped_fragments;
    j["other_surface_fragments"] = s.other_surface_fragments;
    j["surface_switch_pixels"] = s.surface_switch_pixels;
    j["clip_pinholes_filled"] = s.clip_pinholes_filled;
  }
  j["width"] = s.width;
  j["height"] = s.height;
  j["threads"] = s.threads;
  const bool reference = f.rasterizer == Rasterizer::Reference;
  if (!reference) j["lod"] = name(f.lod);
  j["mode"] = name(f.rasterizer);
  if (f.rasterizer == Rasterizer::Quality) {
    j["reconstruction"] =
        f.quality.reconstruction == Reconstruction::ZRange ? "zrange" : "zthreshold";
    j["opacity"] = f.quality.opacity;
  }
  if (r.renderer && f.lod == LodScheme::Spt && !reference) {
    const SptSelectionStats& spt = r.renderer->spt_stats();
    j["list_length"] = spt.entries_total;
    j["entries_scanned"] = spt.entries_scanned;
    j["fraction_scanned"] =
        spt.entries_total ? double(spt.entries_scanned) / double(spt.entries_total) : 0.0;
    j["chunks"] = spt.chunks_total;
    j["chunks_culled"] = spt.chunks_culled;
    if (f.hybrid) {
      j["hybrid"] = true;
      j["triangle_px_per_epsilon"] = f.triangle_px_per_epsilon;
      j["triangles_selected"] = r.renderer->triangles_selected();
      j["triangles"] = s.triangles;
      j["triangle_entries_scanned"] = r.renderer->triangle_entries_scanned();
    }
  }
  if (f.occlusion.method != OcclusionMethod::None) j["occlusion"] = occlusion_json(f.occlusion, s.occlusion);
  if (r.renderer && r.renderer->paging()) {
    const PagingStats p = r.renderer->paging_stats();
    j["paged"] = true;
    j["pages"] = p.pages;
    j["model_bytes"] = p.model_bytes;
    j["memory_cap"] = r.memory_cap;
    j["bytes_read"] = p.cache.bytes_read;
    j["resident_bytes"] = p.cache.resident_bytes;
    j["resident_bytes_peak"] = p.cache.resident_bytes_peak;
    j["resident_page_bytes"] = p.cache.resident_page_bytes;
    j["pages_loaded"] = p.cache.pages_loaded;
    j["pages_deepened"] = p.cache.pages_deepened;
    j["pages_evicted"] = p.cache.pages_evicted;
    j["complete"] = p.complete;
  }
  if (r.scene) {
    Json models = Json::array();
    for (const auto& m : r.scene->models()) {
      Json model = {{"path", m->path()}, {"kind", kind_name(m->kind())},
                    {"paging", m->paging_reason()}};
      if (const TreeFeatures* features = m->features()) {
        const FeatureStats& fs = features->stats;
        model["features"] = {{"splats", fs.splats},
                             {"edges", fs.edges},
                             {"mean_degree", fs.mean_degree()},
                             {"sharp_edges", fs.sharp_edges},
                             {"crossing_edges", fs.crossing_edges},
                             {"candidates", fs.candidates},
                             {"clipped", fs.clipped},
                             {"undefined_4_15", fs.undefined_4_15},
                             {"segments", fs.segments},
                             {"large_segments", fs.large_segments}};
      }
      models.push_back(std::move(model));
    }
    j["models"] = std::move(models);
  }
  j["ms"] = {{"select", ms(s.ms_select)}, {"raster", ms(s.ms_raster)}, {"total", ms(s.ms_total)}};
  if (r.sequence) {
    if (r.target_ms > 0) {
      j["target_ms"] = r.target_ms;
      j["hit_rate"] = hit_rate(r.frames, r.target_ms, r.settle, r.finest);
    }
    Json frames = Json::array();
    for (const SequenceFrame& fr : r.frames) {
      Json o{{"phase", fr.phase}};
      if (fr.azimuth_deg) o["azimuth"] = *fr.azimuth_deg;  // orbit frames
      o["detail"] = fr.detail;
      o["splats"] = fr.stats.splats;
      if (f.hybrid) o["triangles"] = fr.stats.triangles;
      o["ms"] = ms(fr.stats.ms_total);
      o["ms_select"] = ms(fr.stats.ms_select);
      o["ms_raster"] = ms(fr.stats.ms_raster);
      if (f.occlusion.method != OcclusionMethod::None) {
        o["occlusion"] = occlusion_json(f.occlusion, fr.stats.occlusion);
      }
      if (fr.bytes_read >= 0) {
        o["bytes_read"] = fr.bytes_read;
        o["resident_bytes"] = fr.resident_bytes;
      }
      frames.push_back(std::move(o));
    }
    j["frames"] = std::move(frames);
  }
  return j.dump(2) + "\n";
}

}  // namespace pointillist
