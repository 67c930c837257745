// Writing a file so that it appears complete or not at all (used by the readers and writers of io and format).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace pointillist {

// Writes go to `path + ".tmp-XXXXXX"` in the same folder; commit() renames it over `path`.
// Destroyed without commit() (an exception, say), the temporary file is removed; so is it on
// SIGINT, SIGTERM or SIGHUP once remove_temporary_files_on_signals() was called. A temporary file
// of the same output left by a process that died (kill -9, power loss) is removed by the next
// AtomicFile of that output: the live ones hold a lock on theirs.
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
  // Writes at byte `offset` of the file (after flushing what write() buffered); the sequential
  // write position is not moved. For files laid out before they are filled. Several threads may
  // call it at once on disjoint ranges while nothing is buffered. Throws IoError.
  void write_at(std::uint64_t offset, const void* data, std::size_t size);
  // Flushes, closes and renames into place. Throws IoError.
  void commit();
  // Flushes and asks the system to put the bytes written so far on disk (fsync), so that other
  // processes, on other machines of a shared file system too, can read the temporary file.
  // Throws IoError.
  void sync();

  const std::string& temp_path() const { return temp_path_; }

 private:
  void flush();

  std::string path_, temp_path_;
  int fd_ = -1;
  bool committed_ = false;
  std::vector<char> buffer_;
  std::size_t used_ = 0;
  int slot_ = -1;  // in the registry the signal handler reads
};

// Writes all `size` bytes at byte `offset` of the open file `fd`, again after an interruption or
// a short write. False when the system refuses (errno says why; ENOSPC for a write that makes
// no progress).
bool write_all_at(int fd, std::uint64_t offset, const void* data, std::size_t size);

// Installs handlers for SIGINT, SIGTERM and SIGHUP that remove the temporary files of every live
// AtomicFile, then let the signal end the process as it would have. Call once, early (main).
void remove_temporary_files_on_signals();

// Throws OptionError, before any work, when an output would replace an input or another output:
// `outputs` are (option, path) pairs such as {"-o", "x.png"}; paths naming the same file after
// resolving links and "." / ".." count as the same. Empty output paths and "-" are ignored.
void check_outputs(const std::vector<std::string>& inputs,
                   const std::vector<std::pair<std::string, std::string>>& outputs);

}  // namespace pointillist
