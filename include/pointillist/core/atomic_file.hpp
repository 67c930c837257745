// Writing a file so that it appears complete or not at all (used by the readers and writers of io and format).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace pointillist {

// Writes go to `path + ".tmp-XXXXXX"` in the same folder; commit() renames it over `path`.
// Destroyed without commit() (an exception, say), the temporary file is removed.
class AtomicFile {
 public:
  // Throws IoError when the temporary file cannot be created.
  explicit AtomicFile(const std::string& path);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  // Buffered; throws IoError.
  void write(const void* data, std::size_t size);
  void write(const std::string& text) { write(text.data(), text.size()); }
  // Flushes, closes and renames into place. Throws IoError.
  void commit();

  const std::string& temp_path() const { return temp_path_; }

 private:
  void flush();

  std::string path_, temp_path_;
  int fd_ = -1;
  bool committed_ = false;
  std::vector<char> buffer_;
  std::size_t used_ = 0;
};

}  // namespace pointillist
