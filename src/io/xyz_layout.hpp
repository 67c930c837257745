// The column layout of text point files (XYZ, PTS, CSV): which value of a line goes where,
// from column names (--columns, or a header line) or from the count of values. Internal to io.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace pointillist::xyz_detail {

// Where a column's value goes: a coordinate, or one of the two groups of three (A, B) that hold
// normals or colors.
enum Slot : std::int8_t { kSkip = -1, kX, kY, kZ, kA0, kA1, kA2, kB0, kB1, kB2 };

enum class Group { None, Normals, Colors, Detect };

struct Layout {
  std::vector<Slot> slots;  // one per column read; later columns are ignored
  Group a = Group::None, b = Group::None;
  bool exact = false;  // every point line has exactly slots.size() values
};

enum class Delimiter : char { Blank = ' ', Comma = ',', Semicolon = ';' };

std::string lowercase(std::string s);
// Column names separated by commas or blanks, lowercased.
std::vector<std::string> split_names(std::string_view text);
// kSkip for "skip" and unknown names (see layout_from_names).
Slot slot_for_name(const std::string& name);
// The layout named by `names`; with `strict`, a bad list throws OptionError quoting `spec`,
// otherwise gives nothing.
std::optional<Layout> layout_from_names(const std::vector<std::string>& names, bool strict,
                                        const std::string& spec);
// The layout for a first point line of `count` values when nothing names the columns.
Layout layout_from_count(std::size_t count);

}  // namespace pointillist::xyz_detail
