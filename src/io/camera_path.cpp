// Camera path files (see camera_path.hpp).
#include "pointillist/io/camera_path.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <system_error>

#include "pointillist/core/atomic_file.hpp"
#include "pointillist/core/error.hpp"
#include "pointillist/core/file_bytes.hpp"

namespace pointillist {
namespace {

constexpr std::string_view kFrameForm =
    "6 numbers 'eye_x eye_y eye_z target_x target_y target_z', optionally followed by "
    "'up_x up_y up_z'";

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r'; }

// The line's words, up to 10 (enough to tell 6 or 9 from anything else).
std::vector<std::string_view> words(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < line.size() && out.size() < 10) {
    while (i < line.size() && is_blank(line[i])) ++i;
    const std::size_t start = i;
    while (i < line.size() && !is_blank(line[i])) ++i;
    if (i > start) out.push_back(line.substr(start, i - start));
  }
  return out;
}

std::string shown(std::string_view word) {
  return word.size() > 40 ? std::string(word.substr(0, 37)) + "..." : std::string(word);
}

// Whether `word` is a number as a whole; `value` gets it, infinite when it is beyond the float
// range (so the caller's finiteness test names it).
bool read_number(std::string_view word, float& value) {
  if (!word.empty() && word[0] == '+') word.remove_prefix(1);
  if (word.empty() || word[0] == '+') return false;
  const auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), value);
  if (end != word.data() + word.size()) return false;
  if (ec == std::errc::result_out_of_range) {
    // Beyond the float range, or so small that it is 0.
    double wide = 0;
    const auto [wide_end, wide_ec] =
        std::from_chars(word.data(), word.data() + word.size(), wide);
    const bool tiny = wide_ec == std::errc() && wide_end == end &&
                      std::abs(wide) <= std::numeric_limits<float>::max();
    value = tiny ? static_cast<float>(wide) : std::numeric_limits<float>::infinity();
    return true;
  }
  return ec == std::errc();
}

// Whether `up` gives the view direction from eye to target a right vector, as make_camera_frame
// requires.
bool up_fits(Vec3f eye, Vec3f target, Vec3f up) {
  const Vec3f forward = normalized(target - eye);
  return length(cross(forward, up)) > 1e-6f * length(up);
}

std::string triple(Vec3f v) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "%g %g %g", double(v.x), double(v.y), double(v.z));
  return buf;
}

void append_number(std::string& out, float v) {
  std::array<char, 32> buf;
  const auto [end, ec] = std::to_chars(buf.data(), buf.data() + buf.size(), v);
  out.append(buf.data(), ec == std::errc() ? end : buf.data());
}

void append_triple(std::string& out, Vec3f v) {
  append_number(out, v.x);
  out += ' ';
  append_number(out, v.y);
  out += ' ';
  append_number(out, v.z);
}

}  // namespace

CameraPath parse_camera_path(std::string_view text, const std::string& name) {
  CameraPath path;
  std::size_t line_no = 0;
  std::size_t pos = 0;
  while (pos < text.size()) {
    const std::size_t nl = text.find('\n', pos);
    std::string_view line = text.substr(pos, nl == std::string_view::npos ? nl : nl - pos);
    pos = nl == std::string_view::npos ? text.size() : nl + 1;
    ++line_no;
    if (const std::size_t hash = line.find('#'); hash != std::string_view::npos) {
      line = line.substr(0, hash);
    }
    const std::vector<std::string_view> w = words(line);
    if (w.empty()) continue;
    const std::string where = name + ": line " + std::to_string(line_no) + ": ";
    if (w[0] == "fov") {
      float fov = 0;
      if (w.size() != 2 || !read_number(w[1], fov) || !(fov > 0.0f && fov < 180.0f)) {
        throw FormatError(where + "expected 'fov DEGREES' with one number between 0 and 180 "
                          "(exclusive), found '" + shown(line) + "'");
      }
      if (path.fov_deg) {
        throw FormatError(where + "a second fov line; give fov once, before the first frame");
      }
      if (!path.frames.empty()) {
        throw FormatError(where + "the fov line comes after a frame; move it before the first "
                          "frame (it applies to all of them)");
      }
      path.fov_deg = fov;
      continue;
    }
    if (w.size() != 6 && w.size() != 9) {
      throw FormatError(where + "expected " + std::string(kFrameForm) + ", found " +
                        (w.size() >= 10 ? std::string("10 or more") : std::to_string(w.size())) +
                        " values");
    }
    float v[9] = {};
    for (std::size_t i = 0; i < w.size(); ++i) {
      if (!read_number(w[i], v[i])) {
        throw FormatError(where + "value " + std::to_string(i + 1) + " '" + shown(w[i]) +
                          "' is not a number; expected " + std::string(kFrameForm));
      }
      if (!std::isfinite(v[i])) {
        throw FormatError(where + "value " + std::to_string(i + 1) + " '" + shown(w[i]) +
                          "' is not a finite number");
      }
    }
    if (path.frames.size() == kMaxCameraPathFrames) {
      throw FormatError(where + "more than " + std::to_string(kMaxCameraPathFrames) +
                        " frames; a path file holds at most that many (split the path)");
    }
    CameraPathFrame f{{v[0], v[1], v[2]}, {v[3], v[4], v[5]}, std::nullopt, line_no};
    if (f.eye == f.target) {
      throw FormatError(where + "the eye and the target are the same point (" + triple(f.eye) +
                        "); the camera needs a direction to look in");
    }
    if (w.size() == 9) {
      f.up = Vec3f{v[6], v[7], v[8]};
      if (!up_fits(f.eye, f.target, *f.up)) {
        throw FormatError(where + "the up vector (" + triple(*f.up) +
                          ") is zero or parallel to the view direction; give another");
      }
    }
    path.frames.push_back(f);
  }
  if (path.frames.empty()) {
    throw FormatError(name + ": no frames; a path file has one camera a line: " +
                      std::string(kFrameForm));
  }
  return path;
}

CameraPath read_camera_path(const std::string& path) {
  const FileBytes bytes = FileBytes::map(path);
  return parse_camera_path(bytes.view(), path);
}

std::string format_camera_path(const CameraPath& path, std::string_view comment) {
  std::string out;
  std::size_t pos = 0;
  while (pos < comment.size()) {
    const std::size_t nl = comment.find('\n', pos);
    const std::size_t end = nl == std::string_view::npos ? comment.size() : nl;
    out += "# ";
    out.append(comment.substr(pos, end - pos));
    out += '\n';
    pos = end + 1;
  }
  if (path.fov_deg) {
    out += "fov ";
    append_number(out, *path.fov_deg);
    out += '\n';
  }
  for (const CameraPathFrame& f : path.frames) {
    append_triple(out, f.eye);
    out += "  ";
    append_triple(out, f.target);
    if (f.up) {
      out += "  ";
      append_triple(out, *f.up);
    }
    out += '\n';
  }
  return out;
}

void write_camera_path(const std::string& file, const CameraPath& path, std::string_view comment) {
  AtomicFile out(file);
  out.write(format_camera_path(path, comment));
  out.commit();
}

std::vector<Camera> path_cameras(const CameraPath& path, const std::string& name, float fov_deg,
                                 int width, int height, Vec3f default_up) {
  std::vector<Camera> cameras;
  cameras.reserve(path.frames.size());
  for (std::size_t i = 0; i < path.frames.size(); ++i) {
    const CameraPathFrame& f = path.frames[i];
    Camera c{f.eye, f.target, f.up.value_or(default_up), fov_deg, width, height};
    if (!up_fits(c.eye, c.target, c.up)) {
      const std::string place =
          f.line > 0 ? "line " + std::to_string(f.line) : "frame " + std::to_string(i);
      throw FormatError(name + ": " + place + ": the up vector (" + triple(c.up) +
                        ") is parallel to the view direction; give an up vector on that line");
    }
    make_camera_frame(c);  // the size and the fov (OptionError)
    cameras.push_back(c);
  }
  return cameras;
}

}  // namespace pointillist
