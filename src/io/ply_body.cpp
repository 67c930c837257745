// Shared pieces of the PLY body decoders: error messages and the count check.
#include "ply_body.hpp"

#include <algorithm>

#include "pointillist/core/error.hpp"

namespace pointillist::ply {

void BodyContext::fail_at_byte(std::size_t offset, const std::string& what) const {
  throw FormatError(path + ": byte " + std::to_string(byte_base + offset) +
                    (compressed ? " (decompressed)" : "") + ": " + what);
}

void BodyContext::fail_at_char(const char* pos, const std::string& what) const {
  const std::uint64_t line =
      line_base + 1 + static_cast<std::uint64_t>(std::count(data.data(), pos, '\n'));
  throw FormatError(path + ": line " + std::to_string(line) + ": " + what);
}

std::string BodyContext::instance(std::size_t element, std::uint64_t index) const {
  const Element& e = header->elements[element];
  return e.name + " " + std::to_string(index_base + index) + " of " +
         std::to_string(index_total != 0 ? index_total : e.count);
}

std::string BodyContext::property(std::size_t element, std::size_t property_index) const {
  const Property& p = header->elements[element].properties[property_index];
  return std::string(p.is_list ? "list property " : "property ") + p.name;
}

void check_counts_fit(const BodyContext& ctx) {
  const Header& header = *ctx.header;
  const bool ascii = header.format == Format::Ascii;
  // The last ascii line may lack its newline.
  const std::uint64_t available = ctx.data.size() - header.body_offset + (ascii ? 1 : 0);
  std::uint64_t needed = 0;
  bool exact = true;  // `needed` is the exact start of the element (binary, fixed sizes so far)
  for (std::size_t e = 0; e < header.elements.size(); ++e) {
    const Element& element = header.elements[e];
    const std::uint64_t size = element.min_size(header.format);
    const std::uint64_t remaining = available - needed;
    if (size != 0 && element.count > remaining / size) {
      if (!ascii && exact && !element.has_lists())
        fail_binary_truncated(ctx, e, static_cast<std::size_t>(header.body_offset + needed));
      if (ascii) {
        std::uint64_t total = 0;
        for (const Element& el : header.elements) total += el.properties.empty() ? 0 : el.count;
        const char* body = ctx.data.data() + header.body_offset;
        const std::uint64_t lines = count_element_lines(body, ctx.data.data() + ctx.data.size());
        if (lines < total) fail_ascii_ends_early(ctx, lines);
      }
      throw FormatError(ctx.path + ": line " + std::to_string(element.header_line) + ": " +
                        "element " + element.name + ": count " + std::to_string(element.count) +
                        " cannot fit in the file (each needs at least " + std::to_string(size) +
                        " bytes, " + std::to_string(remaining) +
                        " bytes remain after the header and earlier elements)");
    }
    needed += element.count * size;
    exact = exact && !element.has_lists();
  }
}

}  // namespace pointillist::ply
