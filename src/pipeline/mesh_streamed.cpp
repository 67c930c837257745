// A mesh larger than memory prepared for the chunked conversion (see mesh_streamed.hpp).
//
// Three passes: the vertices go to a scratch file of records (position, normal sum, radius);
// the faces stream past those records, held a page at a time (pages pushed out in clock order
// are written back), each triangle adding its cross product to its corners' sums and raising
// their radii to its enclosing circle's; then the vertices are read again and written out with
// what their records hold. A scan's faces mostly use vertices stored near each other, so few
// pages are in play at once; faces in any order still give the same result, only slower.
#include "mesh_streamed.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>
#include <optional>
#include <vector>

#include "pointillist/core/atomic_file.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/io/ply.hpp"
#include "pointillist/io/point_stream.hpp"
#include "pointillist/prep/radii.hpp"

namespace pointillist::chunking {
namespace {

struct VertexSums {
  Vec3f position;
  Vec3f normal;  // the faces' cross products, summed in face order
  float radius;  // the largest enclosing-circle radius; -1 while no face uses the vertex
};
static_assert(sizeof(VertexSums) == 28);

class ScratchFile {
 public:
  explicit ScratchFile(const std::string& path) : path_(path) {
    fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
    if (fd_ < 0) {
      throw IoError(path + ": cannot create a scratch file: " + std::strerror(errno) +
                    " (the output's folder must be writable)");
    }
  }
  ~ScratchFile() {
    ::close(fd_);
    ::unlink(path_.c_str());
  }
  ScratchFile(const ScratchFile&) = delete;
  ScratchFile& operator=(const ScratchFile&) = delete;

  void write(std::uint64_t offset, const void* data, std::size_t size) {
    if (!write_all_at(fd_, offset, data, size)) {
      throw IoError(path_ + ": cannot write the mesh's scratch file (is the disk full?); the "
                            "output was not written and the input is untouched");
    }
  }
  void read(std::uint64_t offset, void* data, std::size_t size) {
    char* p = static_cast<char*>(data);
    while (size > 0) {
      const ssize_t n = ::pread(fd_, p, size, static_cast<off_t>(offset));
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {
        throw IoError(path_ + ": cannot read back the mesh's scratch file (" +
                      (n < 0 ? std::string(std::strerror(errno)) : "it is shorter") +
                      "); was it changed while converting?");
      }
      p += n, size -= std::size_t(n), offset += std::uint64_t(n);
    }
  }

 private:
  std::string path_;
  int fd_ = -1;
};

// The records of a scratch file a page at a time: a page is read when first touched and
// written again when a newer one pushes it out (clock order), until freeze().
template <class Record>
class Pages {
 public:
  Pages(ScratchFile& file, std::uint64_t count, std::uint64_t page, std::uint64_t cache_bytes)
      : file_(file), count_(count), page_(std::max<std::uint64_t>(1, page)) {
    slot_of_.assign(static_cast<std::size_t>((count + page_ - 1) / page_), -1);
    max_slots_ = std::max<std::uint64_t>(4, cache_bytes / (page_ * sizeof(Record)));
  }
  Record& at(std::uint64_t v) {
    const std::uint64_t page = v / page_;
    if (page != last_page_) {
      last_ = hold(page);
      last_page_ = page;
    }
    return last_[v - page * page_];
  }
  // Writes the pages held, and from now on drops pages without writing them: the records are
  // only read from here on (pages pushed out later must come back from the file whole).
  void freeze() {
    for (const Slot& slot : slots_) {
      file_.write(first(slot.page) * sizeof(Record), slot.sums.data(),
                  slot.sums.size() * sizeof(Record));
    }
    write_back_ = false;
  }

 private:
  struct Slot {
    std::uint64_t page = 0;
    bool referenced = false;
    std::vector<Record> sums;
  };
  std::uint64_t first(std::uint64_t page) const { return page * page_; }
  std::size_t size(std::uint64_t page) const {
    return static_cast<std::size_t>(std::min(page_, count_ - first(page)));
  }
  Record* hold(std::uint64_t page) {
    std::int64_t s = slot_of_[page];
    if (s >= 0) {
      slots_[std::size_t(s)].referenced = true;
      return slots_[std::size_t(s)].sums.data();
    }
    if (slots_.size() < max_slots_) {
      s = std::int64_t(slots_.size());
      slots_.emplace_back();
    } else {
      while (slots_[hand_].referenced) {
        slots_[hand_].referenced = false;
        hand_ = (hand_ + 1) % slots_.size();
      }
      s = std::int64_t(hand_);
      hand_ = (hand_ + 1) % slots_.size();
      Slot& old = slots_[std::size_t(s)];
      if (write_back_) {
        file_.write(first(old.page) * sizeof(Record), old.sums.data(),
                    old.sums.size() * sizeof(Record));
      }
      slot_of_[old.page] = -1;
    }
    Slot& slot = slots_[std::size_t(s)];
    slot.page = page;
    slot.referenced = true;
    slot.sums.resize(size(page));
    file_.read(first(page) * sizeof(Record), slot.sums.data(),
               slot.sums.size() * sizeof(Record));
    slot_of_[page] = s;
    return slot.sums.data();
  }

  ScratchFile& file_;
  std::uint64_t count_, page_, max_slots_ = 4;
  std::vector<std::int64_t> slot_of_;
  std::vector<Slot> slots_;
  std::size_t hand_ = 0;
  std::uint64_t last_page_ = ~std::uint64_t{0};
  Record* last_ = nullptr;
  bool write_back_ = true;
};

constexpr std::size_t kBatch = 1 << 16;

}  // namespace

bool prepare_mesh_streamed(const std::string& input, const std::string& output,
                           const std::string& records, const PrepareOptions& prepare,
                           Progress& progress, const StreamedMeshOptions& options) {
  // A binary PLY's face window and its triangles: each a quarter of the pages' memory, 1 to
  // 32 MB.
  std::unique_ptr<FaceStream> faces = open_face_stream(
      input, static_cast<std::size_t>(std::clamp<std::uint64_t>(options.cache_bytes / 4,
                                                                std::uint64_t{1} << 20,
                                                                std::uint64_t{32} << 20)));
  if (!faces) return false;
  const std::string& name = prepare.input_name;
  if (prepare.drop_outliers) {
    throw OptionError(name + " is a mesh: outlier removal applies to point clouds (a mesh's "
                      "faces define its surface; drop the option)");
  }
  const std::unique_ptr<PointStream> vertices = open_point_stream(input);
  const PointStreamInfo& info = vertices->info();
  const std::uint64_t n = info.point_count;
  if (faces->vertex_count() != n) {
    throw Error(input + ": the vertex and face readers disagree on the vertex count (" +
                std::to_string(n) + " and " + std::to_string(faces->vertex_count()) +
                "); this is a bug in Pointillist, please report it");
  }
  ScratchFile file(records);
  PointSet batch;
  {
    ProgressPhase phase(progress, "mesh vertices", n);
    std::vector<VertexSums> out;
    for (std::uint64_t done = 0; done < n;) {
      const std::size_t got = vertices->read(batch, kBatch);
      if (got == 0) break;
      out.resize(got);
      for (std::size_t i = 0; i < got; ++i) out[i] = {batch.positions[i], {0, 0, 0}, -1.0f};
      file.write(done * sizeof(VertexSums), out.data(), got * sizeof(VertexSums));
      done += got;
      phase.advance(got);
    }
  }
  // OBJ's file normals: the vn lines go to a scratch file, and each vertex sums those its
  // corners name, in file order (read_obj's sums), in a scratch file of its own.
  std::optional<ScratchFile> vn_file, vn_sum_file;
  std::optional<Pages<Vec3f>> vn, vn_sums;
  std::uint64_t cache = options.cache_bytes;
  if (faces->normal_count() > 0) {
    cache /= 3;
    vn_file.emplace(records + ".vn");
    std::vector<Vec3f> values;
    for (std::uint64_t at = 0; faces->read_normals(values); at += values.size()) {
      vn_file->write(at * sizeof(Vec3f), values.data(), values.size() * sizeof(Vec3f));
    }
    vn_sum_file.emplace(records + ".vns");
    values.assign(kBatch, Vec3f{0, 0, 0});
    for (std::uint64_t at = 0; at < n; at += kBatch) {
      vn_sum_file->write(at * sizeof(Vec3f), values.data(),
                         std::min<std::uint64_t>(kBatch, n - at) * sizeof(Vec3f));
    }
    vn.emplace(*vn_file, faces->normal_count(), options.page_vertices, cache);
    vn_sums.emplace(*vn_sum_file, n, options.page_vertices, cache);
  }
  bool normal_refs = false;
  Pages<VertexSums> pages(file, n, options.page_vertices, cache);
  std::uint64_t used = 0, triangle_count = 0;
  {
    ProgressPhase phase(progress, "mesh faces", faces->face_count());
    std::vector<std::array<std::uint32_t, 3>> triangles;
    std::uint64_t reported = 0;
    while (faces->read(triangles)) {
      for (const auto& t : triangles) {
        // Copies first: touching one corner's page may push out another's.
        const Vec3f a = pages.at(t[0]).position, b = pages.at(t[1]).position,
                    c = pages.at(t[2]).position;
        const Vec3f face = cross(b - a, c - a);
        const float r = enclosing_circle_radius(a, b, c);
        for (const std::uint32_t v : t) {
          VertexSums& s = pages.at(v);
          if (s.radius < 0) ++used;
          s.normal += face;
          s.radius = std::max(std::max(s.radius, 0.0f), r);
        }
      }
      for (const auto& [v, k] : faces->normal_refs()) {
        const Vec3f value = vn->at(k);
        vn_sums->at(v) += value;
        normal_refs = true;
      }
      triangle_count += triangles.size();
      phase.advance(faces->faces_done() - reported);
      reported = faces->faces_done();
    }
  }
  faces.reset();
  pages.freeze();
  if (vn_sums) vn_sums->freeze();
  // Every vertex of an OBJ whose corners name normals has one (read_obj: the faces' where its
  // own sum is zero).
  const bool file_normals = (info.has_normals && vertices->saw_usable_normals()) || normal_refs;
  const NormalSource source = prepare.normals;
  if (source == NormalSource::Keep && !file_normals) {
    throw Error("--normals keep: " + name +
                " has no normals (no nx/ny/nz vertex properties); use --normals auto or pca");
  }
  // A file whose faces make no triangle is a point cloud: every vertex is kept, as in one piece.
  const bool mesh = triangle_count > 0;
  const bool mesh_normals =
      mesh && (source == NormalSource::Mesh || (source == NormalSource::Auto && !file_normals));
  PointSet layout;
  layout.comments = info.comments;
  layout.origin = info.origin;
  layout.up = info.up;
  const bool normals = mesh_normals || (file_normals && source != NormalSource::Pca);
  if (normals) layout.normals.resize(1);
  if (info.has_colors) layout.colors.resize(1);
  const bool radii = mesh || info.has_radii;
  if (radii) layout.radii.resize(1);
  layout.positions.resize(1);
  PlyPointWriter writer(output, layout, mesh ? used : n);
  {
    ProgressPhase phase(progress, "mesh splats", n);
    vertices->rewind();
    PointSet out;
    for (std::uint64_t done = 0; done < n;) {
      const std::size_t got = vertices->read(batch, kBatch);
      if (got == 0) break;
      out.positions.clear(), out.normals.clear(), out.colors.clear(), out.radii.clear();
      for (std::size_t i = 0; i < got; ++i) {
        const VertexSums& s = pages.at(done + i);
        if (mesh && s.radius < 0) continue;  // used by no face: dropped
        out.positions.push_back(batch.positions[i]);
        if (mesh_normals) {
          out.normals.push_back(normalized(s.normal, {0, 0, 1}));
        } else if (normals && normal_refs) {
          Vec3f sum = vn_sums->at(done + i);
          if (!(length_squared(sum) > 0.0f) || !is_finite(sum)) sum = s.normal;
          out.normals.push_back(normalized(sum));
        } else if (normals) {
          out.normals.push_back(batch.normals[i]);
        }
        if (info.has_colors) out.colors.push_back(batch.colors[i]);
        if (info.has_radii) {
          out.radii.push_back(batch.radii[i]);
        } else if (radii) {
          out.radii.push_back(s.radius);
        }
      }
      writer.write(out);
      done += got;
      phase.advance(got);
    }
  }
  writer.commit();
  return true;
}

}  // namespace pointillist::chunking
