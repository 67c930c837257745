#include "pointillist/viewer/viewer.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>

#include "pointillist/core/error.hpp"
#include "pointillist/io/png.hpp"
#include "pointillist/render/frame_control.hpp"
#include "pointillist/render/sequence.hpp"
#include "viewer_state.hpp"

namespace pointillist {
namespace {

using Clock = std::chrono::steady_clock;

std::uint64_t resident_memory_bytes() {
  std::ifstream statm("/proc/self/statm");
  std::uint64_t size = 0, resident = 0;
  if (!(statm >> size >> resident)) return 0;
  return resident * static_cast<std::uint64_t>(::sysconf(_SC_PAGESIZE));
}

std::string shell_word(const std::string& w) {
  if (!w.empty() && w.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                        "0123456789-_./,:=+@%") == std::string::npos) {
    return w;
  }
  std::string q = "'";
  for (char c : w) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

std::string vec3_text(Vec3f v) {
  char s[128];
  std::snprintf(s, sizeof s, "%.9g,%.9g,%.9g", double(v.x), double(v.y), double(v.z));
  return s;
}

std::string number_text(float v) {
  char s[32];
  std::snprintf(s, sizeof s, "%.9g", double(v));
  return s;
}

// The next free DIR/pointillist-view-NNN.png.
std::string next_screenshot(const std::string& dir) {
  for (int i = 1; i < 100000; ++i) {
    char name[40];
    std::snprintf(name, sizeof name, "pointillist-view-%03d.png", i);
    const std::filesystem::path p = std::filesystem::path(dir) / name;
    std::error_code ec;
    if (!std::filesystem::exists(p, ec)) return p.string();
  }
  throw IoError(dir + ": no free screenshot name (pointillist-view-001.png to -99999.png all "
                      "exist); move them away");
}

}  // namespace

std::string render_command_line(std::span<const std::string> base, const Camera& c,
                                const RenderSettings& s, const FrameSettings& f,
                                const std::string& output) {
  std::vector<std::string> w(base.begin(), base.end());
  const auto add = [&](std::string option, std::string value) {
    w.push_back(std::move(option));
    if (!value.empty()) w.push_back(std::move(value));
  };
  add("--size", std::to_string(c.width) + "x" + std::to_string(c.height));
  add("--eye", vec3_text(c.eye));
  add("--target", vec3_text(c.target));
  add("--up", vec3_text(c.up));
  add("--fov", number_text(c.fov_deg));
  if (c.ortho_height > 0) add("--ortho", number_text(c.ortho_height));
  if (f.rasterizer != Rasterizer::Fast) add("--mode", name(f.rasterizer));
  if (s.shape != SplatShape::Circle) add("--splat", name(s.shape));
  if (f.lod == LodScheme::Spt) {
    add("--lod", "spt");
    if (f.epsilon_px != 1.0f) add("--epsilon", number_text(f.epsilon_px));
    if (f.hybrid) add("--hybrid", "");
    if (f.hybrid && f.triangle_px_per_epsilon != 4.0f) {
      add("--triangle-px", number_text(f.triangle_px_per_epsilon));
    }
  } else if (s.threshold_px != 1.0f) {
    add("--threshold", number_text(s.threshold_px));
  }
  if (f.splat_scale != 1.0f) add("--radius-scale", number_text(f.splat_scale));
  if (s.edl_strength > 0) add("--edl", number_text(s.edl_strength));
  if (s.two_sided) add("--two-sided", "");
  if (!f.features) add("--no-features", "");
  if (f.occlusion.method != OcclusionMethod::None) add("--occlusion", name(f.occlusion.method));
  add("-o", output);
  std::string line;
  for (const std::string& word : w) {
    if (!line.empty()) line += ' ';
    line += shell_word(word);
  }
  return line;
}

std::string viewer_help() {
  return "mouse: left drag orbits, right or middle drag pans, wheel zooms to the cursor,\n"
         "       double click makes the point under the cursor the centre of rotation\n"
         "keys:  1-6 front, back, left, right, top, bottom views; 0 or r reset the view\n"
         "       m fast / quality mode; k splat kernel (square, circle, ellipse)\n"
         "       l QSplat / Sequential Point Tree; plus / minus splat size\n"
         "       p hybrid points and triangles (meshes; switches to the SPT)\n"
         "       e eye-dome lighting on / off; t two-sided lighting on / off\n"
         "       o orthographic / perspective camera\n"
         "       f sharp features on / off; c occlusion culling (none / chc++)\n"
         "       s screenshot and its render command; h this help; q or Escape quit\n";
}

ViewerResult run_viewer(Renderer& renderer, std::span<const SceneInstance> scene,
                        Navigator& navigator, Window& window, ThreadPool& pool,
                        const ViewerOptions& o, std::FILE* out) {
  ViewerState st(o, navigator);
  ViewerResult result;
  const Clock::time_point start = o.start;
  const auto now_ms = [&] {
    return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
  };
  std::optional<std::ofstream> log;
  if (!o.log_frames.empty()) {
    log.emplace(o.log_frames, std::ios::trunc);
    if (!*log) throw IoError(errno_message("cannot write the frame log " + o.log_frames));
    *log << "frame,t_ms,phase,detail_px,render_ms,frame_ms,latency_ms,splats,resident_bytes,"
            "pages_loaded\n";
  }
  if (!o.quiet) std::fprintf(out, "%s", viewer_help().c_str());
  Frame frame;
  bool have_frame = false;
  bool help_shown = false;
  double title_at = -1e9;
  std::size_t title_frames = 0;  // frames drawn when the title was last set
  std::size_t script_step = 0, script_event = 0;
  double wait_until = -1;
  const auto screenshot = [&](std::string file) {
    if (!have_frame) return;
    if (file.empty()) file = next_screenshot(o.screenshot_dir);
    write_png_rgb8(file, frame.width, frame.height, frame.color);
    result.screenshots.push_back(file);
    if (!o.quiet) {
      std::filesystem::path p(file);
      const std::string render_out = (p.parent_path() / (p.stem().string() + "-render.png")).string();
      std::fprintf(out, "screenshot: %s\n  %s\n", file.c_str(),
                   render_command_line(o.render_command, navigator.camera(), st.settings(),
                                       st.frame_settings(), render_out)
                       .c_str());
      std::fflush(out);
    }
  };
  while (!st.quit()) {
    // Input: the window's, then (scripted) one step of the script.
    InputEvent e;
    while (window.poll(e)) st.handle(e, now_ms(), frame);
    while (o.scripted && !st.quit()) {
      if (script_step >= o.script.size()) {
        st.handle({.type = InputEvent::Type::Quit}, now_ms(), frame);
        break;
      }
      const ScriptStep& s = o.script[script_step];
      if (s.type == ScriptStep::Type::Wait) {
        if (wait_until < 0) wait_until = now_ms() + s.wait_ms;
        if (now_ms() < wait_until) break;
        wait_until = -1;
      } else if (s.type == ScriptStep::Type::Settle) {
        if (!st.settled()) break;
      } else if (s.type == ScriptStep::Type::Screenshot) {
        screenshot(s.file);
      } else if (s.type == ScriptStep::Type::Quit) {
        st.handle({.type = InputEvent::Type::Quit}, now_ms(), frame);
        break;
      } else {
        const InputEvent& ev = s.events[script_event];
        if (ev.type == InputEvent::Type::Resize) window.resize(ev.width, ev.height);
        st.handle(ev, now_ms(), frame);
        if (++script_event < s.events.size()) break;  // one event a frame
        script_event = 0;
      }
      ++script_step;
      if (s.type == ScriptStep::Type::Events) break;
    }
    if (st.quit()) break;
    if (st.take_screenshot_request()) screenshot("");
    if (st.help_requested()) {
      // Over the frame where the window draws text, else in the terminal.
      help_shown = !help_shown;
      std::vector<std::string> lines;
      if (help_shown) {
        lines.push_back("Pointillist keys (h hides this)");
        std::istringstream help(viewer_help());
        for (std::string line; std::getline(help, line);) lines.push_back(line);
      }
      if (window.set_overlay(lines)) {
        if (have_frame) window.present(frame);
      } else if (help_shown && !o.quiet) {
        std::fprintf(out, "%s", viewer_help().c_str());
      }
    }
    const std::optional<float> detail = st.next_detail(renderer);
    if (!detail) {
      if (now_ms() - title_at > 250 || title_frames != result.frames.size()) {
        window.set_title(st.title(renderer, now_ms(),
                                  result.frames.empty() ? nullptr : &result.frames.back()));
        title_at = now_ms();
        title_frames = result.frames.size();
      }
      window.wait(o.scripted ? 2 : 50);
      continue;
    }
    RenderSettings s = st.settings();
    FrameSettings f = st.frame_settings();
    (f.lod == LodScheme::Spt ? f.epsilon_px : s.threshold_px) = *detail;
    const double t0 = now_ms();
    try {
      renderer.render(scene, navigator.camera(), s, f, pool, frame);
    } catch (const OptionError& error) {
      if (!st.refuse(error.what(), now_ms())) throw;
      std::fprintf(stderr, "pointillist view: %s\n", error.what());
      continue;
    }
    const double t1 = now_ms();
    window.present(frame);
    have_frame = true;
    const double t2 = now_ms();
    const std::size_t handed = renderer.paging() ? renderer.request_in_background() : 0;
    ViewerFrame r;
    r.t_ms = t2;
    r.phase = st.phase_name();
    r.detail = *detail;
    r.render_ms = t1 - t0;
    r.frame_ms = t2 - t0;
    r.latency_ms = st.input_time() >= 0 ? t2 - st.input_time() : -1;
    r.splats = frame.stats.splats;
    r.resident_bytes = resident_memory_bytes();
    r.pages_loaded = renderer.paging() ? renderer.paging_stats().cache.pages_loaded : 0;
    st.frame_done(r.frame_ms, renderer, handed);
    if (log) {
      *log << result.frames.size() << ',' << r.t_ms << ',' << r.phase << ',' << r.detail << ','
           << r.render_ms << ',' << r.frame_ms << ',' << r.latency_ms << ',' << r.splats << ','
           << r.resident_bytes << ',' << r.pages_loaded << '\n';
    }
    result.frames.push_back(r);
    if (now_ms() - title_at > 250) {
      window.set_title(st.title(renderer, now_ms(), &result.frames.back()));
      title_at = now_ms();
      title_frames = result.frames.size();
    }
  }
  return result;
}

}  // namespace pointillist
