// Reading a file piece by piece with pread (private to io): what the streaming readers use, so
// the file's pages do not count as the process's memory the way a mapping's touched pages do.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace pointillist::io_detail {

class FileWindow {
 public:
  // Opens `path` for reading. Throws IoError naming the file and the reason.
  explicit FileWindow(const std::string& path);
  ~FileWindow();
  FileWindow(const FileWindow&) = delete;
  FileWindow& operator=(const FileWindow&) = delete;

  std::uint64_t size() const { return size_; }
  const std::string& path() const { return path_; }
  // Reads `bytes` bytes at `offset` into `out` (resized). Throws IoError when the file is
  // shorter than that (it changed since it was opened) or reading fails.
  void read(std::uint64_t offset, std::size_t bytes, std::vector<char>& out) const;


 private:
  std::string path_;
  int fd_ = -1;
  std::uint64_t size_ = 0;
};

}  // namespace pointillist::io_detail
