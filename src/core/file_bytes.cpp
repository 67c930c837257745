#include "pointillist/core/file_bytes.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <limits>
#include <utility>

#include "pointillist/core/error.hpp"

namespace pointillist {
namespace {

class Fd {
 public:
  explicit Fd(int fd) : fd_(fd) {}
  ~Fd() {
    if (fd_ >= 0) ::close(fd_);
  }
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  int get() const { return fd_; }

 private:
  int fd_;
};

// Reads exactly `size` bytes (fewer only if the file shrank meanwhile); returns the count read.
std::size_t read_all(int fd, char* out, std::size_t size, const std::string& path) {
  std::size_t done = 0;
  while (done < size) {
    const ssize_t n = ::read(fd, out + done, std::min<std::size_t>(size - done, 1 << 30));
    if (n < 0) {
      if (errno == EINTR) continue;
      throw IoError(errno_message("cannot read " + path));
    }
    if (n == 0) break;
    done += static_cast<std::size_t>(n);
  }
  return done;
}

std::unique_ptr<char[]> grow(std::unique_ptr<char[]> old, std::size_t used, std::size_t new_size) {
  auto bigger = std::make_unique_for_overwrite<char[]>(new_size);
  std::memcpy(bigger.get(), old.get(), used);
  return bigger;
}

}  // namespace

FileBytes::FileBytes(FileBytes&& other) noexcept { *this = std::move(other); }

FileBytes& FileBytes::operator=(FileBytes&& other) noexcept {
  if (this != &other) {
    release();
    data_ = std::exchange(other.data_, "");
    size_ = std::exchange(other.size_, 0);
    map_ = std::exchange(other.map_, nullptr);
    map_size_ = std::exchange(other.map_size_, 0);
    buffer_ = std::move(other.buffer_);
    was_compressed_ = other.was_compressed_;
    file_size_ = other.file_size_;
  }
  return *this;
}

FileBytes::~FileBytes() { release(); }

void FileBytes::release() {
  if (map_) ::munmap(map_, map_size_);
  map_ = nullptr;
  map_size_ = 0;
  buffer_.reset();
  data_ = "";
  size_ = 0;
}

FileBytes FileBytes::map(const std::string& path, Use use) {
  const Fd fd(::open(path.c_str(), O_RDONLY | O_CLOEXEC));
  if (fd.get() < 0) throw IoError(errno_message("cannot open " + path));
  struct stat st {};
  if (::fstat(fd.get(), &st) != 0) throw IoError(errno_message("cannot stat " + path));
  if (S_ISDIR(st.st_mode)) throw IoError("cannot read " + path + ": it is a directory");
  FileBytes bytes;
  if (!S_ISREG(st.st_mode)) {
    // Pipes and devices: read until end of stream.
    std::size_t capacity = 1 << 20, used = 0;
    bytes.buffer_ = std::make_unique_for_overwrite<char[]>(capacity);
    for (;;) {
      if (used == capacity) {
        bytes.buffer_ = grow(std::move(bytes.buffer_), used, capacity * 2);
        capacity *= 2;
      }
      const std::size_t n = read_all(fd.get(), bytes.buffer_.get() + used, capacity - used, path);
      used += n;
      if (used < capacity) break;
    }
    bytes.data_ = bytes.buffer_.get();
    bytes.size_ = used;
    bytes.file_size_ = used;
    return bytes;
  }
  const auto size = static_cast<std::size_t>(st.st_size);
  bytes.file_size_ = size;
  if (size == 0) return bytes;
  // For a whole read, MAP_POPULATE maps the whole page-cache range at once instead of faulting
  // page by page (and reads the file in, when it is not in the page cache yet).
  const int populate = use == Use::Whole ? MAP_POPULATE : 0;
  void* map = ::mmap(nullptr, size, PROT_READ, MAP_PRIVATE | populate, fd.get(), 0);
  if (map != MAP_FAILED) {
    if (use == Use::Whole) ::madvise(map, size, MADV_SEQUENTIAL);
    bytes.map_ = map;
    bytes.map_size_ = size;
    bytes.data_ = static_cast<const char*>(map);
    bytes.size_ = size;
    return bytes;
  }
  bytes.buffer_ = std::make_unique_for_overwrite<char[]>(size);
  bytes.size_ = read_all(fd.get(), bytes.buffer_.get(), size, path);
  bytes.data_ = bytes.buffer_.get();
  return bytes;
}

void FileBytes::forget() const {
  // Mapped read-only, never written: dropping a page loses nothing.
  if (map_ != nullptr) ::madvise(map_, map_size_, MADV_DONTNEED);
}

bool has_gzip_magic(std::string_view bytes) {
  return bytes.size() >= 2 && static_cast<unsigned char>(bytes[0]) == 0x1f &&
         static_cast<unsigned char>(bytes[1]) == 0x8b;
}

FileBytes FileBytes::load(const std::string& path,
                          const std::function<void(std::uint64_t)>& on_compressed_bytes) {
  FileBytes raw = map(path);
  if (!has_gzip_magic(raw.view())) return raw;
  return inflate(raw, path, on_compressed_bytes);
}

FileBytes FileBytes::inflate(const FileBytes& compressed, const std::string& path,
                             const std::function<void(std::uint64_t)>& on_compressed_bytes,
                             std::function<std::uint64_t(std::string_view)> limit) {
  GzipInflater inflater(compressed.view(), path);
  inflater.set_limit(std::move(limit));
  inflater.run(true, on_compressed_bytes);
  return inflater.release(compressed.file_size());
}

GzipInflater::GzipInflater(std::string_view compressed, std::string path)
    : in_(compressed), path_(std::move(path)) {
  // The trailer holds the uncompressed size modulo 2^32: right for single-member files below
  // 4 GiB. Deflate cannot expand more than about 1032:1.
  std::size_t capacity = 1 << 16;
  if (in_.size() >= 18) {
    std::uint32_t isize = 0;
    for (int i = 0; i < 4; ++i)
      isize |= std::uint32_t(static_cast<unsigned char>(in_[in_.size() - 4 + i])) << (8 * i);
    capacity = std::max<std::size_t>(
        capacity, std::min<std::size_t>(std::size_t(isize) + 1, in_.size() * 1032));
  }
  capacity_ = capacity;
  buffer_ = std::make_unique_for_overwrite<char[]>(capacity_);
}

void GzipInflater::publish(std::size_t available, bool finished) {
  {
    const std::lock_guard lock(mutex_);
    available_ = available;
    finished_ = finished;
  }
  changed_.notify_all();
}

std::size_t GzipInflater::wait_for(std::size_t bytes, bool& finished) {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [&] { return finished_ || available_ >= bytes; });
  finished = finished_;
  return available_;
}

FileBytes GzipInflater::release(std::uint64_t file_size) {
  FileBytes bytes;
  bytes.buffer_ = std::move(buffer_);
  bytes.data_ = bytes.buffer_.get();
  bytes.size_ = available_;
  bytes.was_compressed_ = true;
  bytes.file_size_ = file_size;
  return bytes;
}

void GzipInflater::run(bool may_grow,
                       const std::function<void(std::uint64_t)>& on_compressed_bytes) {
  z_stream zs{};
  if (inflateInit2(&zs, 15 + 16) != Z_OK) throw IoError(path_ + ": cannot initialise zlib");
  std::size_t used = 0;
  // Whatever happens, readers waiting in wait_for() must wake up.
  struct Finish {
    GzipInflater* self;
    z_stream* zs;
    std::size_t* used;
    ~Finish() {
      inflateEnd(zs);
      self->publish(*used, true);
    }
  } finish{this, &zs, &used};

  constexpr std::size_t kInChunk = 1 << 20;  // progress and publishing granularity
  constexpr std::size_t kOutChunk = 16 << 20;  // the most inflated between two limit checks
  std::uint64_t limit = std::numeric_limits<std::uint64_t>::max();
  std::size_t next_probe = 0;  // when to ask limit_fn_ again
  std::size_t in_pos = 0;
  bool member_done = false;
  for (;;) {
    if (cancelled_.load(std::memory_order_relaxed)) return;
    if (member_done) {
      // Another gzip member may follow (concatenated .gz files); anything else is ignored, as
      // gzip(1) does.
      if (!has_gzip_magic(in_.substr(in_pos))) break;
      inflateReset(&zs);
      member_done = false;
    }
    if (used == capacity_) {
      if (!may_grow) {
        overflowed_ = true;
        return;
      }
      auto bigger = std::make_unique_for_overwrite<char[]>(capacity_ * 2);
      std::memcpy(bigger.get(), buffer_.get(), used);
      buffer_ = std::move(bigger);
      capacity_ *= 2;
    }
    const std::size_t in_chunk = std::min(kInChunk, in_.size() - in_pos);
    zs.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(in_.data() + in_pos));
    zs.avail_in = static_cast<uInt>(in_chunk);
    const std::size_t out_chunk =
        std::min<std::size_t>({capacity_ - used, std::numeric_limits<uInt>::max(), kOutChunk});
    zs.next_out = reinterpret_cast<Bytef*>(buffer_.get() + used);
    zs.avail_out = static_cast<uInt>(out_chunk);
    const int rc = ::inflate(&zs, Z_NO_FLUSH);
    const std::size_t consumed = in_chunk - zs.avail_in;
    in_pos += consumed;
    used += out_chunk - zs.avail_out;
    if (limit_fn_ && limit == std::numeric_limits<std::uint64_t>::max() && used >= next_probe) {
      limit = limit_fn_({buffer_.get(), used});
      next_probe = used + kInChunk;
    }
    if (used > limit) {
      throw FormatError(path_ + ": decompressed byte " + std::to_string(limit) +
                        ": the data goes on past the " + std::to_string(limit) +
                        " bytes its header describes (compressed byte " + std::to_string(in_pos) +
                        " of " + std::to_string(in_.size()) +
                        "); the file is corrupt or made to exhaust memory, and is not read");
    }
    if (!may_grow) publish(used, false);
    if (on_compressed_bytes && consumed > 0) on_compressed_bytes(consumed);
    if (rc == Z_STREAM_END) {
      member_done = true;
      continue;
    }
    if (rc == Z_DATA_ERROR || rc == Z_NEED_DICT || rc == Z_STREAM_ERROR) {
      throw FormatError(path_ + ": compressed byte " + std::to_string(in_pos) +
                        ": corrupt gzip data (" + (zs.msg ? zs.msg : "zlib error") + ")");
    }
    if (rc == Z_MEM_ERROR) throw IoError(path_ + ": out of memory while decompressing");
    if (in_pos == in_.size() && zs.avail_out > 0) {
      throw FormatError(path_ + ": compressed byte " + std::to_string(in_pos) +
                        ": gzip data ends early (the file is truncated; " + std::to_string(used) +
                        " bytes decompressed so far)");
    }
  }
}

}  // namespace pointillist
