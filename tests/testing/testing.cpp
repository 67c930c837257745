#include "testing/testing.hpp"

#include <atomic>
#include <cstdlib>
#include <random>
#include <unistd.h>

#include <gtest/gtest.h>

namespace pointillist::testing {

std::filesystem::path test_data_dir() { return POINTILLIST_TEST_DATA_DIR; }
std::filesystem::path shared_testdata_dir() { return POINTILLIST_SHARED_TESTDATA_DIR; }

std::filesystem::path model_cache_dir() {
  if (const char* dir = std::getenv("POINTILLIST_MODELS"); dir && *dir) return dir;
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg)
    return std::filesystem::path(xdg) / "pointillist" / "models";
  const char* home = std::getenv("HOME");
  return std::filesystem::path(home ? home : "/tmp") / ".cache" / "pointillist" / "models";
}

std::filesystem::path cached_model(const std::string& file_name) {
  const auto path = model_cache_dir() / file_name;
  return std::filesystem::exists(path) ? path : std::filesystem::path{};
}

TempDir::TempDir() {
  static std::atomic<int> counter{0};
  const auto base = std::filesystem::temp_directory_path();
  for (;;) {
    path_ = base / ("pointillist-test-" + std::to_string(::getpid()) + "-" +
                    std::to_string(counter++));
    if (std::filesystem::create_directory(path_)) break;
  }
}

TempDir::~TempDir() {
  std::error_code ec;
  std::filesystem::remove_all(path_, ec);
}

void expect_names(const std::string& message, const std::string& path, std::uint64_t byte,
                  const std::string& what) {
  EXPECT_NE(message.find(path), std::string::npos) << message;
  EXPECT_NE(message.find("byte " + std::to_string(byte) + ":"), std::string::npos) << message;
  EXPECT_NE(message.find(what), std::string::npos) << message;
}

}  // namespace pointillist::testing
