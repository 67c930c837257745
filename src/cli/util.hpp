// Small helpers shared by the subcommands.
#pragma once

#include <string>

namespace pointillist::cli {

// "1.23 MB"-style size.
std::string human_bytes(double bytes);

// Path of a model fetched by scripts/fetch-models.sh ($POINTILLIST_MODELS, else
// $XDG_CACHE_HOME/pointillist/models, else ~/.cache/pointillist/models), or "" if absent.
std::string cached_model_path(const std::string& file_name);

}  // namespace pointillist::cli
