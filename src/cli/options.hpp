// Command-line option helpers shared by the subcommands: value parsers with messages that say
// what was expected, enum options whose choices print by name, and the option groups.
#pragma once

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "commands.hpp"
#include "pointillist/core/math.hpp"
#include "pointillist/features/features.hpp"
#include "pointillist/prep/prepare.hpp"
#include "pointillist/render/settings.hpp"

namespace pointillist::cli {

// Option groups of --help.
inline constexpr const char* kGroupCamera = "Camera";
inline constexpr const char* kGroupLook = "Look";
inline constexpr const char* kGroupDetail = "Level of detail";
inline constexpr const char* kGroupSequence = "Frame sequences";
inline constexpr const char* kGroupPaging = "Paging (models larger than memory)";
inline constexpr const char* kGroupScan = "Scan preparation (scans given as input)";
inline constexpr const char* kGroupOutput = "Output";

// --size WxH and --view AZ,EL (may be empty) into `v`.
void parse_size_and_view(const std::string& size, const std::string& view, ViewOptions& v);
// "500000", "64K", "512M", "1.5G" (powers of 1024) -> bytes.
std::uint64_t parse_bytes(const std::string& text, const std::string& option);
// "orbit:N" (1 <= N <= 100000) -> N.
unsigned parse_orbit_path(const std::string& text);
// Whether a --path value means the orbit ("orbit:..."); anything else names a path file.
bool is_orbit_path(const std::string& text);
// A --path value naming a camera path file, returned as it is; throws OptionError (mentioning
// orbit:N, which may have been meant) when no such file exists.
std::string checked_path_file(const std::string& text);
Vec3f parse_vec3(const std::string& text, const std::string& option);
// "R,G,B" with each component a whole number 0-255.
Rgb8 parse_rgb8(const std::string& text, const std::string& option);

// An option taking one of `choices` by name (case-insensitive); --help lists the names.
template <class E>
CLI::Option* add_enum(CLI::App* app, const std::string& name, E& target,
                      const std::vector<std::pair<std::string, E>>& choices,
                      const std::string& description, const std::string& default_name = "") {
  std::vector<std::string> names;
  for (const auto& c : choices) names.push_back(c.first);
  auto* option = app->add_option_function<std::string>(
      name,
      [&target, choices](const std::string& value) {
        std::string lower = value;
        std::transform(lower.begin(), lower.end(), lower.begin(),
                       [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
        for (const auto& c : choices) {
          if (c.first == lower) target = c.second;
        }
      },
      description);
  option->check(CLI::IsMember(names, CLI::ignore_case));
  if (!default_name.empty()) option->default_str(default_name);
  return option;
}

// The camera options (--size, --view, --distance, --fov, --eye, --target, --up) as typed: `render`
// takes them, and `generate --reference` too, so that its image matches a render of the
// generated samples pixel for pixel. parse_camera_options fills `view` from them once CLI11 has
// read the line; its parsers throw OptionError naming the option.
struct CameraText {
  std::string size = "1280x720", view, eye, target, up;
};
void add_camera_options(CLI::App* app, ViewOptions& view, CameraText& text);
void parse_camera_options(const CameraText& text, ViewOptions& view);

// --edl [STRENGTH] (into `edl_text`; parse_edl reads it once given) and --two-sided, for render
// and view.
void add_edl_and_two_sided(CLI::App* app, RenderSettings& settings,
                           std::vector<std::string>& edl_text);
float parse_edl(const std::vector<std::string>& edl_text);

void add_columns(CLI::App* app, std::string& columns);
// --sharp-threshold W into features.sharp_threshold. The option's count() says whether the user
// gave it: FeatureOptions::adapt_threshold is for when not (the caller sets it after parsing).
CLI::Option* add_sharp_threshold(CLI::App* app, FeatureOptions& features);
void add_threads(CLI::App* app, unsigned& threads);
// The scan preparation options (--normals, --k, --radius-scale, --drop-outliers,
// --outlier-ratio); `render` has its own --radius-scale (the drawn size).
void add_prepare_options(CLI::App* app, PrepareOptions& p, bool with_radius_scale = true);

// What CLI11 would misreport in `argv` (an unknown command reads as "A subcommand is required";
// an unknown --option before a value makes the value look like a missing input file), as a
// message; "" when there is nothing of the kind.
std::string unknown_word(CLI::App& app, int argc, char** argv);

}  // namespace pointillist::cli
