// Decoding of a PLY body into PointSet arrays (private to the io module). The reader turns the
// header into one ElementPlan per element (which property feeds which output), then hands the
// plans to the ascii or the binary decoder.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "ply_header.hpp"
#include "pointillist/core/math.hpp"
#include "pointillist/io/point_stream.hpp"

namespace pointillist {
class ThreadPool;
}

namespace pointillist::ply {

using Triangle = std::array<std::uint32_t, 3>;

// Vertex outputs a property can feed. Values pass through a float slot per target.
enum Target : std::int8_t {
  kNoTarget = -1,
  kX,
  kY,
  kZ,
  kNx,
  kNy,
  kNz,
  kRed,
  kGreen,
  kBlue,
  kRadius,
  kTargetCount
};

// How a color property's value maps to 0..255.
enum class ColorScale : std::uint8_t {
  Unit,  // float/double 0..1
  Word,  // ushort 0..65535
  Byte,  // other integer types, clamped to 0..255
};

struct PropertyPlan {
  Target target = kNoTarget;
  bool is_face_indices = false;
};

struct ElementPlan {
  enum class Kind { Vertex, Face, Skip };
  Kind kind = Kind::Skip;
  std::vector<PropertyPlan> properties;  // parallel to Element::properties
};

// Destination arrays, sized to the vertex count; null when the attribute is not read.
struct VertexOutput {
  Vec3f* positions = nullptr;
  Vec3f* normals = nullptr;
  Rgb8* colors = nullptr;
  float* radii = nullptr;
  ColorScale color_scale[3] = {ColorScale::Byte, ColorScale::Byte, ColorScale::Byte};
};

struct BodyContext {
  std::string path;
  std::string_view data;  // the whole (decompressed) file
  const Header* header = nullptr;
  bool compressed = false;
  std::vector<ElementPlan> plans;  // parallel to header->elements
  VertexOutput vertex;
  std::uint64_t vertex_count = 0;
  ThreadPool* pool = nullptr;
  // Told about body bytes decoded, in chunks; may be called from several threads.
  std::function<void(std::uint64_t)> on_bytes;
  // A window of a streamed file: `data` starts at byte `byte_base` of the file and its first
  // vertex is vertex `index_base` of `index_total` (0: the header's count), for messages.
  std::uint64_t byte_base = 0;
  std::uint64_t index_base = 0;
  std::uint64_t index_total = 0;
  std::uint64_t line_base = 0;  // lines of the file before `data` (ascii windows)

  // "path: byte N: what" (binary bodies).
  [[noreturn]] void fail_at_byte(std::size_t offset, const std::string& what) const;
  // "path: line N: what" (ascii bodies); `pos` points into data.
  [[noreturn]] void fail_at_char(const char* pos, const std::string& what) const;
  // "vertex 12 of 5000" (0-based index, as face indices count).
  std::string instance(std::size_t element, std::uint64_t index) const;
  // "property z" / "list property vertex_indices".
  std::string property(std::size_t element, std::size_t property) const;
};

// Decode the body after the header into ctx.vertex and `triangles` (appended, fan-triangulated).
// Throw FormatError on malformed data.
void decode_binary_body(const BodyContext& ctx, std::vector<Triangle>& triangles);
void decode_ascii_body(const BodyContext& ctx, std::vector<Triangle>& triangles);

// An integer value (list counts and indices) at `p`, byte-swapped when `swap`.
std::int64_t load_integer(ScalarType type, const unsigned char* p, bool swap);

// What a producer still filling ctx.data has delivered.
struct StreamState {
  std::size_t available = 0;  // bytes of ctx.data that are valid
  bool finished = false;      // no more will come
};
// Like decode_ascii_body, but parses while ctx.data is being filled: `wait(n)` blocks until at
// least n bytes are valid or the producer has finished. ctx.data spans the whole buffer; only
// valid bytes are read.
void decode_ascii_stream(const BodyContext& ctx, std::vector<Triangle>& triangles,
                         const std::function<StreamState(std::size_t)>& wait);

// Parses the element lines in [begin, end) (whole lines, inside ctx.data), the first being
// element line `first` of ctx.header's body; returns how many it parsed. Throws as
// decode_ascii_body. For windows of a streamed file (ctx.line_base numbers their lines).
std::uint64_t parse_ascii_lines(const BodyContext& ctx, const char* begin, const char* end,
                                std::uint64_t first, std::vector<Triangle>* triangles = nullptr);

// Throws FormatError when an element count cannot fit in the bytes after the header, so callers
// can allocate for the counts safely. Names the exact place when it can (a binary body whose
// earlier elements have fixed sizes; an ascii body with too few lines).
void check_counts_fit(const BodyContext& ctx);

// For check_counts_fit: the exact truncation message for fixed-size element `element` starting
// at byte `start` of a binary body, and for an ascii body that has only `lines` element lines.
[[noreturn]] void fail_binary_truncated(const BodyContext& ctx, std::size_t element,
                                        std::size_t start);
[[noreturn]] void fail_ascii_ends_early(const BodyContext& ctx, std::uint64_t lines);
// Lines holding anything besides blanks (space, tab, CR), in [begin, end).
std::uint64_t count_element_lines(const char* begin, const char* end);

// Shared helpers --------------------------------------------------------------------------

inline std::uint8_t to_color(float v, ColorScale scale) {
  if (scale == ColorScale::Unit)
    v *= 255.0f;
  else if (scale == ColorScale::Word)
    v *= 255.0f / 65535.0f;
  if (!(v > 0.0f)) return 0;  // also NaN
  if (v >= 255.0f) return 255;
  return static_cast<std::uint8_t>(v + 0.5f);
}

inline void store_vertex(const VertexOutput& out, std::size_t i, const float* v) {
  out.positions[i] = {v[kX], v[kY], v[kZ]};
  if (out.normals) out.normals[i] = {v[kNx], v[kNy], v[kNz]};
  if (out.colors)
    out.colors[i] = {to_color(v[kRed], out.color_scale[0]), to_color(v[kGreen], out.color_scale[1]),
                     to_color(v[kBlue], out.color_scale[2])};
  if (out.radii) out.radii[i] = v[kRadius];
}

// Targets whose values must be finite (a NaN position poisons every bounding box downstream).
constexpr bool must_be_finite(Target t) { return t == kX || t == kY || t == kZ || t == kRadius; }

// Appends the fan (v0, v_k, v_k+1) of a polygon; called once per polygon vertex.
struct FanBuilder {
  std::uint32_t first = 0, previous = 0;
  std::int64_t seen = 0;

  void add(std::uint32_t index, std::vector<Triangle>& triangles) {
    if (seen == 0)
      first = index;
    else if (seen >= 2)
      triangles.push_back({first, previous, index});
    previous = index;
    ++seen;
  }
};

}  // namespace pointillist::ply

namespace pointillist::io_detail {

class FileWindow;

// The faces of element `face` of a binary PLY file as a stream (ply_face_stream.cpp); `plan` is
// the element's plan, `vertex_count` the vertex element's count; windows of at most
// `window_bytes` (more only for a face larger than that).
std::unique_ptr<FaceStream> make_ply_face_stream(std::unique_ptr<FileWindow> file,
                                                 const ply::Header& header, std::size_t face,
                                                 const ply::ElementPlan& plan,
                                                 std::uint64_t vertex_count,
                                                 std::size_t window_bytes);

// The vertex element of an ASCII PLY file (plain or gzip), `info` filled from its header, read
// a window of lines at a time (ply_ascii_stream.cpp). `scales`: the three colour scales.
// The face element `face` of an ASCII PLY file (plain or gzip) read a window of lines at a
// time, by the same parser (ply_ascii_stream.cpp).
std::unique_ptr<FaceStream> open_ascii_face_stream(const std::string& path,
                                                   const ply::Header& header, std::size_t face,
                                                   const ply::ElementPlan& plan,
                                                   std::uint64_t vertex_count);

std::unique_ptr<PointStream> open_ascii_vertex_stream(const std::string& path,
                                                      const ply::Header& header,
                                                      std::size_t vertex,
                                                      const ply::ElementPlan& plan,
                                                      const ply::ColorScale* scales,
                                                      PointStreamInfo info);

}  // namespace pointillist::io_detail
