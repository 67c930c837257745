#include "util.hpp"

#include <malloc.h>
#include <unistd.h>

#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <string_view>

namespace pointillist::cli {

void use_huge_pages(char** argv) {
#if defined(__linux__) && defined(__GLIBC__) && (__GLIBC__ > 2 || __GLIBC_MINOR__ >= 35)
  // Only the batch commands gain (rendering measured the same); the others start once.
  if (!argv[0] || !argv[1]) return;
  const std::string_view command = argv[1];
  if (command != "convert" && command != "generate") return;
  const char* asked = std::getenv("POINTILLIST_HUGE_PAGES");
  if (!asked || std::string_view(asked) != "1") return;  // off unless asked for
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  const std::string given = tunables ? tunables : "";
  if (given.find("glibc.malloc.hugetlb") != std::string::npos) return;
  std::ifstream mode_file("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string mode;
  std::getline(mode_file, mode);
  if (mode.find("[madvise]") == std::string::npos) return;
  const std::string wanted = (given.empty() ? "" : given + ":") + "glibc.malloc.hugetlb=1";
  if (::setenv("GLIBC_TUNABLES", wanted.c_str(), 1) != 0) return;
  ::execv("/proc/self/exe", argv);
  // Not started again: run as we are, without the tunable in the environment of children.
  if (tunables) {
    ::setenv("GLIBC_TUNABLES", tunables, 1);
  } else {
    ::unsetenv("GLIBC_TUNABLES");
  }
#else
  (void)argv;
#endif
}

void keep_freed_memory() {
  ::mallopt(M_MMAP_MAX, 0);
  ::mallopt(M_TRIM_THRESHOLD, -1);  // never trim (INT_MAX still trimmed a free top over 2 GB)
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

std::string lowercase_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
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
