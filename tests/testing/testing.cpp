#include "testing/testing.hpp"

#include <atomic>
#include <cstdlib>
#include <random>
#include <unistd.h>

#include <gtest/gtest.h>

namespace pointillist::testing {

std::filesystem::path test_data_dir() { return POINTILLIST_TEST_DATA_DIR; }
std::filesystem::path shared_testdata_dir() { return POINTILLIST_SHARED_TESTDATA_DIR; }

std::filesystem::path cached_model(const std::string& file_name) {
  return pointillist::cached_model_path(file_name);
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
