// The folder where scripts/fetch-models.sh keeps the sample models (the Stanford dragon and
// bunny, the lion LAS scan): $POINTILLIST_MODELS, else $XDG_CACHE_HOME/pointillist/models, else
// ~/.cache/pointillist/models. The CLI's demo, the benchmarks and the tests look there.
#pragma once

#include <filesystem>
#include <string>

namespace pointillist {

// The folder (which may not exist); empty when neither variable nor HOME is set.
std::filesystem::path model_cache_dir();

// The path of `file_name` in that folder, or "" when it is not there.
std::string cached_model_path(const std::string& file_name);

}  // namespace pointillist
