// The files of a chunked conversion (private to pipeline; chunked_convert.cpp): the folder
// beside the output, one file of point records per chunk (its own points and its halo), and the
// chunks' prepared splats between the passes.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "pointillist/core/point_set.hpp"

namespace pointillist::chunking {

// The folder of a conversion's temporary files, beside the output; a folder left by a killed
// conversion into the same output is removed first. Removed with everything in it when
// destroyed. Another rank of an MPI job joins the folder rank 0 made (kJoin): it neither makes
// nor removes it.
class WorkFolder {
 public:
  enum Join { kJoin };
  explicit WorkFolder(const std::string& output);
  WorkFolder(const std::string& output, Join) : path_(output + ".chunks"), owner_(false) {}
  ~WorkFolder();
  WorkFolder(const WorkFolder&) = delete;
  WorkFolder& operator=(const WorkFolder&) = delete;
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
  bool owner_ = true;
};

// Appends records to one file per chunk (KIND-NNNNN in the folder) through a buffer each.
class ChunkFiles {
 public:
  // The buffer of each of `chunks` files when all of them may take `most` bytes, an eighth of
  // the memory budget at most: between 4 KB and 1 MB.
  static std::size_t buffer_bytes(std::size_t chunks, std::uint64_t most, std::uint64_t budget);
  ChunkFiles(const WorkFolder& folder, std::size_t chunks, const char* kind,
             std::size_t buffer_bytes);
  static std::string name(const char* kind, std::size_t c);
  // Threads may append at once to different chunks.
  void append(std::size_t c, const void* data, std::size_t size);
  void flush_all();

 private:
  void flush(std::size_t c);
  std::vector<std::vector<char>> buffers_;
  std::vector<std::string> paths_;
  std::size_t buffer_bytes_;
};

// A chunk record: position, colour, flags (bit 0: halo), input index, then normal and radius
// when present.
struct RecordLayout {
  bool normals = false, radii = false;
  std::size_t size() const { return 24 + (normals ? 12 : 0) + (radii ? 4 : 0); }
};

// Point i of `b` as a record of layout `l` in `out`.
void encode_record(const RecordLayout& l, const PointSet& b, std::size_t i, std::uint64_t index,
                   bool halo, char* out);

// A whole file (a chunk file read back). Throws IoError.
std::vector<char> read_whole(const std::string& path);

// A chunk file's points, which of them are its own (not halo) and their input indices.
PointSet read_chunk(const std::string& path, const RecordLayout& l, bool colors,
                    std::vector<std::uint8_t>& own, std::vector<std::uint64_t>& index);

// A chunk's splats (position, normal, radius, colour; and, between the passes, each one's input
// index and orientation piece) as arrays, in order.
struct Splats {
  PointSet points;
  std::vector<std::uint64_t> index;
  std::vector<std::uint32_t> piece;
};

// Throw IoError naming the file (a full disk: the error says so).
void write_splats(const std::string& path, const Splats& s);
// A file of write_splats with n splats, and colours, indices and pieces as said; without
// `geometry`, only the normals (and the indices and pieces asked for) are read.
Splats read_splats(const std::string& path, std::size_t n, bool colors, bool index, bool piece,
                   bool geometry = true);

// A halo point's view of its orientation, for the chunk that owns the point: its input index,
// the chunk and piece that hold it as halo, and its normal there.
struct Relation {
  std::uint64_t index;
  std::uint32_t chunk, piece;
  Vec3f normal;
};

}  // namespace pointillist::chunking
