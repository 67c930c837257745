// FileWindow (see file_window.hpp).
#include "file_window.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cstring>
#include <limits>

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
  unsigned char magic[2] = {};
  if (::pread(fd_, magic, 2, 0) == 2 && magic[0] == 0x1f && magic[1] == 0x8b) {
    const int gz_fd = ::fcntl(fd_, F_DUPFD_CLOEXEC, 0);
    gz_ = gz_fd >= 0 ? ::gzdopen(gz_fd, "rb") : nullptr;
    if (!gz_) {
      if (gz_fd >= 0) ::close(gz_fd);
      ::close(fd_);
      throw IoError(path + ": cannot open the gzip data for reading (out of memory or "
                           "descriptors)");
    }
    ::gzbuffer(gz_, 1 << 17);
  }
}

FileWindow::~FileWindow() {
  if (gz_) ::gzclose(gz_);
  if (fd_ >= 0) ::close(fd_);
}

std::size_t FileWindow::fill(std::uint64_t offset, std::size_t bytes,
                             std::vector<char>& out) const {
  out.resize(bytes);
  std::size_t done = 0;
  if (gz_) {
    const auto corrupt = [&] {
      int code = 0;
      const char* why = ::gzerror(gz_, &code);
      throw FormatError(path_ + ": byte " + std::to_string(gz_at_) +
                        " (decompressed): the gzip data is corrupt (" + (why ? why : "?") +
                        "); the file is damaged: decompress it with gunzip to see where");
    };
    if (offset < gz_at_) {
      if (::gzrewind(gz_) != 0) corrupt();
      gz_at_ = 0;
    }
    while (gz_at_ < offset) {  // skip forward, decompressing into `out` as scratch
      const auto step = static_cast<unsigned>(
          std::min<std::uint64_t>({offset - gz_at_, std::max<std::size_t>(bytes, 1 << 16),
                                   1u << 30}));
      out.resize(std::max<std::size_t>(out.size(), step));
      const int got = ::gzread(gz_, out.data(), step);
      if (got < 0) corrupt();
      if (got == 0) {
        out.resize(0);
        return 0;
      }
      gz_at_ += static_cast<std::uint64_t>(got);
    }
    out.resize(bytes);
    while (done < bytes) {
      const auto step = static_cast<unsigned>(std::min<std::size_t>(bytes - done, 1u << 30));
      const int got = ::gzread(gz_, out.data() + done, step);
      if (got < 0) corrupt();
      if (got == 0) break;
      done += static_cast<std::size_t>(got);
      gz_at_ += static_cast<std::uint64_t>(got);
    }
    out.resize(done);
    return done;
  }
  while (done < bytes) {
    const ssize_t got = ::pread(fd_, out.data() + done, bytes - done,
                                static_cast<off_t>(offset + done));
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) {
      throw IoError(path_ + ": byte " + std::to_string(offset + done) +
                    ": read failed: " + std::strerror(errno));
    }
    if (got == 0) break;
    done += static_cast<std::size_t>(got);
  }
  out.resize(done);
  return done;
}

void FileWindow::check_holds(std::uint64_t bytes, const std::string& what) const {
  if (!gz_) {
    if (bytes <= size_) return;
    throw FormatError(path_ + ": byte " + std::to_string(size_) + ": file ends early: " + what +
                      " need " + std::to_string(bytes) + " bytes, the file has " +
                      std::to_string(size_) + "; the file is truncated");
  }
  constexpr std::uint64_t kDeflateMaxRatio = 1032;
  const std::uint64_t most = size_ > (std::numeric_limits<std::uint64_t>::max() >> 11)
                                 ? std::numeric_limits<std::uint64_t>::max()
                                 : size_ * kDeflateMaxRatio + (1 << 20);
  if (bytes <= most) return;
  throw FormatError(path_ + ": the header says " + what + ", " + std::to_string(bytes) +
                    " bytes, but " + std::to_string(size_) +
                    " bytes of gzip data inflate to at most " + std::to_string(most) +
                    "; the header is wrong or the file is truncated");
}

void FileWindow::read_some(std::uint64_t offset, std::size_t bytes, std::vector<char>& out) const {
  fill(offset, bytes, out);
}

void FileWindow::read(std::uint64_t offset, std::size_t bytes, std::vector<char>& out) const {
  const std::size_t got = fill(offset, bytes, out);
  if (got == bytes) return;
  if (gz_) {
    throw FormatError(path_ + ": byte " + std::to_string(offset + got) +
                      " (decompressed): the file ends early (" + std::to_string(bytes) +
                      " bytes wanted from byte " + std::to_string(offset) +
                      "); the file is truncated");
  }
  throw IoError(path_ + ": byte " + std::to_string(offset + got) +
                ": the file ended early; it was shortened while being read (is another "
                "program writing it?)");
}

}  // namespace pointillist::io_detail
