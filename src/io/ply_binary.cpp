// Binary PLY body decoder. Fixed-size vertex records are decoded in blocks, one column (property)
// at a time through a function chosen once per column, so the inner loops are branch-free strided
// loads; the common face layout (uchar count, int indices) has its own loop; everything else goes
// through a generic per-property walker.
#include <algorithm>
#include <atomic>
#include <bit>
#include <cstring>

#include "ply_body.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/core/thread_pool.hpp"

namespace pointillist::ply {
namespace {

template <std::size_t N>
struct UintOf;
template <>
struct UintOf<1> {
  using type = std::uint8_t;
};
template <>
struct UintOf<2> {
  using type = std::uint16_t;
};
template <>
struct UintOf<4> {
  using type = std::uint32_t;
};
template <>
struct UintOf<8> {
  using type = std::uint64_t;
};

template <class T, bool Swap>
inline T load(const unsigned char* p) {
  using U = typename UintOf<sizeof(T)>::type;
  U u;
  std::memcpy(&u, p, sizeof(U));
  if constexpr (Swap && sizeof(U) == 2) u = __builtin_bswap16(u);
  if constexpr (Swap && sizeof(U) == 4) u = __builtin_bswap32(u);
  if constexpr (Swap && sizeof(U) == 8) u = __builtin_bswap64(u);
  return std::bit_cast<T>(u);
}

template <class F>
decltype(auto) with_type(ScalarType type, F&& f) {
  switch (type) {
    case ScalarType::Int8:
      return f(std::int8_t{});
    case ScalarType::Uint8:
      return f(std::uint8_t{});
    case ScalarType::Int16:
      return f(std::int16_t{});
    case ScalarType::Uint16:
      return f(std::uint16_t{});
    case ScalarType::Int32:
      return f(std::int32_t{});
    case ScalarType::Uint32:
      return f(std::uint32_t{});
    case ScalarType::Float32:
      return f(float{});
    case ScalarType::Float64:
      break;
  }
  return f(double{});
}

double load_value(ScalarType type, const unsigned char* p, bool swap) {
  return with_type(type, [&](auto tag) -> double {
    using T = decltype(tag);
    return swap ? static_cast<double>(load<T, true>(p)) : static_cast<double>(load<T, false>(p));
  });
}


using ColumnFn = void (*)(const unsigned char* src, std::size_t stride, std::size_t n, float* out);

template <class T, bool Swap>
void decode_column(const unsigned char* src, std::size_t stride, std::size_t n, float* out) {
  for (std::size_t i = 0; i < n; ++i) out[i] = static_cast<float>(load<T, Swap>(src + i * stride));
}

ColumnFn column_fn(ScalarType type, bool swap) {
  return with_type(type, [&](auto tag) -> ColumnFn {
    using T = decltype(tag);
    return swap ? &decode_column<T, true> : &decode_column<T, false>;
  });
}

// x - x is 0 exactly for finite x and NaN for NaN or infinity; this form vectorizes.
inline bool finite_bits(float x) { return x - x == 0.0f; }

// NaN and infinity are the floats whose exponent bits are all ones; testing the bits as
// integers vectorizes, unlike floating-point comparisons with NaN semantics.
bool all_finite(const float* values, std::size_t count) {
  std::uint32_t bad = 0;
  for (std::size_t i = 0; i < count; ++i) {
    std::uint32_t u;
    std::memcpy(&u, values + i, 4);
    bad |= static_cast<std::uint32_t>((u & 0x7f800000u) == 0x7f800000u);
  }
  return bad == 0;
}

class BinaryDecoder {
 public:
  BinaryDecoder(const BodyContext& ctx, std::vector<Triangle>& triangles)
      : ctx_(ctx),
        header_(*ctx.header),
        triangles_(triangles),
        swap_((header_.format == Format::BinaryBigEndian) !=
              (std::endian::native == std::endian::big)),
        data_(reinterpret_cast<const unsigned char*>(ctx.data.data())),
        size_(ctx.data.size()) {}

  void run() {
    std::size_t pos = header_.body_offset;
    for (std::size_t e = 0; e < header_.elements.size(); ++e) {
      const Element& element = header_.elements[e];
      const ElementPlan& plan = ctx_.plans[e];
      if (element.count == 0) continue;
      if (!element.has_lists()) {
        check_fixed_fits(e, pos);
        const std::size_t bytes = element.count * element.fixed_size();
        if (plan.kind == ElementPlan::Kind::Vertex)
          decode_fixed_vertices(e, pos);
        else
          report(bytes);
        pos += bytes;
      } else if (plan.kind == ElementPlan::Kind::Face && is_simple_face(element)) {
        pos = decode_simple_faces(e, pos);
      } else {
        pos = walk_generic(e, pos);
      }
    }
  }

 private:
  void report(std::size_t bytes) const {
    if (ctx_.on_bytes && bytes > 0) ctx_.on_bytes(bytes);
  }

  [[noreturn]] void fail_ends_early(std::size_t e, std::uint64_t index, std::size_t p,
                                    std::size_t offset, std::size_t needed) const {
    ctx_.fail_at_byte(offset, ctx_.instance(e, index) + ": file ends early (" +
                                  ctx_.property(e, p) + " needs " + std::to_string(needed) +
                                  " bytes, " + std::to_string(size_ - std::min(offset, size_)) +
                                  " remain)");
  }

  void check_fixed_fits(std::size_t e, std::size_t pos) const {
    const Element& element = header_.elements[e];
    const std::size_t stride = element.fixed_size();
    if (stride != 0 && element.count > (size_ - pos) / stride) fail_binary_truncated(ctx_, e, pos);
  }

  // Targets [first, first + count) form a run of `type` values at consecutive offsets, so one
  // memcpy per vertex fills the output (a float x y z or uchar red green blue layout).
  bool is_direct_run(const ScalarType* types, const std::size_t* offsets, Target first, int count,
                     ScalarType type) const {
    if (swap_) return false;
    for (int k = 0; k < count; ++k) {
      if (types[first + k] != type || offsets[first + k] != offsets[first] + k * scalar_size(type))
        return false;
    }
    return true;
  }

  void decode_fixed_vertices(std::size_t e, std::size_t pos) {
    const Element& element = header_.elements[e];
    const ElementPlan& plan = ctx_.plans[e];
    const std::size_t stride = element.fixed_size();
    constexpr std::size_t kBlock = 1024;
    const VertexOutput& out = ctx_.vertex;

    ScalarType types[kTargetCount] = {};
    std::size_t offsets[kTargetCount] = {};
    std::size_t property_of[kTargetCount] = {};
    bool present[kTargetCount] = {};
    std::size_t offset = 0;
    for (std::size_t p = 0; p < element.properties.size(); ++p) {
      const Target t = plan.properties[p].target;
      if (t != kNoTarget) {
        types[t] = element.properties[p].type;
        offsets[t] = offset;
        property_of[t] = p;
        present[t] = true;
      }
      offset += scalar_size(element.properties[p].type);
    }
    const bool direct_positions = is_direct_run(types, offsets, kX, 3, ScalarType::Float32);
    const bool direct_normals =
        out.normals && is_direct_run(types, offsets, kNx, 3, ScalarType::Float32);
    const bool direct_colors =
        out.colors && is_direct_run(types, offsets, kRed, 3, ScalarType::Uint8);
    const bool direct_radii =
        out.radii && is_direct_run(types, offsets, kRadius, 1, ScalarType::Float32);
    // The other targets go through float columns, one decoding function per column.
    ColumnFn fns[kTargetCount] = {};
    for (int t = 0; t < kTargetCount; ++t) {
      const bool direct =
          (t <= kZ && direct_positions) || (t >= kNx && t <= kNz && direct_normals) ||
          (t >= kRed && t <= kBlue && direct_colors) || (t == kRadius && direct_radii);
      if (present[t] && !direct) fns[t] = column_fn(types[t], swap_);
    }
    std::vector<float> columns(kTargetCount * kBlock, 0.0f);
    float* col[kTargetCount];
    for (int t = 0; t < kTargetCount; ++t) col[t] = columns.data() + t * kBlock;

    for (std::uint64_t first = 0; first < element.count; first += kBlock) {
      const std::size_t n =
          static_cast<std::size_t>(std::min<std::uint64_t>(kBlock, element.count - first));
      const unsigned char* base = data_ + pos + first * stride;
      for (int t = 0; t < kTargetCount; ++t)
        if (fns[t]) fns[t](base + offsets[t], stride, n, col[t]);

      Vec3f* positions = out.positions + first;
      if (direct_positions) {
        for (std::size_t i = 0; i < n; ++i)
          std::memcpy(&positions[i], base + i * stride + offsets[kX], 12);
      } else {
        for (std::size_t i = 0; i < n; ++i) positions[i] = {col[kX][i], col[kY][i], col[kZ][i]};
      }
      if (out.normals) {
        Vec3f* normals = out.normals + first;
        if (direct_normals) {
          for (std::size_t i = 0; i < n; ++i)
            std::memcpy(&normals[i], base + i * stride + offsets[kNx], 12);
        } else {
          for (std::size_t i = 0; i < n; ++i) normals[i] = {col[kNx][i], col[kNy][i], col[kNz][i]};
        }
      }
      if (out.colors) {
        Rgb8* colors = out.colors + first;
        if (direct_colors) {
          for (std::size_t i = 0; i < n; ++i)
            std::memcpy(&colors[i], base + i * stride + offsets[kRed], 3);
        } else {
          for (std::size_t i = 0; i < n; ++i)
            colors[i] = {to_color(col[kRed][i], out.color_scale[0]),
                         to_color(col[kGreen][i], out.color_scale[1]),
                         to_color(col[kBlue][i], out.color_scale[2])};
        }
      }
      if (out.radii) {
        float* radii = out.radii + first;
        if (direct_radii) {
          for (std::size_t i = 0; i < n; ++i)
            std::memcpy(&radii[i], base + i * stride + offsets[kRadius], 4);
        } else {
          std::copy_n(col[kRadius], n, radii);
        }
      }

      bool finite = all_finite(reinterpret_cast<const float*>(positions), 3 * n);
      if (out.radii) finite &= all_finite(out.radii + first, n);
      if (!finite) fail_not_finite(e, pos, first, n, offsets, property_of);
      report(n * stride);
    }
  }

  [[noreturn]] void fail_not_finite(std::size_t e, std::size_t pos, std::uint64_t first,
                                    std::size_t n, const std::size_t* offsets,
                                    const std::size_t* property_of) const {
    const std::size_t stride = header_.elements[e].fixed_size();
    const VertexOutput& out = ctx_.vertex;
    for (std::size_t i = first; i < first + n; ++i) {
      for (Target t : {kX, kY, kZ, kRadius}) {
        if (t == kRadius && !out.radii) continue;
        const float v = t == kRadius ? out.radii[i] : out.positions[i][t - kX];
        if (!finite_bits(v))
          ctx_.fail_at_byte(pos + i * stride + offsets[t],
                            ctx_.instance(e, i) + ": " + ctx_.property(e, property_of[t]) +
                                " is not a finite number (found " + std::to_string(v) + ")");
      }
    }
    ctx_.fail_at_byte(pos, "non-finite value");  // not reached
  }

  bool is_simple_face(const Element& element) const {
    return element.properties.size() == 1 &&
           ctx_.plans[&element - header_.elements.data()].properties[0].is_face_indices;
  }

  [[noreturn]] void fail_bad_index(std::size_t e, std::uint64_t face, std::size_t offset,
                                   std::int64_t index) const {
    ctx_.fail_at_byte(offset, ctx_.instance(e, face) + ": " + ctx_.property(e, 0) +
                                  ": vertex index " + std::to_string(index) +
                                  " out of range (expected 0 to " +
                                  std::to_string(ctx_.vertex_count) + " - 1)");
  }

  // Defined before decode_simple_faces, which calls it from a generic lambda: clang 14 does not
  // instantiate a member template that such a lambda uses before the template's definition
  // (undefined internal symbols at link time).
  // The common case in parallel: every face a triangle with indices in range, so the records
  // have one size and any piece can be decoded on its own. False (nothing kept) when some
  // record says otherwise; the serial loop then decodes all and names the first bad one.
  template <class C, class I, bool Swap>
  bool decode_triangles_in_parallel(std::size_t e, std::size_t pos, std::size_t used) {
    constexpr std::size_t kRecord = sizeof(C) + 3 * sizeof(I);
    constexpr std::uint64_t kMinFaces = 1 << 18, kPiece = 1 << 16;
    const std::uint64_t count = header_.elements[e].count;
    if (!ctx_.pool || ctx_.pool->thread_count() < 2 || count < kMinFaces ||
        count > (size_ - pos) / kRecord) {
      return false;
    }
    const std::uint64_t vertex_count = ctx_.vertex_count;
    std::atomic<bool> simple{true};
    ctx_.pool->run(static_cast<std::size_t>((count + kPiece - 1) / kPiece), [&](std::size_t k) {
      const std::uint64_t first = k * kPiece, last = std::min(count, first + kPiece);
      const unsigned char* r = data_ + pos + first * kRecord;
      for (std::uint64_t f = first; f < last && simple.load(std::memory_order_relaxed);
           ++f, r += kRecord) {
        const auto a = static_cast<std::int64_t>(load<I, Swap>(r + sizeof(C)));
        const auto b = static_cast<std::int64_t>(load<I, Swap>(r + sizeof(C) + sizeof(I)));
        const auto c = static_cast<std::int64_t>(load<I, Swap>(r + sizeof(C) + 2 * sizeof(I)));
        if (static_cast<std::int64_t>(load<C, Swap>(r)) != 3 ||
            static_cast<std::uint64_t>(a) >= vertex_count ||
            static_cast<std::uint64_t>(b) >= vertex_count ||
            static_cast<std::uint64_t>(c) >= vertex_count) {
          simple.store(false, std::memory_order_relaxed);
          return;
        }
        triangles_[used + f] = {static_cast<std::uint32_t>(a), static_cast<std::uint32_t>(b),
                                static_cast<std::uint32_t>(c)};
      }
    });
    if (!simple.load()) return false;
    report(count * kRecord);
    return true;
  }

  template <class C, class I, bool Swap>
  std::size_t decode_faces(std::size_t e, std::size_t pos) {
    const std::uint64_t count = header_.elements[e].count;
    const std::uint64_t vertex_count = ctx_.vertex_count;
    std::size_t p = pos, reported = pos;
    // Most faces are triangles: size for that, grow when polygons need more.
    std::size_t used = triangles_.size();
    triangles_.resize(used + count);
    if (decode_triangles_in_parallel<C, I, Swap>(e, pos, used)) {
      return pos + count * (sizeof(C) + 3 * sizeof(I));
    }
    for (std::uint64_t f = 0; f < count; ++f) {
      if (size_ - p < sizeof(C)) fail_ends_early(e, f, 0, p, sizeof(C));
      const std::int64_t n = static_cast<std::int64_t>(load<C, Swap>(data_ + p));
      if (n < 0)
        ctx_.fail_at_byte(p, ctx_.instance(e, f) + ": " + ctx_.property(e, 0) +
                                 ": negative count " + std::to_string(n));
      p += sizeof(C);
      if (static_cast<std::uint64_t>(n) > (size_ - p) / sizeof(I))
        fail_ends_early(e, f, 0, p, static_cast<std::size_t>(n) * sizeof(I));
      for (std::int64_t k = 0; k < n; ++k) {
        const std::int64_t index =
            static_cast<std::int64_t>(load<I, Swap>(data_ + p + k * sizeof(I)));
        if (static_cast<std::uint64_t>(index) >= vertex_count)
          fail_bad_index(e, f, p + k * sizeof(I), index);
      }
      if (n >= 3) {
        if (used + static_cast<std::size_t>(n - 2) > triangles_.size())
          triangles_.resize(
              std::max(triangles_.size() * 2, used + static_cast<std::size_t>(n - 2)));
        const auto v0 = static_cast<std::uint32_t>(load<I, Swap>(data_ + p));
        auto previous = static_cast<std::uint32_t>(load<I, Swap>(data_ + p + sizeof(I)));
        for (std::int64_t k = 2; k < n; ++k) {
          const auto v = static_cast<std::uint32_t>(load<I, Swap>(data_ + p + k * sizeof(I)));
          triangles_[used++] = {v0, previous, v};
          previous = v;
        }
      }
      p += static_cast<std::size_t>(n) * sizeof(I);
      if ((f & 0xffff) == 0xffff) {
        report(p - reported);
        reported = p;
      }
    }
    triangles_.resize(used);
    report(p - reported);
    return p;
  }

  std::size_t decode_simple_faces(std::size_t e, std::size_t pos) {
    const Property& property = header_.elements[e].properties[0];
    return with_type(property.count_type, [&](auto count_tag) {
      return with_type(property.type, [&](auto index_tag) -> std::size_t {
        using C = decltype(count_tag);
        using I = decltype(index_tag);
        if constexpr (std::is_integral_v<C> && std::is_integral_v<I>) {
          return swap_ ? decode_faces<C, I, true>(e, pos) : decode_faces<C, I, false>(e, pos);
        } else {
          return walk_generic(e, pos);  // excluded by the plan; keeps the template well-formed
        }
      });
    });
  }

  // Any element, any layout: property by property, with a bounds check before every read.
  std::size_t walk_generic(std::size_t e, std::size_t pos) {
    const Element& element = header_.elements[e];
    const ElementPlan& plan = ctx_.plans[e];
    const bool is_vertex = plan.kind == ElementPlan::Kind::Vertex;
    std::size_t p = pos, reported = pos;
    float values[kTargetCount] = {};
    for (std::uint64_t i = 0; i < element.count; ++i) {
      for (std::size_t j = 0; j < element.properties.size(); ++j) {
        const Property& property = element.properties[j];
        const PropertyPlan& target = plan.properties[j];
        if (!property.is_list) {
          const std::size_t size = scalar_size(property.type);
          if (size_ - p < size) fail_ends_early(e, i, j, p, size);
          if (target.target != kNoTarget) {
            const float v = static_cast<float>(load_value(property.type, data_ + p, swap_));
            if (must_be_finite(target.target) && !finite_bits(v))
              ctx_.fail_at_byte(p, ctx_.instance(e, i) + ": " + ctx_.property(e, j) +
                                       " is not a finite number (found " + std::to_string(v) + ")");
            values[target.target] = v;
          }
          p += size;
          continue;
        }
        const std::size_t count_size = scalar_size(property.count_type);
        if (size_ - p < count_size) fail_ends_early(e, i, j, p, count_size);
        const std::int64_t n = load_integer(property.count_type, data_ + p, swap_);
        if (n < 0)
          ctx_.fail_at_byte(p, ctx_.instance(e, i) + ": " + ctx_.property(e, j) +
                                   ": negative count " + std::to_string(n));
        p += count_size;
        const std::size_t item = scalar_size(property.type);
        if (static_cast<std::uint64_t>(n) > (size_ - p) / item)
          fail_ends_early(e, i, j, p, static_cast<std::size_t>(n) * item);
        if (target.is_face_indices) {
          FanBuilder fan;
          for (std::int64_t k = 0; k < n; ++k) {
            const std::int64_t index = load_integer(property.type, data_ + p + k * item, swap_);
            if (static_cast<std::uint64_t>(index) >= ctx_.vertex_count)
              ctx_.fail_at_byte(p + k * item, ctx_.instance(e, i) + ": " + ctx_.property(e, j) +
                                                  ": vertex index " + std::to_string(index) +
                                                  " out of range (expected 0 to " +
                                                  std::to_string(ctx_.vertex_count) + " - 1)");
            fan.add(static_cast<std::uint32_t>(index), triangles_);
          }
        }
        p += static_cast<std::size_t>(n) * item;
      }
      if (is_vertex) store_vertex(ctx_.vertex, static_cast<std::size_t>(i), values);
      if ((i & 0xffff) == 0xffff) {
        report(p - reported);
        reported = p;
      }
    }
    report(p - reported);
    return p;
  }

  const BodyContext& ctx_;
  const Header& header_;
  std::vector<Triangle>& triangles_;
  const bool swap_;
  const unsigned char* data_;
  const std::size_t size_;
};

}  // namespace

void fail_binary_truncated(const BodyContext& ctx, std::size_t e, std::size_t start) {
  const Element& element = ctx.header->elements[e];
  const std::size_t stride = element.fixed_size();
  const std::size_t available = ctx.data.size() - start;
  const std::uint64_t index = available / stride;
  const std::size_t within = available % stride;
  std::size_t offset = 0;
  for (std::size_t p = 0; p < element.properties.size(); ++p) {
    const std::size_t size = scalar_size(element.properties[p].type);
    if (within < offset + size) {
      const std::size_t at = start + index * stride + offset;
      ctx.fail_at_byte(at, ctx.instance(e, index) + ": file ends early (" + ctx.property(e, p) +
                               " needs " + std::to_string(size) + " bytes, " +
                               std::to_string(ctx.data.size() - at) + " remain)");
    }
    offset += size;
  }
  ctx.fail_at_byte(ctx.data.size(), ctx.instance(e, index) + ": file ends early");  // not reached
}

std::int64_t load_integer(ScalarType type, const unsigned char* p, bool swap) {
  return with_type(type, [&](auto tag) -> std::int64_t {
    using T = decltype(tag);
    return swap ? static_cast<std::int64_t>(load<T, true>(p))
                : static_cast<std::int64_t>(load<T, false>(p));
  });
}

void decode_binary_body(const BodyContext& ctx, std::vector<Triangle>& triangles) {
  BinaryDecoder(ctx, triangles).run();
}

}  // namespace pointillist::ply
