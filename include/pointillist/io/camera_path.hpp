// Camera path files: a text file with one camera a line, read by `render --path FILE` and
// written by `generate --scene wall|city|field|row`.
//
//   # comments run from '#' to the end of the line; blank lines are ignored
//   fov 30                      optional, once, before the first frame: vertical fov, degrees
//   0 2 30   0 2 0              eye_x eye_y eye_z  target_x target_y target_z
//   0 2 30   0 2 0   0 1 0      ... optionally followed by up_x up_y up_z
//
// Numbers are decimal (as strtod reads them, without hex), separated by blanks or tabs.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "pointillist/core/camera.hpp"
#include "pointillist/core/math.hpp"

namespace pointillist {

struct CameraPathFrame {
  Vec3f eye;
  Vec3f target;
  std::optional<Vec3f> up;  // unset: the default of whoever builds the camera (path_cameras)
  std::size_t line = 0;     // 1-based line it was read from; 0 for a frame made in code
};

struct CameraPath {
  std::optional<float> fov_deg;  // the `fov` line, degrees in (0, 180)
  std::vector<CameraPathFrame> frames;
};

// A path file holds at most this many frames (a bad or hostile file stops there).
inline constexpr std::size_t kMaxCameraPathFrames = 1'000'000;

// Parses the text of a path file; `name` (the file's path) starts every message. Throws
// FormatError naming the line and what was expected: a line of other than 6 or 9 numbers, a
// value that is not a finite number, eye == target, an up vector that is zero or parallel to
// the view direction, a misplaced or repeated `fov` line or one out of (0, 180), more than
// kMaxCameraPathFrames frames, or no frame at all.
CameraPath parse_camera_path(std::string_view text, const std::string& name);

// Reads and parses the path file at `path`. Throws IoError when it cannot be read, and what
// parse_camera_path throws.
CameraPath read_camera_path(const std::string& path);

// The text of a path file: `comment` (each of its lines prefixed with "# "), the fov line when
// set, then one line per frame (the up vector only when the frame has one). Numbers are written
// in their shortest form that reads back to the same float.
std::string format_camera_path(const CameraPath& path, std::string_view comment = {});

// Writes format_camera_path(path, comment) to `file` atomically. Throws IoError.
void write_camera_path(const std::string& file, const CameraPath& path,
                       std::string_view comment = {});

// The cameras of a path's frames at the given field of view and image size; frames without an
// up vector get `default_up`. `name` (the file's path) starts the messages. Throws FormatError
// naming the frame's line when `default_up` is parallel to that frame's view direction, and
// OptionError for a size or fov out of range.
std::vector<Camera> path_cameras(const CameraPath& path, const std::string& name, float fov_deg,
                                 int width, int height, Vec3f default_up = {0, 1, 0});

}  // namespace pointillist
