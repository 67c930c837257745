// Native model file `.ptl`, version 1: a fixed little-endian header followed by the breadth-first
// SphereNode array and a free-form metadata block. See docs/ptl-format.md. The compact, paged
// version 2 is read by PtlV2File, and either version by read_ptl (ptl_v2.hpp).
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "pointillist/lod/sphere_tree.hpp"

namespace pointillist {

constexpr std::uint32_t kPtlVersion = 1;

// Writes `tree` to `path` atomically (temporary file in the same folder, then rename), with
// `metadata` (free text: source file, conversion settings) stored after the nodes.
// Throws IoError.
void write_ptl(const std::string& path, const SphereTree& tree, const std::string& metadata);

// A read-only memory-mapped .ptl file. `tree()` points into the mapping, so it stays valid as long
// as the PtlFile lives.
class PtlFile {
 public:
  // Maps and validates the file: magic, version, sizes, and every node's child range (so a
  // corrupt file cannot make traversal read out of bounds). Throws FormatError naming the file
  // and byte offset (for a version 2 file: one saying to use PtlV2File or read_ptl), or
  // IoError.
  static std::unique_ptr<PtlFile> open(const std::string& path);
  ~PtlFile();
  PtlFile(const PtlFile&) = delete;
  PtlFile& operator=(const PtlFile&) = delete;

  const SphereTreeView& tree() const { return view_; }
  const std::string& metadata() const { return metadata_; }
  std::uint32_t version() const { return version_; }
  std::uint64_t file_size() const { return size_; }

 private:
  PtlFile() = default;
  void* map_ = nullptr;
  std::uint64_t size_ = 0;
  std::uint32_t version_ = 0;
  SphereTreeView view_;
  std::string metadata_;
};

// True when the file starts with the .ptl magic (used to dispatch on content, not extension).
bool is_ptl_file(const std::string& path);
// The version field of a .ptl file's header, or 0 when the file does not start with the magic
// (or is shorter than the field).
std::uint32_t ptl_file_version(const std::string& path);

}  // namespace pointillist
