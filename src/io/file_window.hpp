// Reading a file piece by piece (private to io): what the streaming readers use, so the file's
// pages do not count as the process's memory the way a mapping's touched pages do. A plain file
// is read with pread at any offset; a gzip file through zlib, its decompressed bytes at
// increasing offsets (an offset behind the last read starts decompressing again from the
// beginning), in constant memory.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

struct gzFile_s;

namespace pointillist::io_detail {

class FileWindow {
 public:
  // Opens `path` for reading (gzip when it starts with the gzip magic bytes). Throws IoError
  // naming the file and the reason.
  explicit FileWindow(const std::string& path);
  ~FileWindow();
  FileWindow(const FileWindow&) = delete;
  FileWindow& operator=(const FileWindow&) = delete;

  // The size of the file on disk (for a gzip file, its compressed size).
  std::uint64_t size() const { return size_; }
  const std::string& path() const { return path_; }
  // Offsets are into the decompressed data.
  bool compressed() const { return gz_ != nullptr; }
  // Reads `bytes` bytes at `offset` into `out` (resized). Throws IoError when a plain file is
  // shorter than that (it changed since it was opened) or reading fails, FormatError when gzip
  // data ends early or is corrupt.
  void read(std::uint64_t offset, std::size_t bytes, std::vector<char>& out) const;
  // As read, but stops at the end of the data: `out` may hold fewer bytes.
  void read_some(std::uint64_t offset, std::size_t bytes, std::vector<char>& out) const;
  // Throws FormatError when a header's claim that the data holds `bytes` bytes (`what`, e.g.
  // "1000 vertices of 15 bytes from byte 200") cannot be true: more than the file holds, or for
  // gzip data more than deflate's largest ratio (1032 to 1) makes of the file. So a count from a
  // header is checked against the file's size before anything is sized by it.
  void check_holds(std::uint64_t bytes, const std::string& what) const;

 private:
  std::size_t fill(std::uint64_t offset, std::size_t bytes, std::vector<char>& out) const;

  std::string path_;
  int fd_ = -1;
  std::uint64_t size_ = 0;
  gzFile_s* gz_ = nullptr;
  mutable std::uint64_t gz_at_ = 0;  // decompressed offset of the next byte gzread gives
};

}  // namespace pointillist::io_detail
