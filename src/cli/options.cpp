// Command-line option helpers (see options.hpp).
#include "options.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "pointillist/core/error.hpp"
#include "pointillist/core/thread_pool.hpp"

namespace pointillist::cli {
namespace {

std::vector<float> parse_floats(const std::string& text, std::size_t count, const char sep,
                                const std::string& option) {
  std::vector<float> values;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, sep)) {
    try {
      std::size_t used = 0;
      const float v = std::stof(item, &used);
      if (used != item.size()) throw std::invalid_argument(item);
      values.push_back(v);
    } catch (const std::exception&) {
      values.clear();
      break;
    }
  }
  if (values.size() != count) {
    throw OptionError(option + " '" + text + "': expected " + std::to_string(count) +
                      " numbers separated by '" + sep + "'");
  }
  return values;
}

}  // namespace

// --size WxH and --view AZ,EL (may be empty) into `v`.
void parse_size_and_view(const std::string& size, const std::string& view, ViewOptions& v) {
  const auto wh = parse_floats(size, 2, 'x', "--size");
  v.width = static_cast<int>(wh[0]);
  v.height = static_cast<int>(wh[1]);
  if (wh[0] < 1 || wh[1] < 1 || wh[0] > 32768 || wh[1] > 32768 || wh[0] != v.width ||
      wh[1] != v.height) {
    throw OptionError("--size '" + size +
                                   "': width and height must be whole numbers from 1 to 32768");
  }
  if (!view.empty()) {
    const auto ae = parse_floats(view, 2, ',', "--view");
    v.azimuth_deg = ae[0];
    v.elevation_deg = ae[1];
  }
}

// "500000", "64K", "512M", "1.5G" (powers of 1024) -> bytes.
std::uint64_t parse_bytes(const std::string& text, const std::string& option) {
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  double scale = 1;
  const std::string unit = end ? std::string(end) : std::string();
  if (unit == "K" || unit == "k" || unit == "KB" || unit == "KiB") scale = 1024.0;
  else if (unit == "M" || unit == "MB" || unit == "MiB") scale = 1024.0 * 1024;
  else if (unit == "G" || unit == "GB" || unit == "GiB") scale = 1024.0 * 1024 * 1024;
  else if (!unit.empty()) scale = -1;
  const double bytes = value * scale;
  if (text.empty() || end == text.c_str() || scale < 0 || !(bytes >= 1) || bytes > 1e18) {
    throw OptionError(option + " '" + text +
                      "': give a size in bytes, optionally with K, M or G (e.g. 512M)");
  }
  return static_cast<std::uint64_t>(bytes);
}

// "orbit:N" (1 <= N <= 100000) -> N.
unsigned parse_orbit_path(const std::string& text) {
  const std::string prefix = "orbit:";
  if (text.rfind(prefix, 0) == 0) {
    const std::string count = text.substr(prefix.size());
    char* end = nullptr;
    const unsigned long n = std::strtoul(count.c_str(), &end, 10);
    if (!count.empty() && *end == '\0' && n >= 1 && n <= 100000 && count[0] != '-') {
      return static_cast<unsigned>(n);
    }
  }
  throw OptionError("--path '" + text +
                                 "' is not a camera path; give orbit:N with N frames from 1 to 100000 "
                                 "(e.g. --path orbit:120)");
}

bool is_orbit_path(const std::string& text) { return text.rfind("orbit:", 0) == 0; }

std::string checked_path_file(const std::string& text) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(text, ec)) {
    throw OptionError("--path '" + text +
                      "': no such camera path file; give orbit:N for N frames around the model "
                      "(e.g. --path orbit:120) or the path of a camera path file");
  }
  return text;
}

Vec3f parse_vec3(const std::string& text, const std::string& option) {
  const auto v = parse_floats(text, 3, ',', option);
  return {v[0], v[1], v[2]};
}

// "R,G,B" with each component a whole number 0-255.
Rgb8 parse_rgb8(const std::string& text, const std::string& option) {
  const Vec3f c = parse_vec3(text, option);
  for (float v : {c.x, c.y, c.z}) {
    if (v < 0 || v > 255 || v != std::floor(v)) {
      throw OptionError(option + " '" + text + "': components must be whole numbers 0-255");
    }
  }
  return {static_cast<std::uint8_t>(c.x), static_cast<std::uint8_t>(c.y),
          static_cast<std::uint8_t>(c.z)};
}

void add_camera_options(CLI::App* app, ViewOptions& view, CameraText& text) {
  app->add_option("--size", text.size, "Image size WxH")
      ->default_str("1280x720")
      ->group(kGroupCamera);
  app->add_option("--view", text.view, "Orbit view AZ,EL in degrees (default 0,0)")
      ->group(kGroupCamera);
  app->add_option("--distance", view.distance,
                  "Eye distance in model radii (default: whole model in view)")
      ->group(kGroupCamera);
  app->add_option("--fov", view.fov_deg, "Vertical field of view, degrees")
      ->default_val(30.0f)
      ->group(kGroupCamera);
  app->add_option("--ortho", view.ortho_height,
                  "Orthographic camera showing HEIGHT world units from the image's top to its "
                  "bottom (parallel rays: no perspective; --view 0,90 is a plan view)")
      ->check(CLI::PositiveNumber)
      ->group(kGroupCamera);
  app->add_option("--eye", text.eye, "Explicit eye X,Y,Z (with --target)")->group(kGroupCamera);
  app->add_option("--target", text.target, "Explicit target X,Y,Z (with --eye)")
      ->group(kGroupCamera);
  app->add_option("--up", text.up,
                  "Up vector X,Y,Z: with --eye/--target, or for the frames of a camera path file "
                  "that give none, the camera's (default 0,1,0); otherwise the up axis for --view "
                  "and --path orbit:N (default: the model's, +Z for LAS scans, else +Y)")
      ->group(kGroupCamera);
}

void parse_camera_options(const CameraText& text, ViewOptions& view) {
  parse_size_and_view(text.size, text.view, view);
  if (!text.eye.empty()) view.eye = parse_vec3(text.eye, "--eye");
  if (!text.target.empty()) view.target = parse_vec3(text.target, "--target");
  if (!text.up.empty()) view.up = parse_vec3(text.up, "--up");
}

void add_edl_and_two_sided(CLI::App* app, RenderSettings& settings,
                           std::vector<std::string>& edl_text) {
  app->add_option("--edl", edl_text,
                  "Eye-dome lighting [STRENGTH, default 1]: darken each pixel by how far its "
                  "neighbours stand in front of it (depth-only shading that shows the shape of "
                  "scans without normals; combine with --unlit for depth shading alone)")
      ->expected(0, 1)
      ->group(kGroupLook);
  app->add_flag("--two-sided", settings.two_sided,
                "Two-sided lighting: no backface culling, surfaces seen from behind lit as "
                "from the front (partial scans seen from behind)")
      ->group(kGroupLook);
}

float parse_edl(const std::vector<std::string>& edl_text) {
  if (edl_text.empty() || edl_text.front().empty()) return 1.0f;
  const std::string& t = edl_text.front();
  char* end = nullptr;
  const float v = std::strtof(t.c_str(), &end);
  if (end != t.c_str() + t.size() || t.empty() || !(v > 0.0f) || !(v <= 100.0f)) {
    throw OptionError("--edl " + t + ": give a strength between 0 and 100 (exclusive of 0; 1 is "
                      "the usual strength), or --edl alone");
  }
  return v;
}

void add_columns(CLI::App* app, std::string& columns) {
  app->add_option("--columns", columns,
                  "Text inputs (.xyz .pts .csv .txt): what each column holds, e.g. "
                  "x,y,z,skip,r,g,b (names: x y z nx ny nz r g b skip; default: detect)")
      ->group(kGroupScan);
}

CLI::Option* add_sharp_threshold(CLI::App* app, FeatureOptions& features) {
  char help[256];
  std::snprintf(help, sizeof help,
                "With --features: neighbours whose normals' cosine is below W are a sharp edge "
                "(default 0.9, about 26 degrees; on a rough scan lower: %.1f times the angle "
                "within which 3/4 of the neighbours' normals agree, at most 45 degrees)",
                kSpreadFactor);
  return app->add_option("--sharp-threshold", features.sharp_threshold, help)
      ->default_val(0.9f)
      ->check(CLI::Range(-1.0f, 1.0f));
}

void add_threads(CLI::App* app, unsigned& threads) {
  const unsigned cap = ThreadPool::max_threads();
  app->add_option("--threads", threads,
                  "Worker threads (0 = one per core; at most " + std::to_string(cap) +
                      ", 4 per core, here)")
      ->default_val(0)
      ->each([cap](const std::string& value) {
        // The pool caps the count; say so rather than silently.
        if (value.find_first_not_of("0123456789") == std::string::npos && value.size() < 10 &&
            std::stoul(value) > cap) {
          std::fprintf(stderr,
                       "pointillist: warning: --threads %s is more than 4 per core; using %u\n",
                       value.c_str(), cap);
        }
      });
}

void add_prepare_options(CLI::App* app, PrepareOptions& p, bool with_radius_scale) {
  add_enum<NormalSource>(app, "--normals", p.normals,
                         {{"auto", NormalSource::Auto},
                          {"keep", NormalSource::Keep},
                          {"mesh", NormalSource::Mesh},
                          {"pca", NormalSource::Pca}},
                         "Normal source: auto (file, else mesh faces, else PCA), keep, mesh, pca",
                         "auto")
      ->group(kGroupScan);
  app->add_option("--k", p.k, "Neighbours for PCA normals")
      ->default_val(16)
      ->check(CLI::Range(3u, 256u))
      ->group(kGroupScan);
  if (with_radius_scale) {
    app->add_option("--radius-scale", p.radius_scale, "Multiply every splat radius by S")
        ->default_val(1.0f)
        ->check(CLI::Validator(
            [](const std::string& v) {
              char* end = nullptr;
              const double x = std::strtod(v.c_str(), &end);
              return end != v.c_str() && *end == 0 && x > 0 && std::isfinite(x)
                         ? std::string()
                         : "must be a positive number, found " + v;
            },
            "POSITIVE"))
        ->group(kGroupScan);
  }
  app->add_flag("--drop-outliers", p.drop_outliers,
                "Point clouds: drop stray points, whose neighbours are much farther than usual")
      ->group(kGroupScan);
  app->add_option("--outlier-ratio", p.outlier_ratio_drop,
                  "With --drop-outliers: how many times farther than its neighbours' a point's "
                  "neighbours must be (lower drops more)")
      ->default_val(3.0f)
      ->check(CLI::Range(1.0001f, 1e6f))
      ->group(kGroupScan);
}

std::string unknown_word(CLI::App& app, int argc, char** argv) {
  if (argc < 2) return {};
  const std::string first = argv[1];
  if (first.empty() || first[0] == '-') return {};  // --help, --version: CLI11's
  CLI::App* command = nullptr;
  for (CLI::App* c : app.get_subcommands({})) {
    if (c->check_name(first)) command = c;
  }
  if (!command) {
    std::string names;
    for (const CLI::App* c : app.get_subcommands({})) {
      names += (names.empty() ? "" : ", ") + c->get_name();
    }
    return "unknown command '" + first + "'; the commands are " + names +
           " (pointillist --help describes them)";
  }
  for (int i = 2; i < argc; ++i) {
    const std::string word = argv[i];
    if (word == "--") break;  // what follows is positional
    if (word.size() < 3 || word.compare(0, 2, "--") != 0) continue;
    const std::string name = word.substr(0, word.find('='));
    if (!command->get_option_no_throw(name)) {
      return "unknown option " + name + " for '" + first + "'; pointillist " + first +
             " --help lists its options";
    }
  }
  return {};
}

}  // namespace pointillist::cli
