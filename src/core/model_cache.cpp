#include "pointillist/core/model_cache.hpp"

#include <cstdlib>

namespace pointillist {

std::filesystem::path model_cache_dir() {
  if (const char* env = std::getenv("POINTILLIST_MODELS"); env && *env) return env;
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) {
    return std::filesystem::path(xdg) / "pointillist" / "models";
  }
  if (const char* home = std::getenv("HOME"); home && *home) {
    return std::filesystem::path(home) / ".cache" / "pointillist" / "models";
  }
  return {};
}

std::string cached_model_path(const std::string& file_name) {
  const std::filesystem::path dir = model_cache_dir();
  if (dir.empty()) return {};
  std::error_code ec;
  const auto path = dir / file_name;
  return std::filesystem::exists(path, ec) ? path.string() : std::string{};
}

}  // namespace pointillist
