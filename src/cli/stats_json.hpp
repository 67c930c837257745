// Render statistics as JSON (for --stats).
#pragma once

#include <string>

#include "pointillist/render/render.hpp"

namespace pointillist::cli {

// {"splats": ..., "nodes_visited": ..., ..., "ms": {"select": .., "raster": .., "total": ..}}
std::string stats_to_json(const RenderStats& stats);

}  // namespace pointillist::cli
