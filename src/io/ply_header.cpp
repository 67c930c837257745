// PLY 1.0 header parser (Greg Turk, "The PLY Polygon File Format", 1994).
#include "ply_header.hpp"

#include <charconv>
#include <limits>
#include <string>
#include <unordered_set>

#include "pointillist/core/error.hpp"

namespace pointillist::ply {
namespace {

struct TypeName {
  std::string_view name;
  ScalarType type;
};

// Both the original spellings and the sized ones used by newer writers.
constexpr TypeName kTypeNames[] = {
    {"char", ScalarType::Int8},       {"uchar", ScalarType::Uint8},
    {"short", ScalarType::Int16},     {"ushort", ScalarType::Uint16},
    {"int", ScalarType::Int32},       {"uint", ScalarType::Uint32},
    {"float", ScalarType::Float32},   {"double", ScalarType::Float64},
    {"int8", ScalarType::Int8},       {"uint8", ScalarType::Uint8},
    {"int16", ScalarType::Int16},     {"uint16", ScalarType::Uint16},
    {"int32", ScalarType::Int32},     {"uint32", ScalarType::Uint32},
    {"float32", ScalarType::Float32}, {"float64", ScalarType::Float64}};

bool parse_type(std::string_view word, ScalarType& type) {
  for (const TypeName& t : kTypeNames) {
    if (t.name == word) {
      type = t.type;
      return true;
    }
  }
  return false;
}

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

std::vector<std::string_view> split_words(std::string_view line) {
  std::vector<std::string_view> words;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && is_space(line[i])) ++i;
    const std::size_t start = i;
    while (i < line.size() && !is_space(line[i])) ++i;
    if (i > start) words.push_back(line.substr(start, i - start));
  }
  return words;
}

// Text of a comment line after the keyword and one separator.
std::string comment_text(std::string_view line, std::string_view keyword) {
  std::string_view rest =
      line.substr(static_cast<std::size_t>(keyword.data() - line.data()) + keyword.size());
  if (!rest.empty() && (rest[0] == ' ' || rest[0] == '\t')) rest.remove_prefix(1);
  return std::string(rest);
}

std::string quoted(std::string_view s) {
  constexpr std::size_t kMax = 40;
  std::string out = "'";
  for (char c : s.substr(0, kMax))
    out += (static_cast<unsigned char>(c) < 32 || c == 127) ? '?' : c;
  if (s.size() > kMax) out += "...";
  return out + "'";
}

class HeaderParser {
 public:
  HeaderParser(std::string_view data, const std::string& path) : data_(data), path_(path) {}

  Header parse() {
    std::string_view line;
    if (!next_line(line) || trim_cr(line) != "ply") {
      if (data_.empty()) fail(1, "file is empty (expected a PLY header starting with 'ply')");
      fail(1, "not a PLY file: expected 'ply' on the first line, found " +
                  quoted(data_.substr(0, std::min<std::size_t>(data_.size(), 16))));
    }
    bool have_format = false;
    for (;;) {
      if (!next_line(line))
        fail(line_, "header has no end_header line (file ends after " + std::to_string(line_) +
                        " header lines)");
      const auto words = split_words(line);
      if (words.empty()) continue;  // tolerate blank header lines
      const std::string_view keyword = words[0];
      if (keyword == "end_header") {
        if (words.size() != 1) fail(line_, "unexpected text after end_header");
        break;
      }
      if (keyword == "comment") {
        header_.comments.push_back(comment_text(trim_cr(line), keyword));
      } else if (keyword == "obj_info") {
        // Free-form metadata; nothing in a PointSet to put it in.
      } else if (keyword == "format") {
        parse_format(words);
        have_format = true;
      } else if (keyword == "element") {
        if (!have_format)
          fail(line_, "element before the format line (expected 'format ...' first)");
        parse_element(words);
      } else if (keyword == "property") {
        parse_property(words);
      } else {
        fail(line_, "unknown header keyword " + quoted(keyword) +
                        " (expected comment, obj_info, format, element, property or end_header)");
      }
    }
    if (!have_format)
      fail(line_, "header has no format line (expected 'format ascii 1.0' or a binary format)");
    header_.body_offset = pos_;
    header_.line_count = line_;
    return std::move(header_);
  }

 private:
  static std::string_view trim_cr(std::string_view s) {
    while (!s.empty() && (s.back() == '\r' || s.back() == ' ' || s.back() == '\t'))
      s.remove_suffix(1);
    return s;
  }

  bool next_line(std::string_view& line) {
    if (pos_ >= data_.size()) return false;
    const std::size_t end = data_.find('\n', pos_);
    if (end == std::string_view::npos) {
      line = data_.substr(pos_);
      pos_ = data_.size();
      ++line_;
      return false;  // a header line must end with a newline
    }
    line = data_.substr(pos_, end - pos_);
    pos_ = end + 1;
    ++line_;
    return true;
  }

  [[noreturn]] void fail(std::size_t line, const std::string& what) const {
    throw FormatError(path_ + ": line " + std::to_string(line) + ": " + what);
  }

  void parse_format(const std::vector<std::string_view>& words) {
    if (words.size() != 3)
      fail(line_,
           "bad format line: expected 'format <ascii|binary_little_endian|binary_big_endian> 1.0'");
    if (words[1] == "ascii")
      header_.format = Format::Ascii;
    else if (words[1] == "binary_little_endian")
      header_.format = Format::BinaryLittleEndian;
    else if (words[1] == "binary_big_endian")
      header_.format = Format::BinaryBigEndian;
    else
      fail(line_, "unknown format " + quoted(words[1]) +
                      " (expected ascii, binary_little_endian or binary_big_endian)");
    if (words[2] != "1.0" && words[2] != "1")
      fail(line_, "unsupported PLY version " + quoted(words[2]) + " (expected 1.0)");
  }

  void parse_element(const std::vector<std::string_view>& words) {
    if (words.size() != 3) fail(line_, "bad element line: expected 'element <name> <count>'");
    Element element;
    element.name = std::string(words[1]);
    element.header_line = line_;
    const std::string_view count = words[2];
    const auto [end, ec] =
        std::from_chars(count.data(), count.data() + count.size(), element.count);
    if (ec != std::errc() || end != count.data() + count.size())
      fail(line_, "element " + element.name + ": count " + quoted(count) +
                      " is not a non-negative integer");
    if (element.name == "vertex" || element.name == "face") {
      std::size_t& first = element.name == "vertex" ? vertex_line_ : face_line_;
      if (first != 0)
        fail(line_, "second '" + element.name + "' element (the first is on line " +
                        std::to_string(first) + ")");
      first = line_;
    }
    if (header_.elements.size() == kMaxElements)
      fail(line_, "more than " + std::to_string(kMaxElements) +
                      " elements declared; no real PLY file has that many (the header is "
                      "corrupt or hostile)");
    header_.elements.push_back(std::move(element));
    property_names_.clear();
  }

  void parse_property(const std::vector<std::string_view>& words) {
    if (header_.elements.empty()) fail(line_, "property before any element line");
    Element& element = header_.elements.back();
    Property property;
    property.header_line = line_;
    if (words.size() >= 2 && words[1] == "list") {
      if (words.size() != 5)
        fail(line_,
             "element " + element.name +
                 ": bad list property: expected 'property list <count type> <item type> <name>'");
      if (!parse_type(words[2], property.count_type))
        fail(line_, "element " + element.name + ": unknown list count type " + quoted(words[2]));
      if (!is_integer(property.count_type))
        fail(line_, "element " + element.name +
                        ": list count type must be an integer type, found " + quoted(words[2]));
      if (!parse_type(words[3], property.type))
        fail(line_, "element " + element.name + ": unknown list item type " + quoted(words[3]));
      property.is_list = true;
      property.name = std::string(words[4]);
    } else {
      if (words.size() != 3)
        fail(line_,
             "element " + element.name + ": bad property line: expected 'property <type> <name>'");
      if (!parse_type(words[1], property.type))
        fail(line_,
             "element " + element.name + ": unknown property type " + quoted(words[1]) +
                 " (expected char uchar short ushort int uint float double or int8 ... float64)");
      property.name = std::string(words[2]);
    }
    if (!property_names_.insert(property.name).second)
      fail(line_, "element " + element.name + ": property " + property.name + " declared twice");
    if (element.properties.size() == kMaxProperties)
      fail(line_, "element " + element.name + ": more than " + std::to_string(kMaxProperties) +
                      " properties declared; no real PLY file has that many (the header is "
                      "corrupt or hostile)");
    element.properties.push_back(std::move(property));
  }

  // Limits no real file reaches; they keep a hostile header from costing minutes.
  static constexpr std::size_t kMaxElements = 1024, kMaxProperties = 4096;

  std::string_view data_;
  const std::string& path_;
  std::size_t pos_ = 0;
  std::size_t line_ = 0;
  std::size_t vertex_line_ = 0, face_line_ = 0;  // where those elements were declared
  std::unordered_set<std::string> property_names_;  // of the last element: duplicates in O(1)
  Header header_;
};

}  // namespace

const char* scalar_name(ScalarType type) {
  constexpr const char* kNames[kScalarTypeCount] = {"char", "uchar", "short", "ushort",
                                                    "int",  "uint",  "float", "double"};
  return kNames[static_cast<int>(type)];
}

bool Element::has_lists() const {
  for (const Property& p : properties)
    if (p.is_list) return true;
  return false;
}

std::size_t Element::fixed_size() const {
  std::size_t size = 0;
  for (const Property& p : properties) size += scalar_size(p.type);
  return size;
}

std::size_t Element::min_size(Format format) const {
  if (format == Format::Ascii) return 2 * properties.size();  // a digit and a separator per value
  std::size_t size = 0;
  for (const Property& p : properties) size += scalar_size(p.is_list ? p.count_type : p.type);
  return size;
}

std::uint64_t Header::max_file_bytes() const {
  constexpr std::uint64_t kMax = std::numeric_limits<std::uint64_t>::max();
  const auto add = [](std::uint64_t a, std::uint64_t b) { return a > kMax - b ? kMax : a + b; };
  const auto mul = [](std::uint64_t a, std::uint64_t b) {
    return a != 0 && b > kMax / a ? kMax : a * b;
  };
  const auto largest_count = [](ScalarType t) -> std::uint64_t {
    const std::size_t bytes = scalar_size(t);
    return bytes >= 4 ? std::uint64_t{0xffffffff} : (std::uint64_t{1} << (8 * bytes)) - 1;
  };
  const bool ascii = format == Format::Ascii;
  std::uint64_t total = body_offset;
  for (const Element& e : elements) {
    std::uint64_t per = ascii ? 2 : 0;  // a line end (CR LF)
    for (const Property& p : e.properties) {
      const std::uint64_t value = ascii ? kMaxAsciiValueBytes : scalar_size(p.type);
      const std::uint64_t count = ascii ? kMaxAsciiValueBytes : scalar_size(p.count_type);
      per = add(per, p.is_list ? add(count, mul(largest_count(p.count_type), value)) : value);
    }
    total = add(total, mul(e.count, per));
  }
  return total;
}

int Element::find(std::string_view property_name) const {
  for (std::size_t i = 0; i < properties.size(); ++i)
    if (properties[i].name == property_name) return static_cast<int>(i);
  return -1;
}

Header parse_header(std::string_view data, const std::string& path) {
  return HeaderParser(data, path).parse();
}

}  // namespace pointillist::ply
