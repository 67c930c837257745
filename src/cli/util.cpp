#include "util.hpp"

#include <cstdio>
#include <cstdlib>
#include <filesystem>

namespace pointillist::cli {

std::string human_bytes(double bytes) {
  const char* units[] = {"B", "KB", "MB", "GB", "TB"};
  int u = 0;
  while (bytes >= 1000.0 && u < 4) {
    bytes /= 1000.0;
    ++u;
  }
  char buf[32];
  std::snprintf(buf, sizeof buf, u == 0 ? "%.0f %s" : "%.2f %s", bytes, units[u]);
  return buf;
}

std::string cached_model_path(const std::string& file_name) {
  std::filesystem::path dir;
  if (const char* env = std::getenv("POINTILLIST_MODELS"); env && *env) {
    dir = env;
  } else if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) {
    dir = std::filesystem::path(xdg) / "pointillist" / "models";
  } else if (const char* home = std::getenv("HOME"); home && *home) {
    dir = std::filesystem::path(home) / ".cache" / "pointillist" / "models";
  } else {
    return {};
  }
  const auto path = dir / file_name;
  return std::filesystem::exists(path) ? path.string() : std::string{};
}

}  // namespace pointillist::cli
