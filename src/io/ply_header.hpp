// PLY 1.0 header model and parser (private to the io module).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace pointillist::ply {

enum class ScalarType : std::uint8_t {
  Int8,
  Uint8,
  Int16,
  Uint16,
  Int32,
  Uint32,
  Float32,
  Float64
};

constexpr int kScalarTypeCount = 8;

constexpr std::size_t scalar_size(ScalarType type) {
  constexpr std::size_t kSizes[kScalarTypeCount] = {1, 1, 2, 2, 4, 4, 4, 8};
  return kSizes[static_cast<int>(type)];
}
constexpr bool is_integer(ScalarType type) {
  return type != ScalarType::Float32 && type != ScalarType::Float64;
}
// The PLY 1.0 spelling ("uchar", "float", ...), for messages.
const char* scalar_name(ScalarType type);

enum class Format { Ascii, BinaryLittleEndian, BinaryBigEndian };

struct Property {
  std::string name;
  ScalarType type = ScalarType::Float32;  // value type (item type for lists)
  bool is_list = false;
  ScalarType count_type = ScalarType::Uint8;  // lists only
  std::size_t header_line = 0;                // 1-based line of the `property` line
};

struct Element {
  std::string name;
  std::uint64_t count = 0;
  std::vector<Property> properties;
  std::size_t header_line = 0;

  bool has_lists() const;
  // Bytes per instance in binary files; meaningful only without lists.
  std::size_t fixed_size() const;
  // Fewest bytes one instance can take: binary (lists empty) or ascii (one digit + separator per
  // value).
  std::size_t min_size(Format format) const;
  // Index of the property named `name`, or -1.
  int find(std::string_view property_name) const;
};

struct Header {
  Format format = Format::Ascii;
  std::vector<Element> elements;
  std::vector<std::string> comments;  // text after "comment ", in file order
  std::size_t body_offset = 0;        // first byte after the end_header line
  std::size_t line_count = 0;         // lines in the header, end_header included

  // The most bytes a file with this header can hold (header and body; saturating at
  // UINT64_MAX): binary values at their size, lists at their count type's largest count, ascii
  // values at kMaxAsciiValueBytes each. A gzip file that inflates to more is refused early.
  std::uint64_t max_file_bytes() const;
  static constexpr std::uint64_t kMaxAsciiValueBytes = 64;
};

// Parses the header at the start of `data`. `path` is only used in messages. Element counts are
// not checked against the file size here (see check_counts_fit in ply_body.hpp).
// Throws FormatError naming the path and line.
Header parse_header(std::string_view data, const std::string& path);

}  // namespace pointillist::ply
