// Reading .ptl files (docs/ptl-format.md): memory-mapped read-only and validated up front, so
// traversal code can trust every child index.
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstring>
#include <string>

#include "printable.hpp"
#include "ptl_header.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/format/ptl.hpp"

namespace pointillist {
namespace {

static_assert(std::endian::native == std::endian::little,
              ".ptl nodes are mapped as raw little-endian memory");
static_assert(ptl::kHeaderSize % ptl::kNodeAlignment == 0);

std::string hex(std::uint32_t v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%x", v);
  return buf;
}

// Printable rendering of up to 8 leading bytes, for "found ..." in the magic error.
std::string leading_bytes(const std::uint8_t* p, std::size_t size) {
  return format_detail::printable_bytes(p, std::min<std::size_t>(size, 8));
}

using ptl::fail_at;

bool finite_box(const Aabb& b) { return is_finite(b.lo) && is_finite(b.hi); }

void check_header(const std::string& path, const ptl::Header& h, std::uint64_t file_size) {
  if (h.version == 0) fail_at(path, ptl::offset::kVersion, "invalid .ptl version 0");
  if (h.version == 2) {
    fail_at(path, ptl::offset::kVersion,
            ".ptl version 2 (compact, paged) file; PtlFile maps version 1 only: open it with "
            "PtlV2File or read_ptl (pointillist/format/ptl_v2.hpp), which read both");
  }
  if (h.version > kPtlVersion) {
    fail_at(path, ptl::offset::kVersion,
            ".ptl version " + std::to_string(h.version) + " is newer than this build of "
            "Pointillist reads (versions 1 and 2); upgrade Pointillist to open it");
  }
  if (h.header_size < ptl::kHeaderSize) {
    fail_at(path, ptl::offset::kHeaderSize,
            "header size " + std::to_string(h.header_size) + " is below the minimum " +
                std::to_string(ptl::kHeaderSize));
  }
  if ((h.flags & ~ptl::kKnownFlags) != 0) {
    fail_at(path, ptl::offset::kFlags,
            "flags " + hex(h.flags) + " name features this build does not know (it knows " +
                hex(ptl::kKnownFlags) + "); upgrade Pointillist to open the file");
  }
  if (h.node_size != ptl::kNodeSize) {
    fail_at(path, ptl::offset::kNodeSize,
            "node size " + std::to_string(h.node_size) + ", expected " +
                std::to_string(ptl::kNodeSize));
  }
  if (h.node_count == 0) {
    fail_at(path, ptl::offset::kNodeCount, "node count is 0; a model has at least a root node");
  }
  if (h.node_count > (std::uint64_t{1} << 32)) {
    fail_at(path, ptl::offset::kNodeCount,
            "node count " + std::to_string(h.node_count) + " exceeds 32-bit child indices");
  }
  if (!finite_box(h.bounds) || !is_finite(h.view_sphere.center) ||
      !std::isfinite(h.view_sphere.radius)) {
    fail_at(path, ptl::offset::kBoundsLo, "bounds or view sphere are not finite");
  }
  if (h.nodes_offset < h.header_size || h.nodes_offset % ptl::kNodeAlignment != 0) {
    fail_at(path, ptl::offset::kNodesOffset,
            "node array offset " + std::to_string(h.nodes_offset) +
                " must be a multiple of 64 and not inside the " + std::to_string(h.header_size) +
                "-byte header");
  }
  // node_count < 2^33 and nodes_offset <= file size (checked next), so no overflow.
  const std::uint64_t nodes_end = h.nodes_offset + h.node_count * ptl::kNodeSize;
  if (h.nodes_offset > file_size || nodes_end > file_size) {
    fail_at(path, file_size,
            "file ends early: the node array (" + std::to_string(h.node_count) +
                " nodes) needs bytes " + std::to_string(h.nodes_offset) + " to " +
                std::to_string(nodes_end) + ", but the file has only " +
                std::to_string(file_size) + " bytes; it was probably truncated");
  }
  if (h.metadata_offset < nodes_end) {
    fail_at(path, ptl::offset::kMetadataOffset,
            "metadata offset " + std::to_string(h.metadata_offset) +
                " overlaps the node array (which ends at byte " + std::to_string(nodes_end) +
                ")");
  }
  if (h.metadata_offset > file_size || h.metadata_size > file_size - h.metadata_offset) {
    fail_at(path, file_size,
            "file ends early: the metadata needs bytes " + std::to_string(h.metadata_offset) +
                " to " + std::to_string(h.metadata_offset + h.metadata_size) +
                ", but the file has only " + std::to_string(file_size) +
                " bytes; it was probably truncated");
  }
}

// Every node's values and child range: child_count in {0, 2, 3, 4}; children stored
// breadth-first (each interior node's children follow right after the previous interior node's,
// starting at node 1), which puts every child after its parent, gives every node but the root
// exactly one parent, and keeps all indices in range. Also recomputes leaf count and depth.
void check_nodes(const std::string& path, const ptl::Header& h, const SphereNode* nodes) {
  const std::uint64_t count = h.node_count;
  const auto fail_node = [&](std::uint64_t i, std::size_t field, const std::string& what) {
    fail_at(path, h.nodes_offset + i * ptl::kNodeSize + field,
            "node " + std::to_string(i) + " of " + std::to_string(count) + ": " + what);
  };
  constexpr std::size_t kCenter = offsetof(SphereNode, center);
  constexpr std::size_t kRadius = offsetof(SphereNode, radius);
  constexpr std::size_t kNormal = offsetof(SphereNode, normal);
  constexpr std::size_t kCone = offsetof(SphereNode, cone_sin);
  constexpr std::size_t kFirstChild = offsetof(SphereNode, first_child);
  constexpr std::size_t kChildCount = offsetof(SphereNode, child_count);
  std::uint64_t next_child = 1;  // where the next interior node's children must start
  std::uint64_t leaves = 0;
  std::uint32_t depth = 0;
  std::uint64_t level_end = 1, next_level_end = 1;  // BFS: levels are consecutive index ranges
  for (std::uint64_t i = 0; i < count; ++i) {
    if (i == level_end) {
      ++depth;
      level_end = next_level_end;
    }
    const SphereNode& n = nodes[i];
    if (!is_finite(n.center)) fail_node(i, kCenter, "centre is not finite");
    if (!(std::isfinite(n.radius) && n.radius >= 0)) {
      fail_node(i, kRadius, "radius is negative or not finite");
    }
    if (!is_finite(n.normal)) fail_node(i, kNormal, "normal is not finite");
    if (!(std::isfinite(n.cone_sin) && n.cone_sin >= 0)) {
      fail_node(i, kCone, "normal cone is negative or not finite");
    }
    const unsigned children = n.child_count;
    if (children == 0) {
      if (n.first_child != 0) {
        fail_node(i, kFirstChild,
                  "a leaf with first child " + std::to_string(n.first_child) + " (must be 0)");
      }
      ++leaves;
      continue;
    }
    if (children < 2 || children > 4) {
      fail_node(i, kChildCount,
                "child count " + std::to_string(children) + " (must be 0, 2, 3 or 4)");
    }
    if (n.first_child <= i) {
      fail_node(i, kFirstChild,
                "first child " + std::to_string(n.first_child) +
                    " does not come after the node itself; traversal could loop");
    }
    if (std::uint64_t{n.first_child} + children > count) {
      fail_node(i, kFirstChild,
                "children " + std::to_string(n.first_child) + " to " +
                    std::to_string(std::uint64_t{n.first_child} + children - 1) +
                    " are out of range (the file has " + std::to_string(count) + " nodes)");
    }
    if (n.first_child != next_child) {
      fail_node(i, kFirstChild,
                "first child " + std::to_string(n.first_child) + ", expected " +
                    std::to_string(next_child) +
                    " (children follow breadth-first, right after the previous node's)");
    }
    next_child += children;
    next_level_end = next_child;
  }
  if (next_child != count) {
    fail_node(next_child, 0, "no node has this node as a child (the tree ends at node " +
                                 std::to_string(next_child - 1) + ")");
  }
  if (leaves != h.leaf_count) {
    fail_at(path, ptl::offset::kLeafCount,
            "header says " + std::to_string(h.leaf_count) + " leaves, the node array has " +
                std::to_string(leaves));
  }
  if (depth != h.depth) {
    fail_at(path, ptl::offset::kDepth,
            "header says depth " + std::to_string(h.depth) + ", the node array has depth " +
                std::to_string(depth));
  }
}

}  // namespace

std::unique_ptr<PtlFile> PtlFile::open(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw IoError(errno_message("cannot open " + path));
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    const std::string message = errno_message("cannot read " + path);
    ::close(fd);
    throw IoError(message);
  }
  std::unique_ptr<PtlFile> file(new PtlFile);
  file->size_ = static_cast<std::uint64_t>(st.st_size);
  if (file->size_ > 0) {
    void* map = ::mmap(nullptr, file->size_, PROT_READ, MAP_PRIVATE, fd, 0);
    if (map == MAP_FAILED) {
      const std::string message = errno_message("cannot map " + path);
      ::close(fd);
      throw IoError(message);
    }
    file->map_ = map;
  }
  ::close(fd);  // the mapping stays valid

  const auto* bytes = static_cast<const std::uint8_t*>(file->map_);
  if (file->size_ < sizeof ptl::kMagic ||
      std::memcmp(bytes, ptl::kMagic, sizeof ptl::kMagic) != 0) {
    throw FormatError("not a Pointillist model file: " + path + ": byte 0: expected \"PTLSPLAT\", found " +
                      (file->size_ == 0 ? std::string("an empty file")
                                        : leading_bytes(bytes, file->size_)));
  }
  if (file->size_ < ptl::kHeaderSize) {
    fail_at(path, file->size_,
            "file ends early: the header needs " + std::to_string(ptl::kHeaderSize) +
                " bytes, the file has only " + std::to_string(file->size_));
  }
  const ptl::Header h = ptl::decode_header(bytes);
  check_header(path, h, file->size_);
  const auto* nodes = reinterpret_cast<const SphereNode*>(bytes + h.nodes_offset);
  check_nodes(path, h, nodes);

  file->version_ = h.version;
  file->view_.nodes = {nodes, static_cast<std::size_t>(h.node_count)};
  file->view_.has_colors = (h.flags & ptl::kFlagHasColors) != 0;
  file->view_.leaf_count = h.leaf_count;
  file->view_.depth = h.depth;
  file->view_.bounds = h.bounds;
  file->view_.view_sphere = h.view_sphere;
  file->metadata_.assign(reinterpret_cast<const char*>(bytes + h.metadata_offset),
                         static_cast<std::size_t>(h.metadata_size));
  return file;
}

PtlFile::~PtlFile() {
  if (map_ != nullptr) ::munmap(map_, size_);
}

namespace {

// The first `n` bytes of the file (fewer when it is shorter or cannot be read).
std::size_t read_prefix(const std::string& path, char* out, std::size_t n) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return 0;
  std::size_t got = 0;
  while (got < n) {
    const ssize_t k = ::read(fd, out + got, n - got);
    if (k < 0 && errno == EINTR) continue;
    if (k <= 0) break;
    got += static_cast<std::size_t>(k);
  }
  ::close(fd);
  return got;
}

}  // namespace

bool is_ptl_file(const std::string& path) {
  char magic[sizeof ptl::kMagic];
  return read_prefix(path, magic, sizeof magic) == sizeof magic &&
         std::memcmp(magic, ptl::kMagic, sizeof magic) == 0;
}

std::uint32_t ptl_file_version(const std::string& path) {
  char head[ptl::offset::kVersion + 4];
  if (read_prefix(path, head, sizeof head) != sizeof head ||
      std::memcmp(head, ptl::kMagic, sizeof ptl::kMagic) != 0) {
    return 0;
  }
  std::uint32_t version = 0;
  std::memcpy(&version, head + ptl::offset::kVersion, sizeof version);  // little endian
  return version;
}

}  // namespace pointillist
