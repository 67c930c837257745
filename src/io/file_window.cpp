// FileWindow (see file_window.hpp).
#include "file_window.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "pointillist/core/error.hpp"

namespace pointillist::io_detail {

FileWindow::FileWindow(const std::string& path) : path_(path) {
  fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd_ < 0) {
    throw IoError(path + ": cannot open for reading: " + std::strerror(errno) +
                  " (check the path and its permissions)");
  }
  struct stat st {};
  if (::fstat(fd_, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd_);
    throw IoError(path + ": not a regular file; give a scan file");
  }
  size_ = static_cast<std::uint64_t>(st.st_size);
  ::posix_fadvise(fd_, 0, 0, POSIX_FADV_SEQUENTIAL);
}

FileWindow::~FileWindow() {
  if (fd_ >= 0) ::close(fd_);
}

void FileWindow::read(std::uint64_t offset, std::size_t bytes, std::vector<char>& out) const {
  out.resize(bytes);
  std::size_t done = 0;
  while (done < bytes) {
    const ssize_t got = ::pread(fd_, out.data() + done, bytes - done,
                                static_cast<off_t>(offset + done));
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) {
      throw IoError(path_ + ": byte " + std::to_string(offset + done) +
                    ": read failed: " + std::strerror(errno));
    }
    if (got == 0) {
      throw IoError(path_ + ": byte " + std::to_string(offset + done) +
                    ": the file ended early; it was shortened while being read (is another "
                    "program writing it?)");
    }
    done += static_cast<std::size_t>(got);
  }
}

}  // namespace pointillist::io_detail
