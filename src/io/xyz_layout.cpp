#include "xyz_layout.hpp"

#include <algorithm>
#include <cctype>
#include <utility>

#include "pointillist/core/error.hpp"

namespace pointillist::xyz_detail {

std::string lowercase(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::vector<std::string> split_names(std::string_view text) {
  std::vector<std::string> names;
  std::string current;
  for (char c : text) {
    if (c == ',' || c == ';' || c == ' ' || c == '\t' || c == '\r' || c == '"' || c == '\'') {
      if (!current.empty()) names.push_back(lowercase(current));
      current.clear();
    } else {
      current += c;
    }
  }
  if (!current.empty()) names.push_back(lowercase(current));
  return names;
}

Slot slot_for_name(const std::string& name) {
  static const std::pair<const char*, Slot> kNames[] = {
      {"x", kX},         {"y", kY},          {"z", kZ},         {"nx", kA0},
      {"ny", kA1},       {"nz", kA2},        {"normal_x", kA0}, {"normal_y", kA1},
      {"normal_z", kA2}, {"r", kB0},         {"g", kB1},        {"b", kB2},
      {"red", kB0},      {"green", kB1},     {"blue", kB2}};
  for (const auto& [text, slot] : kNames)
    if (name == text) return slot;
  return kSkip;
}

// A layout from column names. `strict` (the columns option): unknown names, repeated names
// and partial groups throw OptionError. Not strict (a header line): unknown names are skipped,
// and a layout without x, y and z, or with repeats, is no layout.
std::optional<Layout> layout_from_names(const std::vector<std::string>& names, bool strict,
                                        const std::string& spec) {
  const auto fail = [&](const std::string& what) -> std::optional<Layout> {
    if (!strict) return std::nullopt;
    throw OptionError("columns '" + spec + "': " + what +
                      " (expected names from x, y, z, nx, ny, nz, r, g, b, skip, separated by "
                      "commas or blanks, e.g. \"x,y,z,skip,r,g,b\")");
  };
  Layout layout;
  int seen[9] = {};
  for (const std::string& name : names) {
    Slot slot = slot_for_name(name);
    if (slot == kSkip && strict && name != "skip" && name != "_")
      return fail("unknown column name '" + name + "'");
    if (slot != kSkip && seen[slot]++) return fail("column '" + name + "' given twice");
    layout.slots.push_back(slot);
  }
  if (!seen[kX] || !seen[kY] || !seen[kZ]) return fail("x, y and z are all required");
  const auto group = [&](int first, const char* what) {
    const int count = seen[first] + seen[first + 1] + seen[first + 2];
    if (count == 3) return true;
    if (count != 0 && strict) fail(std::string(what) + " need all three columns");
    // A header naming only part of a group: those columns are not read.
    for (Slot& s : layout.slots)
      if (s >= first && s < first + 3) s = kSkip;
    return false;
  };
  layout.a = group(kA0, "normals (nx ny nz)") ? Group::Normals : Group::None;
  layout.b = group(kB0, "colors (r g b)") ? Group::Colors : Group::None;
  return layout;
}

// The layout for a first point line of `count` values when nothing names the columns.
Layout layout_from_count(std::size_t count) {
  Layout layout;
  layout.exact = true;
  layout.slots.assign(count, kSkip);
  for (int a = 0; a < 3; ++a) layout.slots[static_cast<std::size_t>(a)] = Slot(kX + a);
  const auto put_group = [&](std::size_t first, Slot slot) {
    for (int k = 0; k < 3; ++k) layout.slots[first + static_cast<std::size_t>(k)] = Slot(slot + k);
  };
  switch (count) {
    case 6:
      put_group(3, kA0);
      layout.a = Group::Detect;
      break;
    case 7:
      put_group(4, kB0);
      layout.b = Group::Detect;
      break;
    case 9:
      put_group(3, kA0);
      put_group(6, kB0);
      layout.a = layout.b = Group::Detect;
      break;
    case 10:
      put_group(4, kA0);
      put_group(7, kB0);
      layout.a = layout.b = Group::Detect;
      break;
    default:
      break;
  }
  return layout;
}

}  // namespace pointillist::xyz_detail
