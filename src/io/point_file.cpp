// read_point_file: the reader is chosen by the file name's extension alone, so a file is never
// half-parsed as the wrong format.
#include "pointillist/io/point_file.hpp"

#include <cctype>
#include <charconv>
#include <filesystem>
#include <string_view>

#include "pointillist/core/error.hpp"
#include "pointillist/io/las.hpp"
#include "pointillist/io/obj.hpp"
#include "pointillist/io/ply.hpp"
#include "pointillist/io/xyz.hpp"
#include "pointillist/io/point_stream.hpp"
#include "streams.hpp"
#include "text_numbers.hpp"

namespace pointillist {
namespace {

enum class Kind { Unknown, Ply, Text, Obj, Las, Laz };

struct Extension {
  const char* suffix;
  Kind kind;
};

// Longer suffixes first, so ".ply.gz" wins over ".gz".
constexpr Extension kExtensions[] = {
    {".ply.gz", Kind::Ply}, {".xyz.gz", Kind::Text}, {".pts.gz", Kind::Text},
    {".csv.gz", Kind::Text}, {".txt.gz", Kind::Text}, {".obj.gz", Kind::Obj},
    {".las.gz", Kind::Las}, {".ply", Kind::Ply},      {".xyz", Kind::Text},
    {".pts", Kind::Text},    {".csv", Kind::Text},    {".txt", Kind::Text},
    {".obj", Kind::Obj},     {".las", Kind::Las},     {".laz", Kind::Laz}};

Kind kind_of(const std::string& path) {
  // Only the file name counts, not a folder called "scans.ply".
  const std::size_t slash = path.find_last_of('/');
  std::string name = path.substr(slash == std::string::npos ? 0 : slash + 1);
  for (char& c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  for (const Extension& e : kExtensions) {
    const std::string_view suffix(e.suffix);
    if (name.size() > suffix.size() && name.ends_with(suffix)) return e.kind;
  }
  return Kind::Unknown;
}

}  // namespace

std::string supported_point_file_extensions() {
  return ".ply, .ply.gz, .xyz, .pts, .csv, .txt (each also .gz), .obj, .obj.gz, .las, .las.gz";
}

bool is_point_file_extension(const std::string& path) {
  const Kind kind = kind_of(path);
  return kind != Kind::Unknown && kind != Kind::Laz;
}

bool may_hold_faces(const std::string& path) {
  const Kind kind = kind_of(path);
  return kind == Kind::Ply || kind == Kind::Obj;
}

PointSet read_point_file(const std::string& path, Progress& progress,
                         const PointReadOptions& options) {
  switch (kind_of(path)) {
    case Kind::Ply:
      return read_ply(path, progress, {.read_colors = options.read_colors, .pool = options.pool});
    case Kind::Text:
      return read_xyz(path, progress,
                      {.read_colors = options.read_colors,
                       .pool = options.pool,
                       .columns = options.columns});
    case Kind::Obj:
      return read_obj(path, progress, {.read_colors = options.read_colors});
    case Kind::Las:
      return read_las(path, progress, {.read_colors = options.read_colors, .pool = options.pool});
    case Kind::Laz:
      throw FormatError(path +
                        ": compressed LAS (LAZ) is not supported yet; decompress it with laszip or "
                        "pdal first, e.g. 'laszip -i in.laz -o out.las' or "
                        "'pdal translate in.laz out.las'");
    case Kind::Unknown:
      break;
  }
  throw FormatError(path + ": unknown point file type (scans: " +
                    supported_point_file_extensions() +
                    "; models: .ptl, .qs); rename the file if its extension is wrong, or convert "
                    "it to PLY");
}

std::optional<std::array<double, 3>> point_set_origin(const PointSet& points) {
  if (points.origin != std::array<double, 3>{}) return points.origin;
  constexpr std::string_view kPrefix = "origin: ";
  for (const std::string& comment : points.comments) {
    std::array<double, 3> origin{};
    if (comment.starts_with(kPrefix) &&
        io_detail::read_triple(comment, kPrefix.size(), origin)) {
      return origin;
    }
  }
  return std::nullopt;
}

namespace {

// A file without a streaming form, read whole when opened and handed out in batches.
class WholeFileStream final : public PointStream {
 public:
  WholeFileStream(const std::string& path, PointSet points) : points_(std::move(points)) {
    info_.path = path;
    info_.point_count = points_.size();
    info_.has_normals = points_.has_normals();
    info_.has_colors = points_.has_colors();
    info_.has_radii = points_.has_radii();
    info_.is_mesh = points_.is_mesh();
    info_.streamed = false;
    info_.resident_bytes = points_.size() * (sizeof(Vec3f) * (1 + info_.has_normals) +
                                             sizeof(Rgb8) * info_.has_colors +
                                             sizeof(float) * info_.has_radii) +
                           points_.triangles.size() * sizeof(points_.triangles[0]);
    std::error_code error;
    info_.file_size = std::filesystem::file_size(path, error);
    info_.origin = point_set_origin(points_).value_or(std::array<double, 3>{});
    info_.up = points_.up;
    for (const std::string& c : points_.comments) {
      if (!c.starts_with("origin: ")) info_.comments.push_back(c);
    }
  }

  std::size_t read(PointSet& batch, std::size_t max) override {
    const std::size_t n = std::min(max, points_.size() - next_);
    const auto take = [&](auto& dst, const auto& src) {
      if (src.empty()) {
        dst.clear();
      } else {
        dst.assign(src.begin() + std::ptrdiff_t(next_), src.begin() + std::ptrdiff_t(next_ + n));
      }
    };
    take(batch.positions, points_.positions);
    take(batch.normals, points_.normals);
    take(batch.colors, points_.colors);
    take(batch.radii, points_.radii);
    batch.triangles.clear();
    batch.comments.clear();
    next_ += n;
    return n;
  }
  void rewind() override { next_ = 0; }
  std::uint64_t bytes_done() const override {
    return points_.size() == 0 ? info_.file_size : info_.file_size * next_ / points_.size();
  }

 private:
  PointSet points_;
  std::size_t next_ = 0;
};

}  // namespace

std::unique_ptr<PointStream> open_point_stream(const std::string& path,
                                               const PointReadOptions& options) {
  if (!std::filesystem::exists(path)) {
    throw IoError(path + ": no such file; check the path (models fetched by "
                         "scripts/fetch-models.sh are in ~/.cache/pointillist/models)");
  }
  std::unique_ptr<PointStream> stream;
  const Kind kind = kind_of(path);
  if (kind == Kind::Ply) stream = io_detail::open_ply_stream(path, options);
  if (kind == Kind::Las) stream = io_detail::open_las_stream(path, options);
  if (kind == Kind::Text) stream = io_detail::open_xyz_stream(path, options);
  if (kind == Kind::Obj) stream = io_detail::open_obj_stream(path, options);
  if (stream) return stream;
  return std::make_unique<WholeFileStream>(path, read_point_file(path, Progress::none(), options));
}

std::unique_ptr<FaceStream> open_face_stream(const std::string& path, std::size_t window_bytes) {
  if (!std::filesystem::exists(path)) {
    throw IoError(path + ": no such file; check the path");
  }
  if (kind_of(path) == Kind::Ply) return io_detail::open_ply_face_stream(path, window_bytes);
  if (kind_of(path) == Kind::Obj) return io_detail::open_obj_face_stream(path);
  return nullptr;
}

std::optional<std::uint64_t> exact_point_count(const std::string& path) {
  if (!std::filesystem::exists(path)) {
    throw IoError(path + ": no such file; check the path (models fetched by "
                         "scripts/fetch-models.sh are in ~/.cache/pointillist/models)");
  }
  const Kind kind = kind_of(path);
  if (kind == Kind::Ply) {
    if (const auto stream = io_detail::open_ply_stream(path, {})) return stream->info().point_count;
  }
  if (kind == Kind::Las) return io_detail::las_header_point_count(path);
  return std::nullopt;
}

std::uint64_t point_count_estimate(const std::string& path) {
  if (const auto count = exact_point_count(path)) return *count;
  const std::uint64_t size = std::filesystem::file_size(path);
  const bool gzip = path.size() > 3 && path.compare(path.size() - 3, 3, ".gz") == 0;
  return (gzip ? 16 : 1) * size / 6 + 1;
}

}  // namespace pointillist
