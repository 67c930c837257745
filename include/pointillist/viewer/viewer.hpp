// The interactive viewer (`pointillist view`): a loop over a window that turns input into camera
// moves and toggles, holds the frame rate while the camera moves (the frame-time controller sets
// the detail), refines to full detail when it stops (QSplat's idle refinement), lets a paged
// model's pages stream in on the loader thread, and writes screenshots with the `render` command
// that draws the same image headless. The window itself is an interface: SDL in the program
// (sdl_window.hpp), a recording fake in tests.
#pragma once

#include <chrono>
#include <cstdio>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "pointillist/core/thread_pool.hpp"
#include "pointillist/render/renderer.hpp"
#include "pointillist/viewer/input.hpp"
#include "pointillist/viewer/navigation.hpp"

namespace pointillist {

class Window {
 public:
  virtual ~Window() = default;
  // Shows the frame's colours (the window may be larger or smaller for a moment while resizing).
  virtual void present(const Frame& frame) = 0;
  // The next pending event, without waiting; false when there is none.
  virtual bool poll(InputEvent& event) = 0;
  // Sleeps until an event is pending or `ms` milliseconds pass.
  virtual void wait(int ms) = 0;
  virtual void set_title(const std::string& title) = 0;
  // Resizes the window (a script's `resize`); the window reports it back as a Resize event.
  virtual void resize(int width, int height) = 0;
  // Lines of text drawn over every frame presented from now on (none: empty). Never part of the
  // frame (screenshots are the frame). False when this window cannot draw text.
  virtual bool set_overlay(const std::vector<std::string>& lines) {
    (void)lines;
    return false;
  }
};

struct ViewerOptions {
  RenderSettings settings;  // the detail in it (threshold_px, or frame.epsilon_px) is full detail
  FrameSettings frame;
  double fps = 30;                 // the frame rate held while the camera moves
  unsigned refine_frames = 8;      // frames from the moving detail to full detail
  std::string name;                // the window title's file name(s)
  // The words of `pointillist render` that the viewer does not change: the inputs and the options
  // given to `view` that shape the image (e.g. --background, --memory). The viewer appends the
  // camera and the options its keys toggle.
  std::vector<std::string> render_command;
  std::string screenshot_dir = ".";  // key s writes pointillist-view-NNN.png there
  std::vector<ScriptStep> script;    // scripted input (--events); empty = a person's input
  bool scripted = false;
  std::string log_frames;  // a CSV line per frame there (--log-frames), or empty
  bool quiet = false;      // print no help and no screenshot lines
  // Where the frames' times count from (ViewerFrame::t_ms): the program's start, so the first
  // frame's time includes opening the models and the window.
  std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
};

// What one frame of the viewer was (also a line of --log-frames).
struct ViewerFrame {
  double t_ms = 0;          // when it was shown, since ViewerOptions::start
  const char* phase = "";   // "moving", "refine" or "loading"
  float detail = 0;         // QSplat threshold or SPT epsilon, pixels
  double render_ms = 0;     // Renderer::render
  double frame_ms = 0;      // render and present
  double latency_ms = -1;   // from the first input event the frame answers to its showing
  std::uint64_t splats = 0;
  std::uint64_t resident_bytes = 0;  // the process's resident memory
  std::uint64_t pages_loaded = 0;    // paged models: pages loaded so far
};

struct ViewerResult {
  std::vector<ViewerFrame> frames;
  std::vector<std::string> screenshots;  // files written
};

// The render command line that draws `camera` with these settings (every word, shell-quoted
// where needed): `base` then --size --eye --target --up --fov and the toggled options.
std::string render_command_line(std::span<const std::string> base, const Camera& camera,
                                const RenderSettings& settings, const FrameSettings& frame,
                                const std::string& output);

// Runs the viewer until the window is closed, `q`/Escape is pressed or the script ends. Prints
// help and screenshot lines to `out`. Throws what rendering throws for the first frame (a model
// that cannot be drawn); later refusals (a toggle the models do not allow) are shown in the
// title and undone.
ViewerResult run_viewer(Renderer& renderer, std::span<const SceneInstance> scene,
                        Navigator& navigator, Window& window, ThreadPool& pool,
                        const ViewerOptions& options, std::FILE* out);

// The viewer's keys, one per line, as `h` prints them.
std::string viewer_help();

}  // namespace pointillist
