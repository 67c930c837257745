#include "pointillist/core/atomic_file.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <random>

#include "pointillist/core/error.hpp"

namespace pointillist {
namespace {

// The temporary files of live AtomicFiles, for the signal handler: fixed slots of plain bytes
// (a handler may not allocate or lock). A file whose path does not fit, or beyond the slots, is
// still removed by its destructor, just not on a signal.
constexpr int kSlots = 64;
constexpr std::size_t kPathBytes = 4096;
struct Slot {
  std::atomic<bool> used{false};
  char path[kPathBytes];
};
std::array<Slot, kSlots> g_slots;

int register_temp(const std::string& path) {
  if (path.size() >= kPathBytes) return -1;
  for (int i = 0; i < kSlots; ++i) {
    bool expected = false;
    if (g_slots[i].used.load(std::memory_order_relaxed)) continue;
    std::memcpy(g_slots[i].path, path.c_str(), path.size() + 1);
    if (g_slots[i].used.compare_exchange_strong(expected, true)) return i;
  }
  return -1;
}

void unregister_temp(int slot) {
  if (slot >= 0) g_slots[slot].used.store(false);
}

extern "C" void remove_temporary_files(int signal) {
  for (Slot& s : g_slots) {
    if (s.used.load()) ::unlink(s.path);
  }
  std::signal(signal, SIG_DFL);
  std::raise(signal);
}

// Removes `path`'s temporary files (path + ".tmp-" + 6 characters) that no live writer holds:
// each live AtomicFile keeps an exclusive lock on its own.
void remove_stale_temporaries(const std::string& path) {
  namespace fs = std::filesystem;
  const fs::path target(path);
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  const std::string prefix = target.filename().string() + ".tmp-";
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.size() != prefix.size() + 6 || name.compare(0, prefix.size(), prefix) != 0) continue;
    const int fd = ::open(it->path().c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) continue;
    if (::flock(fd, LOCK_EX | LOCK_NB) == 0) ::unlink(it->path().c_str());
    ::close(fd);
  }
}

}  // namespace

void remove_temporary_files_on_signals() {
  struct sigaction action {};
  action.sa_handler = remove_temporary_files;
  sigemptyset(&action.sa_mask);
  for (int signal : {SIGINT, SIGTERM, SIGHUP}) sigaction(signal, &action, nullptr);
}

void check_outputs(const std::vector<std::string>& inputs,
                   const std::vector<std::pair<std::string, std::string>>& outputs) {
  namespace fs = std::filesystem;
  const auto same = [](const std::string& a, const std::string& b) {
    std::error_code ec;
    if (fs::equivalent(a, b, ec) && !ec) return true;
    const fs::path ca = fs::weakly_canonical(a, ec);
    if (ec) return a == b;
    const fs::path cb = fs::weakly_canonical(b, ec);
    return ec ? a == b : ca == cb;
  };
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    const auto& [option, path] = outputs[i];
    if (path.empty() || path == "-") continue;
    for (const std::string& in : inputs) {
      if (same(path, in)) {
        throw OptionError(option + " " + path + " names an input (" + in +
                          "): writing it would destroy the input; choose another output path");
      }
    }
    for (std::size_t j = 0; j < i; ++j) {
      const auto& [other_option, other] = outputs[j];
      if (!other.empty() && other != "-" && same(path, other)) {
        throw OptionError(option + " " + path + " is also the output of " + other_option +
                          ": one would overwrite the other; give them different paths");
      }
    }
  }
}

AtomicFile::AtomicFile(const std::string& path) : path_(path), buffer_(1 << 20) {
  remove_stale_temporaries(path);
  constexpr char kAlphabet[] = "abcdefghijklmnopqrstuvwxyz0123456789";
  std::random_device device;
  for (int attempt = 0; attempt < 100; ++attempt) {
    std::string suffix = ".tmp-";
    for (int i = 0; i < 6; ++i) suffix += kAlphabet[device() % (sizeof(kAlphabet) - 1)];
    temp_path_ = path + suffix;
    // 0666 before the umask, like any other newly created file.
    fd_ = ::open(temp_path_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd_ >= 0) {
      ::flock(fd_, LOCK_EX | LOCK_NB);  // marks it live for remove_stale_temporaries
      slot_ = register_temp(temp_path_);
      return;
    }
    if (errno != EEXIST) break;
  }
  throw IoError(errno_message("cannot create " + temp_path_ + " (to write " + path + ")"));
}

AtomicFile::~AtomicFile() {
  unregister_temp(slot_);
  if (committed_) return;
  ::unlink(temp_path_.c_str());
  if (fd_ >= 0) ::close(fd_);
}

void AtomicFile::write(const void* data, std::size_t size) {
  if (size == 0) return;  // data may be null (an empty vector's)
  const char* bytes = static_cast<const char*>(data);
  if (used_ + size > buffer_.size()) {
    flush();
    if (size >= buffer_.size()) {
      used_ = 0;
      while (size > 0) {
        const ssize_t n = ::write(fd_, bytes, size);
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) throw IoError(errno_message("cannot write " + path_ + " (its temporary file " + temp_path_ + ")"));
        bytes += n;
        size -= static_cast<std::size_t>(n);
      }
      return;
    }
  }
  std::memcpy(buffer_.data() + used_, bytes, size);
  used_ += size;
}

bool write_all_at(int fd, std::uint64_t offset, const void* data, std::size_t size) {
  const char* bytes = static_cast<const char*>(data);
  while (size > 0) {
    const ssize_t n = ::pwrite(fd, bytes, size, static_cast<off_t>(offset));
    if (n < 0 && errno == EINTR) continue;
    if (n == 0) errno = ENOSPC;
    if (n <= 0) return false;
    bytes += n;
    offset += static_cast<std::uint64_t>(n);
    size -= static_cast<std::size_t>(n);
  }
  return true;
}

void AtomicFile::write_at(std::uint64_t offset, const void* data, std::size_t size) {
  if (used_ > 0) flush();
  if (!write_all_at(fd_, offset, data, size)) {
    throw IoError(errno_message("cannot write " + path_ + " (its temporary file " + temp_path_ + ")"));
  }
}

void AtomicFile::flush() {
  const char* p = buffer_.data();
  std::size_t left = used_;
  while (left > 0) {
    const ssize_t n = ::write(fd_, p, left);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw IoError(errno_message("cannot write " + path_ + " (its temporary file " + temp_path_ + ")"));
    p += n;
    left -= static_cast<std::size_t>(n);
  }
  used_ = 0;
}

void AtomicFile::sync() {
  flush();
  if (::fsync(fd_) != 0) {
    throw IoError(errno_message("cannot write " + path_ + " (its temporary file " + temp_path_ + ")"));
  }
}

void AtomicFile::commit() {
  flush();
  const int fd = fd_;
  fd_ = -1;
  if (::close(fd) != 0) {
    throw IoError(errno_message("cannot write " + path_ + " (its temporary file " + temp_path_ + ")"));
  }
  if (std::rename(temp_path_.c_str(), path_.c_str()) != 0)
    throw IoError(errno_message("cannot rename " + temp_path_ + " to " + path_));
  committed_ = true;
  unregister_temp(slot_);
  slot_ = -1;
}

}  // namespace pointillist
