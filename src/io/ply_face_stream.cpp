// The faces of a binary PLY file read a window at a time (point_stream.hpp, FaceStream). Face
// records have variable sizes, so each window is first walked record by record to find the
// whole faces it holds; those are then decoded by the body decoder (ply_binary.cpp), which
// checks them and fan-triangulates them exactly as reading the whole file does.
#include <algorithm>
#include <bit>
#include <limits>

#include "file_window.hpp"
#include "ply_body.hpp"
#include "streams.hpp"
#include "pointillist/core/error.hpp"

namespace pointillist::io_detail {
namespace {

using namespace ply;

// A window larger than this that still holds no whole face means a face of more than about
// 50 million indices: refused rather than read.
constexpr std::size_t kMaxFaceWindowBytes = std::size_t{256} << 20;

// The whole records of an element at the start of a window: their bytes and count. A record
// whose list count is negative ends the walk and is counted with the bytes up to its count (the
// decoder names it); `cut`: the next record runs past the window.
struct Walk {
  std::size_t bytes = 0;
  std::uint64_t records = 0;
  bool negative = false, cut = false;
};

Walk whole_records(const Element& element, const unsigned char* data, std::size_t size,
                   std::uint64_t most, bool swap) {
  Walk w;
  while (w.records < most) {
    std::size_t q = w.bytes;
    for (const Property& property : element.properties) {
      const std::size_t count_size = property.is_list ? scalar_size(property.count_type) : 0;
      const std::size_t item = scalar_size(property.type);
      if (!property.is_list) {
        q += item;
        continue;
      }
      if (size - std::min(q, size) < count_size) {
        w.cut = true;
        return w;
      }
      const std::int64_t n = load_integer(property.count_type, data + q, swap);
      q += count_size;
      if (n < 0) {
        w.negative = true;
        w.bytes = q;
        ++w.records;
        return w;
      }
      if (static_cast<std::uint64_t>(n) > (size - std::min(q, size)) / item) {
        w.cut = true;
        return w;
      }
      q += static_cast<std::size_t>(n) * item;
    }
    if (q > size) {
      w.cut = true;
      return w;
    }
    w.bytes = q;
    ++w.records;
  }
  return w;
}

class PlyFaceStream final : public FaceStream {
 public:
  PlyFaceStream(std::unique_ptr<FileWindow> file, const Header& header, std::size_t face,
                const ElementPlan& plan, std::uint64_t vertex_count, std::size_t window_bytes)
      : file_(std::move(file)),
        window_bytes_(std::max<std::size_t>(window_bytes, 16)),
        swap_((header.format == Format::BinaryBigEndian) != (std::endian::native == std::endian::big)) {
    vertex_count_ = vertex_count;
    face_count_ = header.elements[face].count;
    window_header_.format = header.format;
    window_header_.elements = {header.elements[face]};
    window_header_.body_offset = 0;
    ctx_.path = file_->path();
    ctx_.header = &window_header_;
    ctx_.plans = {plan};
    ctx_.compressed = file_->compressed();
    ctx_.vertex_count = vertex_count;
    ctx_.index_total = face_count_;
    // Where the faces start: past the elements before them, walked when they hold lists.
    std::uint64_t at = header.body_offset;
    for (std::size_t e = 0; e < face; ++e) at = skip(header.elements[e], at);
    at_ = at;
  }

  bool read(std::vector<std::array<std::uint32_t, 3>>& triangles) override {
    triangles.clear();
    if (next_ == face_count_) return false;
    Element& element = window_header_.elements[0];
    const Walk w = window(element, at_, face_count_ - next_);
    // A file that ends inside a face: that face, with what remains of it, so the decoder
    // names the place.
    const std::uint64_t records = w.records > 0 ? w.records : 1;
    const std::size_t bytes = w.records > 0 ? w.bytes : buffer_.size();
    element.count = records;
    ctx_.data = {buffer_.data(), bytes};
    ctx_.byte_base = at_;
    ctx_.index_base = next_;
    decode_binary_body(ctx_, triangles);
    at_ += bytes;
    next_ += records;
    return true;
  }

  std::uint64_t faces_done() const override { return next_; }

 private:
  // Reads the window at `at` and walks its whole records of `element` (at most `most`); grows
  // the window while it holds not one whole record and the file goes on.
  Walk window(const Element& element, std::uint64_t at, std::uint64_t most) {
    // (a plain file's window stops at its end: a small file is not given a large buffer)
    std::size_t want = window_bytes_;
    if (!file_->compressed() && file_->size() > at) {
      want = static_cast<std::size_t>(std::min<std::uint64_t>(want, file_->size() - at));
    }
    for (;; want *= 4) {
      file_->read_some(at, want, buffer_);
      const auto* data = reinterpret_cast<const unsigned char*>(buffer_.data());
      const Walk w = whole_records(element, data, buffer_.size(), most, swap_);
      if (w.records > 0 || buffer_.size() < want) return w;
      if (want >= kMaxFaceWindowBytes) {
        throw FormatError(ctx_.path + ": byte " + std::to_string(at) + ": element " +
                          element.name + " " + std::to_string(next_) + " is larger than " +
                          std::to_string(kMaxFaceWindowBytes >> 20) +
                          " MB; the file is damaged, or write its faces as triangles");
      }
    }
  }

  // The offset past all records of `element` from `at`.
  std::uint64_t skip(const Element& element, std::uint64_t at) {
    if (!element.has_lists()) {
      const std::uint64_t stride = element.fixed_size();
      if (stride != 0 && element.count > (std::numeric_limits<std::uint64_t>::max() - at) / stride) {
        throw FormatError(ctx_.path + ": element " + element.name + " has " +
                          std::to_string(element.count) + " records of " + std::to_string(stride) +
                          " bytes, more than any file holds; the header is wrong");
      }
      return at + element.count * stride;
    }
    for (std::uint64_t done = 0; done < element.count;) {
      const Walk w = window(element, at, element.count - done);
      if (w.negative || w.records == 0) {
        throw FormatError(ctx_.path + ": byte " + std::to_string(at + w.bytes) + ": element " +
                          element.name + " " + std::to_string(done + w.records) + " of " +
                          std::to_string(element.count) +
                          (w.negative ? ": a list count is negative" : ": file ends early"));
      }
      at += w.bytes;
      done += w.records;
    }
    return at;
  }

  std::unique_ptr<FileWindow> file_;
  const std::size_t window_bytes_;
  const bool swap_;
  Header window_header_;
  BodyContext ctx_;
  std::vector<char> buffer_;
  std::uint64_t at_ = 0, next_ = 0;
};

}  // namespace

std::unique_ptr<FaceStream> make_ply_face_stream(std::unique_ptr<FileWindow> file,
                                                 const Header& header, std::size_t face,
                                                 const ElementPlan& plan,
                                                 std::uint64_t vertex_count,
                                                 std::size_t window_bytes) {
  return std::make_unique<PlyFaceStream>(std::move(file), header, face, plan, vertex_count,
                                         window_bytes);
}

}  // namespace pointillist::io_detail
