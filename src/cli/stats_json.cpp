#include "stats_json.hpp"

#include <cstdio>

namespace pointillist::cli {

std::string stats_to_json(const RenderStats& s, const std::string& extra) {
  char buf[2048];
  std::snprintf(buf, sizeof buf,
                "{\n"
                "  \"splats\": %llu,\n"
                "  \"nodes_visited\": %llu,\n"
                "  \"culled_frustum\": %llu,\n"
                "  \"culled_backface\": %llu,\n"
                "  \"width\": %d,\n"
                "  \"height\": %d,\n"
                "  \"threads\": %u,\n"
                "%s"
                "  \"ms\": {\"select\": %.3f, \"raster\": %.3f, \"total\": %.3f}\n"
                "}\n",
                static_cast<unsigned long long>(s.splats),
                static_cast<unsigned long long>(s.nodes_visited),
                static_cast<unsigned long long>(s.culled_frustum),
                static_cast<unsigned long long>(s.culled_backface), s.width, s.height, s.threads,
                extra.c_str(), s.ms_select, s.ms_raster, s.ms_total);
  return buf;
}

std::string sequence_to_json(std::span<const SequenceFrame> frames, double target_ms,
                             std::size_t settle, float finest, const std::string& extra) {
  std::string json =
      frames.empty() ? std::string("{\n}\n") : stats_to_json(frames.back().stats, extra);
  json.erase(json.rfind('}'));  // reopen the object
  while (!json.empty() && (json.back() == '\n' || json.back() == ' ')) json.pop_back();
  char buf[512];
  if (target_ms > 0) {
    std::snprintf(buf, sizeof buf, ",\n  \"target_ms\": %.3f,\n  \"hit_rate\": %.4f",
                  target_ms, hit_rate(frames, target_ms, settle, finest));
    json += buf;
  }
  json += ",\n  \"frames\": [";
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const SequenceFrame& f = frames[i];
    std::snprintf(buf, sizeof buf,
                  "%s\n    {\"phase\": \"%s\", \"azimuth\": %.3f, \"threshold\": %.4f, "
                  "\"splats\": %llu, \"ms\": %.3f, \"ms_select\": %.3f, \"ms_raster\": %.3f}",
                  i ? "," : "", f.phase, f.azimuth_deg, f.detail,
                  static_cast<unsigned long long>(f.stats.splats), f.stats.ms_total,
                  f.stats.ms_select, f.stats.ms_raster);
    json += buf;
    if (f.bytes_read >= 0) {
      json.pop_back();  // '}'
      std::snprintf(buf, sizeof buf, ", \"bytes_read\": %lld, \"resident_bytes\": %lld}",
                    static_cast<long long>(f.bytes_read), static_cast<long long>(f.resident_bytes));
      json += buf;
    }
  }
  json += "\n  ]\n}\n";
  return json;
}

}  // namespace pointillist::cli
