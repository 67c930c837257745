// Helpers shared by the test suites: where test data lives, temporary folders.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

#include "pointillist/core/model_cache.hpp"

namespace pointillist::testing {

using pointillist::model_cache_dir;  // core/model_cache.hpp

// tests/data in the source tree (small files committed with the tests).
std::filesystem::path test_data_dir();
// ../shared/testdata beside the project (QSplat reference files and friends).
std::filesystem::path shared_testdata_dir();
// Skips the current test, saying why, when ../shared/testdata is not beside the project (a
// checkout on its own): the QSplat reference files live there, not in the repository.
#define POINTILLIST_REQUIRE_SHARED_TESTDATA()                                                  \
  if (!std::filesystem::is_directory(::pointillist::testing::shared_testdata_dir() / "qsplat")) \
  GTEST_SKIP() << "QSplat reference files not found in "                                   \
               << ::pointillist::testing::shared_testdata_dir()                           \
               << " (../shared/testdata beside the project)"

// The model cache filled by scripts/fetch-models.sh (core/model_cache.hpp): model_cache_dir(),
// and the path of a fetched model (e.g. "dragon_vrip.ply.gz"), empty when it is not there.
std::filesystem::path cached_model(const std::string& file_name);

// A fresh, empty temporary folder removed when the object dies.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

// Expects an error message of a binary reader to name the file, the place ("byte N:") and what
// was wrong.
void expect_names(const std::string& message, const std::string& path, std::uint64_t byte,
                  const std::string& what);

}  // namespace pointillist::testing
