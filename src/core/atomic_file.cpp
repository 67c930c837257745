#include "pointillist/core/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <random>

#include "pointillist/core/error.hpp"

namespace pointillist {

AtomicFile::AtomicFile(const std::string& path) : path_(path), buffer_(1 << 20) {
  constexpr char kAlphabet[] = "abcdefghijklmnopqrstuvwxyz0123456789";
  std::random_device device;
  for (int attempt = 0; attempt < 100; ++attempt) {
    std::string suffix = ".tmp-";
    for (int i = 0; i < 6; ++i) suffix += kAlphabet[device() % (sizeof(kAlphabet) - 1)];
    temp_path_ = path + suffix;
    // 0666 before the umask, like any other newly created file.
    fd_ = ::open(temp_path_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd_ >= 0) return;
    if (errno != EEXIST) break;
  }
  throw IoError(errno_message("cannot create " + temp_path_ + " (to write " + path + ")"));
}

AtomicFile::~AtomicFile() {
  if (committed_) return;
  if (fd_ >= 0) ::close(fd_);
  ::unlink(temp_path_.c_str());
}

void AtomicFile::write(const void* data, std::size_t size) {
  const char* bytes = static_cast<const char*>(data);
  if (used_ + size > buffer_.size()) {
    flush();
    if (size >= buffer_.size()) {
      used_ = 0;
      while (size > 0) {
        const ssize_t n = ::write(fd_, bytes, size);
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) throw IoError(errno_message("cannot write " + temp_path_));
        bytes += n;
        size -= static_cast<std::size_t>(n);
      }
      return;
    }
  }
  std::memcpy(buffer_.data() + used_, bytes, size);
  used_ += size;
}

void AtomicFile::flush() {
  const char* p = buffer_.data();
  std::size_t left = used_;
  while (left > 0) {
    const ssize_t n = ::write(fd_, p, left);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw IoError(errno_message("cannot write " + temp_path_));
    p += n;
    left -= static_cast<std::size_t>(n);
  }
  used_ = 0;
}

void AtomicFile::commit() {
  flush();
  const int fd = fd_;
  fd_ = -1;
  if (::close(fd) != 0) throw IoError(errno_message("cannot write " + temp_path_));
  if (std::rename(temp_path_.c_str(), path_.c_str()) != 0)
    throw IoError(errno_message("cannot rename " + temp_path_ + " to " + path_));
  committed_ = true;
}

}  // namespace pointillist
