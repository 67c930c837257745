#include "cli/stats_json.hpp"

#include <cstdio>

namespace pointillist::cli {

std::string stats_to_json(const RenderStats& s) {
  char buf[1024];
  std::snprintf(buf, sizeof buf,
                "{\n"
                "  \"splats\": %llu,\n"
                "  \"nodes_visited\": %llu,\n"
                "  \"culled_frustum\": %llu,\n"
                "  \"culled_backface\": %llu,\n"
                "  \"width\": %d,\n"
                "  \"height\": %d,\n"
                "  \"threads\": %u,\n"
                "  \"ms\": {\"select\": %.3f, \"raster\": %.3f, \"total\": %.3f}\n"
                "}\n",
                static_cast<unsigned long long>(s.splats),
                static_cast<unsigned long long>(s.nodes_visited),
                static_cast<unsigned long long>(s.culled_frustum),
                static_cast<unsigned long long>(s.culled_backface), s.width, s.height, s.threads,
                s.ms_select, s.ms_raster, s.ms_total);
  return buf;
}

}  // namespace pointillist::cli
