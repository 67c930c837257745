// PLY reader: loads the file into memory (mmap, or inflate for .gz), parses the header, plans
// which property feeds which PointSet array, and hands the body to the ascii or binary decoder.
#include <sys/mman.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <optional>

#include "decimal_scan.hpp"
#include "pointillist/core/file_bytes.hpp"
#include "ply_body.hpp"
#include "text_numbers.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/core/thread_pool.hpp"
#include "pointillist/io/ply.hpp"
#include "file_window.hpp"
#include "streams.hpp"

namespace pointillist {
namespace ply {

namespace {


[[noreturn]] void fail_line(const std::string& path, std::size_t line, const std::string& what) {
  throw FormatError(path + ": line " + std::to_string(line) + ": " + what);
}

ColorScale color_scale(ScalarType type) {
  if (!is_integer(type)) return ColorScale::Unit;
  return type == ScalarType::Uint16 ? ColorScale::Word : ColorScale::Byte;
}

struct VertexPlanResult {
  bool normals = false, colors = false, radii = false;
  ColorScale scales[3] = {};
};

// Assigns `targets` to the properties of the first alternative whose names are all present
// (normals need nx, ny and nz; colors red green blue, else diffuse_*). Returns false if none is.
bool assign_group(const std::string& path, const Element& element, ElementPlan& plan,
                  std::initializer_list<std::initializer_list<const char*>> alternatives,
                  std::initializer_list<Target> targets) {
  for (const auto& names : alternatives) {
    std::vector<int> found;
    for (const char* name : names) {
      const int index = element.find(name);
      if (index < 0) break;
      found.push_back(index);
    }
    if (found.size() != names.size()) continue;
    auto target = targets.begin();
    for (int index : found) {
      const Property& property = element.properties[static_cast<std::size_t>(index)];
      if (property.is_list)
        fail_line(path, property.header_line,
                  "element vertex: property " + property.name + " must be a scalar, not a list");
      plan.properties[static_cast<std::size_t>(index)].target = *target++;
    }
    return true;
  }
  return false;
}

VertexPlanResult plan_vertex(const std::string& path, const Element& element, ElementPlan& plan,
                             const PlyReadOptions& options) {
  for (const char* axis : {"x", "y", "z"}) {
    if (element.find(axis) < 0)
      fail_line(path, element.header_line,
                std::string("element vertex has no property ") + axis +
                    " (positions need float properties x, y and z)");
  }
  VertexPlanResult result;
  assign_group(path, element, plan, {{"x", "y", "z"}}, {kX, kY, kZ});
  result.normals = assign_group(path, element, plan, {{"nx", "ny", "nz"}}, {kNx, kNy, kNz});
  if (options.read_colors) {
    result.colors =
        assign_group(path, element, plan,
                     {{"red", "green", "blue"}, {"diffuse_red", "diffuse_green", "diffuse_blue"}},
                     {kRed, kGreen, kBlue});
    if (result.colors) {
      for (std::size_t j = 0; j < element.properties.size(); ++j) {
        const Target t = plan.properties[j].target;
        if (t >= kRed && t <= kBlue)
          result.scales[t - kRed] = color_scale(element.properties[j].type);
      }
    }
  }
  result.radii = assign_group(path, element, plan, {{"radius"}, {"scale"}}, {kRadius});
  return result;
}

void plan_face(const std::string& path, const Element& element, ElementPlan& plan) {
  int index = element.find("vertex_indices");
  if (index < 0) index = element.find("vertex_index");
  if (index < 0) return;  // a face element without indices carries nothing we use
  const Property& property = element.properties[static_cast<std::size_t>(index)];
  if (!property.is_list)
    fail_line(path, property.header_line,
              "element face: property " + property.name +
                  " must be a list (expected 'property list uchar int " + property.name + "')");
  if (!is_integer(property.type))
    fail_line(path, property.header_line,
              "element face: list " + property.name + " must hold an integer type, found " +
                  scalar_name(property.type));
  plan.kind = ElementPlan::Kind::Face;
  plan.properties[static_cast<std::size_t>(index)].is_face_indices = true;
}

// Turns progress in body bytes into units of the file size; a .gz file spends the first half
// of its units on inflating and the second half on decoding.
class PlyProgress {
 public:
  PlyProgress(Progress& progress, std::uint64_t total)
      : phase_(progress, "read", total), total_(total) {}
  void advance(std::uint64_t units) {
    if (units == 0) return;
    reported_.fetch_add(units, std::memory_order_relaxed);
    phase_.advance(units);
  }
  void finish() {
    const std::uint64_t done = reported_.load();
    if (done < total_) phase_.advance(total_ - done);
  }
  std::uint64_t total() const { return total_; }

 private:
  ProgressPhase phase_;
  std::uint64_t total_;
  std::atomic<std::uint64_t> reported_{0};
};


// The header's comments, except that our own writer's coordinate frame ("origin: X Y Z",
// "up: X Y Z") goes to `origin` and `up`.
void take_header_comments(const Header& header, std::vector<std::string>& comments,
                          std::array<double, 3>& origin, Vec3f& up) {
  for (const std::string& c : header.comments) {
    if (c.starts_with("origin: ") && io_detail::read_triple(c, 8, origin)) continue;
    std::array<double, 3> axis{};
    if (c.starts_with("up: ") && io_detail::read_triple(c, 4, axis) &&
        (axis[0] != 0 || axis[1] != 0 || axis[2] != 0)) {
      up = normalized(Vec3f{float(axis[0]), float(axis[1]), float(axis[2])});
      continue;
    }
    comments.push_back(c);
  }
}

// Sizes a large output array. Asking for transparent huge pages before the first touch makes
// filling hundreds of MB take a few hundred page faults instead of tens of thousands (measured:
// the faults were a quarter of the time of a 200 MB binary read).
template <class T>
void resize_output(std::vector<T>& v, std::size_t n) {
  constexpr std::size_t kHugePage = std::size_t{2} << 20;
  v.reserve(n);
  const auto begin = reinterpret_cast<std::uintptr_t>(v.data());
  const std::uintptr_t first = (begin + kHugePage - 1) & ~(kHugePage - 1);
  const std::uintptr_t last = (begin + n * sizeof(T)) & ~(kHugePage - 1);
  if (last > first)
    ::madvise(reinterpret_cast<void*>(first), last - first, MADV_HUGEPAGE);  // a hint only
  v.resize(n);
}

// One read: the header, the plans, the output arrays. Not movable (ctx points into it).
class PlyRead {
 public:
  PlyRead(const std::string& path, const PlyReadOptions& options, PlyProgress& progress)
      : options_(options), progress_(progress) {
    ctx.path = path;
    ctx.pool = options.pool;
  }
  PlyRead(const PlyRead&) = delete;
  PlyRead& operator=(const PlyRead&) = delete;

  // Parses the header at the start of `data` (the whole file, or a prefix holding the whole
  // header) and plans the body. Sets ctx.data to `data`.
  void prepare(std::string_view data, bool compressed) {
    header = parse_header(data, ctx.path);
    ctx.data = data;
    ctx.header = &header;
    ctx.compressed = compressed;
    ctx.plans.resize(header.elements.size());
    int vertex_element = -1;
    for (std::size_t e = 0; e < header.elements.size(); ++e) {
      const Element& element = header.elements[e];
      ElementPlan& plan = ctx.plans[e];
      plan.properties.resize(element.properties.size());
      if (element.name == "vertex") {
        plan.kind = ElementPlan::Kind::Vertex;
        vertex_plan_ = plan_vertex(ctx.path, element, plan, options_);
        vertex_element = static_cast<int>(e);
      } else if (element.name == "face") {
        plan_face(ctx.path, element, plan);
      }
    }
    if (vertex_element < 0)
      fail_line(ctx.path, header.line_count,
                "header declares no vertex element (expected 'element vertex <count>')");
    const Element& vertices = header.elements[static_cast<std::size_t>(vertex_element)];
    if (vertices.count == 0)
      fail_line(ctx.path, vertices.header_line,
                "element vertex has count 0: the file has no points");
    ctx.vertex_count = vertices.count;
  }

  // Sizes the outputs; call after check_counts_fit(ctx) has passed. `body_size_estimate`: the
  // bytes the body decoder will report, for scaling progress.
  void allocate(std::uint64_t data_size_estimate) {
    // Triangles hold 32-bit indices.
    for (std::size_t e = 0; e < header.elements.size(); ++e) {
      if (ctx.plans[e].kind == ElementPlan::Kind::Face && ctx.vertex_count > 0xffffffffu)
        fail_line(ctx.path, header.elements[e].header_line,
                  "faces cannot index more than 2^32 vertices (the file has " +
                      std::to_string(ctx.vertex_count) + ")");
    }
    const auto n = static_cast<std::size_t>(ctx.vertex_count);
    resize_output(points.positions, n);
    if (vertex_plan_.normals) resize_output(points.normals, n);
    if (vertex_plan_.colors) resize_output(points.colors, n);
    if (vertex_plan_.radii) resize_output(points.radii, n);
    ctx.vertex.positions = points.positions.data();
    ctx.vertex.normals = vertex_plan_.normals ? points.normals.data() : nullptr;
    ctx.vertex.colors = vertex_plan_.colors ? points.colors.data() : nullptr;
    ctx.vertex.radii = vertex_plan_.radii ? points.radii.data() : nullptr;
    std::copy_n(vertex_plan_.scales, 3, ctx.vertex.color_scale);
    for (std::size_t e = 0; e < header.elements.size(); ++e) {
      // Most faces are triangles; check_counts_fit bounds the count by the file size.
      if (ctx.plans[e].kind == ElementPlan::Kind::Face)
        points.triangles.reserve(points.triangles.size() +
                                 static_cast<std::size_t>(header.elements[e].count));
    }
    // Units per decoded byte: the rest of the file size (half of it after inflating).
    const std::uint64_t total = progress_.total();
    const std::uint64_t units_left = ctx.compressed ? total - total / 2 : total;
    const double units_per_byte =
        data_size_estimate == 0 ? 0.0 : double(units_left) / double(data_size_estimate);
    progress_.advance(static_cast<std::uint64_t>(double(header.body_offset) * units_per_byte));
    ctx.on_bytes = [this, units_per_byte](std::uint64_t body_bytes) {
      progress_.advance(static_cast<std::uint64_t>(double(body_bytes) * units_per_byte));
    };
  }

  PointSet finish() {
    if (points.has_normals()) io_detail::finish_normals(points.normals);
    take_header_comments(header, points.comments, points.origin, points.up);
    progress_.finish();
    return std::move(points);
  }

  const VertexPlanResult& vertex_plan() const { return vertex_plan_; }

  Header header;
  BodyContext ctx;
  PointSet points;

 private:
  const PlyReadOptions& options_;
  PlyProgress& progress_;
  VertexPlanResult vertex_plan_;
};

// True once `data` holds a whole "end_header" line.
bool has_header_end(std::string_view data) {
  for (std::size_t at = data.find("end_header"); at != std::string_view::npos;
       at = data.find("end_header", at + 1)) {
    if (at > 0 && data[at - 1] != '\n') continue;
    std::size_t p = at + 10;
    while (p < data.size() && (data[p] == ' ' || data[p] == '\t' || data[p] == '\r')) ++p;
    if (p < data.size() && data[p] == '\n') return true;
  }
  return false;
}

struct StreamOverflow {};

// For GzipInflater::set_limit: the most bytes the file's header allows once the header is in,
// plus 1 MiB for what some writers leave after the body (a header that is not in the first
// 16 MiB does not exist: the inflating stops there and the parser reports it).
std::uint64_t header_limit(std::string_view prefix, const std::string& path) {
  constexpr std::uint64_t kMaxHeaderBytes = 16 << 20;
  if (!has_header_end(prefix.substr(0, kMaxHeaderBytes))) {
    return prefix.size() >= kMaxHeaderBytes ? kMaxHeaderBytes
                                            : std::numeric_limits<std::uint64_t>::max();
  }
  try {
    const std::uint64_t most = parse_header(prefix, path).max_file_bytes();
    constexpr std::uint64_t kSlack = 1 << 20;
    return most > std::numeric_limits<std::uint64_t>::max() - kSlack ? most : most + kSlack;
  } catch (const FormatError&) {
    return std::numeric_limits<std::uint64_t>::max();  // the parser reports it
  }
}

// The reading side of read_gzip_streaming: waits for the header, then parses the body as it
// is inflated.
PointSet parse_stream(GzipInflater& inflater,
                      const std::function<StreamState(std::size_t)>& wait, const std::string& path,
                      const PlyReadOptions& options, PlyProgress& progress) {
  StreamState state = wait(1 << 16);
  while (!state.finished && !has_header_end({inflater.data(), state.available}))
    state = wait(std::max<std::size_t>(state.available * 2, 1 << 16));
  PlyRead read(path, options, progress);
  read.prepare({inflater.data(), state.available}, true);
  if (read.header.format != Format::Ascii) {
    state = wait(std::numeric_limits<std::size_t>::max());
    read.ctx.data = {inflater.data(), state.available};
    read.ctx.pool = nullptr;  // this runs in one of the pool's tasks: no nested run
    check_counts_fit(read.ctx);
    read.allocate(state.available);
    decode_binary_body(read.ctx, read.points.triangles);
    return read.finish();
  }
  // Until the end, the capacity stands in for the size in the count check; if that check
  // fails, wait for the real size and check again for the exact message.
  read.ctx.data = {inflater.data(), inflater.capacity()};
  try {
    check_counts_fit(read.ctx);
  } catch (const FormatError&) {
    state = wait(std::numeric_limits<std::size_t>::max());
    read.ctx.data = {inflater.data(), state.available};
    check_counts_fit(read.ctx);
    throw;
  }
  read.allocate(inflater.capacity());
  decode_ascii_stream(read.ctx, read.points.triangles, wait);
  return read.finish();
}

// Inflating on one thread while parsing on another: the ascii body is parsed as it appears.
// Returns nothing when the gzip trailer under-stated the size (a multi-member or > 4 GiB file);
// the caller then starts over with a growing buffer.
std::optional<PointSet> read_gzip_streaming(const FileBytes& raw,
                                            const std::string& path, const PlyReadOptions& options,
                                            PlyProgress& progress,
                                            const std::function<void(std::uint64_t)>& on_inflate) {
  GzipInflater inflater(raw.view(), path);
  inflater.set_limit([&](std::string_view prefix) { return header_limit(prefix, path); });
  const auto wait = [&](std::size_t bytes) {
    bool finished = false;
    const std::size_t available = inflater.wait_for(bytes, finished);
    if (finished && inflater.overflowed()) throw StreamOverflow{};
    return StreamState{available, finished};
  };
  std::optional<PointSet> result;
  try {
    options.pool->run(2, [&](std::size_t task) {
      if (task == 0) {
        inflater.run(false, on_inflate);
        return;
      }
      try {
        result = parse_stream(inflater, wait, path, options, progress);
      } catch (...) {
        inflater.cancel();
        throw;
      }
    });
  } catch (const StreamOverflow&) {
    return std::nullopt;
  }
  return result;
}

}  // namespace
}  // namespace ply

PointSet read_ply(const std::string& path, Progress& progress, const PlyReadOptions& options) {
  using namespace ply;
  FileBytes raw = FileBytes::map(path);
  PlyProgress read_progress(progress, raw.file_size());
  // Inflating earns the first half of the progress units of a .gz file.
  std::uint64_t inflated = 0;
  const auto on_inflate = [&](std::uint64_t consumed) {
    read_progress.advance((inflated + consumed) / 2 - inflated / 2);
    inflated += consumed;
  };

  const bool gzip = has_gzip_magic(raw.view());
  if (gzip && options.pool && options.pool->thread_count() >= 2) {
    if (auto points = read_gzip_streaming(raw, path, options, read_progress, on_inflate))
      return std::move(*points);
  }
  const FileBytes bytes =
      gzip
          ? FileBytes::inflate(
                raw, path, inflated == 0 ? std::function<void(std::uint64_t)>(on_inflate) : nullptr,
                [&](std::string_view prefix) { return header_limit(prefix, path); })
          : std::move(raw);
  PlyRead read(path, options, read_progress);
  read.prepare(bytes.view(), bytes.was_compressed());
  check_counts_fit(read.ctx);
  read.allocate(bytes.view().size());
  if (read.header.format == Format::Ascii)
    decode_ascii_body(read.ctx, read.points.triangles);
  else
    decode_binary_body(read.ctx, read.points.triangles);
  return read.finish();
}

namespace io_detail {
namespace {

using namespace ply;


// The start of a file, decompressed, up to its whole header (or 16 MB).
std::vector<char> header_prefix(const FileWindow& file) {
  constexpr std::size_t kMaxHeaderBytes = 16 << 20;
  std::vector<char> prefix;
  for (std::size_t want = 1 << 16;; want *= 4) {
    file.read_some(0, want, prefix);
    const std::string_view head(prefix.data(), prefix.size());
    if (has_header_end(head) || prefix.size() < want || want >= kMaxHeaderBytes) return prefix;
  }
}

class PlyStream final : public PointStream {
 public:
  PlyStream(std::unique_ptr<FileWindow> file, const Header& header, std::size_t vertex_element,
            const ElementPlan& plan, std::uint64_t vertex_offset, const VertexPlanResult& vp,
            ThreadPool* pool)
      : file_(std::move(file)), vertex_offset_(vertex_offset), vp_(vp) {
    window_header_.format = header.format;
    window_header_.elements = {header.elements[vertex_element]};
    window_header_.body_offset = 0;
    ctx_.path = file_->path();
    ctx_.header = &window_header_;
    ctx_.plans = {plan};
    ctx_.pool = pool;
    std::copy_n(vp.scales, 3, ctx_.vertex.color_scale);
  }

  std::size_t read(PointSet& batch, std::size_t max) override {
    Element& element = window_header_.elements[0];
    const std::size_t stride = element.fixed_size();
    const std::uint64_t n =
        std::min<std::uint64_t>({max, info_.point_count - next_,
                                 std::max<std::uint64_t>(1, kStreamWindowBytes / stride)});
    size_batch(batch, static_cast<std::size_t>(n), info_);  // info_ says what vp_ reads
    if (n == 0) return 0;
    const std::uint64_t at = vertex_offset_ + next_ * stride;
    file_->read(at, static_cast<std::size_t>(n * stride), buffer_);
    element.count = n;
    ctx_.data = {buffer_.data(), buffer_.size()};
    ctx_.vertex_count = n;
    ctx_.vertex.positions = batch.positions.data();
    ctx_.vertex.normals = vp_.normals ? batch.normals.data() : nullptr;
    ctx_.vertex.colors = vp_.colors ? batch.colors.data() : nullptr;
    ctx_.vertex.radii = vp_.radii ? batch.radii.data() : nullptr;
    ctx_.byte_base = at;
    ctx_.index_base = next_;
    ctx_.index_total = info_.point_count;
    std::vector<Triangle> none;
    decode_binary_body(ctx_, none);
    if (vp_.normals && normalize_normals_window(batch.normals)) usable_normals_ = true;
    next_ += n;
    return n;
  }
  void rewind() override { next_ = 0; }
  std::uint64_t bytes_done() const override {
    return vertex_offset_ + next_ * window_header_.elements[0].fixed_size();
  }
  bool saw_usable_normals() const override { return usable_normals_; }

  void set_info(PointStreamInfo info) { info_ = std::move(info); }

 private:
  std::unique_ptr<FileWindow> file_;
  std::uint64_t vertex_offset_;
  VertexPlanResult vp_;
  Header window_header_;
  BodyContext ctx_;
  std::uint64_t next_ = 0;
  bool usable_normals_ = false;
  std::vector<char> buffer_;
};

}  // namespace

std::unique_ptr<PointStream> open_ply_stream(const std::string& path,
                                             const PointReadOptions& options) {
  auto file = std::make_unique<FileWindow>(path);
  const std::vector<char> prefix = header_prefix(*file);
  PlyProgress progress(Progress::none(), 1);
  const PlyReadOptions read_options{.read_colors = options.read_colors, .pool = options.pool};
  PlyRead read(path, read_options, progress);
  read.prepare({prefix.data(), prefix.size()}, file->compressed());
  const Header& header = read.header;
  PointStreamInfo info;
  info.path = path;
  info.has_normals = read.vertex_plan().normals;
  info.has_colors = read.vertex_plan().colors;
  info.has_radii = read.vertex_plan().radii;
  for (std::size_t e = 0; e < header.elements.size(); ++e) {
    if (read.ctx.plans[e].kind == ElementPlan::Kind::Face && header.elements[e].count > 0)
      info.is_mesh = true;
  }
  take_header_comments(header, info.comments, info.origin, info.up);
  if (header.format == Format::Ascii) {
    std::size_t vertex = 0;
    while (header.elements[vertex].name != "vertex") ++vertex;
    const Element& element = header.elements[vertex];
    // At least a digit and a blank or newline for each value: a count the file cannot hold is
    // refused before anything is sized by it.
    const std::uint64_t values = std::max<std::size_t>(1, element.properties.size());
    if (element.count > std::numeric_limits<std::uint64_t>::max() / (2 * values)) {
      throw FormatError(path + ": element vertex has " + std::to_string(element.count) +
                        " lines, more than any file holds; the header is wrong");
    }
    file->check_holds(element.count * 2 * values,
                      std::to_string(element.count) + " vertex lines of " +
                          std::to_string(values) + " values");
    info.point_count = element.count;
    info.file_size = file->size();
    return open_ascii_vertex_stream(path, header, vertex, read.ctx.plans[vertex],
                                    read.vertex_plan().scales, std::move(info));
  }
  // offset + the bytes of `e`, refused when a header's count makes it overflow
  const auto past = [&](std::uint64_t offset, const Element& e) {
    const std::uint64_t stride = std::max<std::uint64_t>(1, e.fixed_size());
    if (e.count > (std::numeric_limits<std::uint64_t>::max() - offset) / stride) {
      throw FormatError(path + ": element " + e.name + " has " + std::to_string(e.count) +
                        " records of " + std::to_string(stride) +
                        " bytes, more than any file holds; the header is wrong");
    }
    return offset + e.count * e.fixed_size();
  };
  std::uint64_t offset = header.body_offset;
  std::size_t vertex = 0;
  for (; header.elements[vertex].name != "vertex"; ++vertex) {
    const Element& e = header.elements[vertex];
    if (e.has_lists()) return nullptr;  // where the vertices start depends on the lists
    offset = past(offset, e);
  }
  const Element& element = header.elements[vertex];
  if (element.has_lists()) return nullptr;
  const std::uint64_t need = past(offset, element);
  file->check_holds(need, std::to_string(element.count) + " vertices of " +
                              std::to_string(element.fixed_size()) + " bytes from byte " +
                              std::to_string(offset));
  info.point_count = element.count;
  // Progress counts decompressed bytes of a gzip file, up to the last vertex.
  info.file_size = file->compressed() ? need : file->size();
  auto stream = std::make_unique<PlyStream>(std::move(file), header, vertex, read.ctx.plans[vertex],
                                            offset, read.vertex_plan(), options.pool);
  stream->set_info(std::move(info));
  return stream;
}

std::unique_ptr<FaceStream> open_ply_face_stream(const std::string& path,
                                                 std::size_t window_bytes) {
  auto file = std::make_unique<FileWindow>(path);
  const std::vector<char> prefix = header_prefix(*file);
  PlyProgress progress(Progress::none(), 1);
  const PlyReadOptions options;  // (PlyRead keeps a reference)
  PlyRead read(path, options, progress);
  read.prepare({prefix.data(), prefix.size()}, file->compressed());
  const Header& header = read.header;
  for (std::size_t e = 0; e < header.elements.size(); ++e) {
    if (read.ctx.plans[e].kind != ElementPlan::Kind::Face || header.elements[e].count == 0) continue;
    if (read.ctx.vertex_count > 0xffffffffu) {
      fail_line(path, header.elements[e].header_line,
                "faces cannot index more than 2^32 vertices (the file has " +
                    std::to_string(read.ctx.vertex_count) + ")");
    }
    if (header.format == Format::Ascii) {
      return open_ascii_face_stream(path, header, e, read.ctx.plans[e], read.ctx.vertex_count);
    }
    return make_ply_face_stream(std::move(file), header, e, read.ctx.plans[e],
                                read.ctx.vertex_count, window_bytes);
  }
  return nullptr;
}

}  // namespace io_detail
}  // namespace pointillist
