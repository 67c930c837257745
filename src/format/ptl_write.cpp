// Writing .ptl files (docs/ptl-format.md): to a temporary file in the destination folder, then
// renamed over the destination, so a failure never leaves a half-written model behind.
#include <fcntl.h>
#include <unistd.h>

#include <bit>
#include <cerrno>
#include <cstdio>
#include <string>
#include <vector>

#include "ptl_header.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/format/ptl.hpp"

namespace pointillist {
namespace {

static_assert(std::endian::native == std::endian::little,
              ".ptl nodes are written as raw little-endian memory");

// An open temporary file that is closed and removed unless `commit` renamed it.
class TempFile {
 public:
  explicit TempFile(const std::string& path) : path_(path) {
    // A fresh name per attempt: O_EXCL never reuses (or truncates) somebody else's file.
    for (int attempt = 0; fd_ < 0; ++attempt) {
      temp_ = path + ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(attempt);
      fd_ = ::open(temp_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
      if (fd_ < 0 && (errno != EEXIST || attempt >= 100)) {
        throw IoError(errno_message("cannot write " + path + ": cannot create temporary file " +
                                    temp_));
      }
    }
  }
  ~TempFile() {
    if (fd_ >= 0) ::close(fd_);
    if (!committed_) ::unlink(temp_.c_str());
  }
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;

  void write(const void* data, std::size_t size) {
    const auto* p = static_cast<const char*>(data);
    while (size > 0) {
      const ssize_t n = ::write(fd_, p, size);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {
        if (n == 0) errno = EIO;
        throw IoError(errno_message("cannot write " + path_ + " (temporary file " + temp_ + ")"));
      }
      p += n;
      size -= static_cast<std::size_t>(n);
    }
  }

  void commit() {
    const int fd = fd_;
    fd_ = -1;
    if (::close(fd) != 0) {
      throw IoError(errno_message("cannot write " + path_ + " (temporary file " + temp_ + ")"));
    }
    if (::rename(temp_.c_str(), path_.c_str()) != 0) {
      throw IoError(errno_message("cannot write " + path_ + ": cannot rename " + temp_ +
                                  " to it"));
    }
    committed_ = true;
  }

 private:
  std::string path_, temp_;
  int fd_ = -1;
  bool committed_ = false;
};

}  // namespace

void write_ptl(const std::string& path, const SphereTree& tree, const std::string& metadata) {
  if (tree.nodes.empty()) {
    throw Error("cannot write " + path + ": the hierarchy has no nodes");
  }
  ptl::Header h;
  h.version = kPtlVersion;
  h.header_size = ptl::kHeaderSize;
  h.flags = tree.has_colors ? ptl::kFlagHasColors : 0;
  h.node_size = ptl::kNodeSize;
  h.node_count = tree.nodes.size();
  h.leaf_count = tree.leaf_count;
  h.depth = tree.depth;
  h.bounds = tree.bounds;
  h.view_sphere = tree.view_sphere;
  h.nodes_offset = ptl::kHeaderSize;  // a multiple of kNodeAlignment
  h.metadata_offset = h.nodes_offset + h.node_count * ptl::kNodeSize;
  h.metadata_size = metadata.size();
  const auto header = ptl::encode_header(h);

  TempFile file(path);
  file.write(header.data(), header.size());
  file.write(tree.nodes.data(), tree.nodes.size() * sizeof(SphereNode));
  file.write(metadata.data(), metadata.size());
  file.commit();
}

}  // namespace pointillist
