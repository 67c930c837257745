#include "util.hpp"

#include <malloc.h>

#include <cstdio>
#include <filesystem>
#include <limits>

namespace pointillist::cli {

void keep_freed_memory() {
  ::mallopt(M_MMAP_MAX, 0);
  ::mallopt(M_TRIM_THRESHOLD, std::numeric_limits<int>::max());
}

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

std::string input_names(std::span<const std::string> inputs, bool file_names) {
  std::string names;
  for (std::size_t i = 0; i < inputs.size() && i < 3; ++i) {
    if (i) names += ", ";
    names += file_names ? std::filesystem::path(inputs[i]).filename().string() : inputs[i];
  }
  if (inputs.size() > 3) names += " and " + std::to_string(inputs.size() - 3) + " more";
  return names;
}

}  // namespace pointillist::cli
