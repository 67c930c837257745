// open_sdl_window: loads the window library (src/window/sdl_window.cpp) on first use, so that
// only `pointillist view` pays for SDL and the desktop libraries it depends on.
#include <dlfcn.h>

#include <filesystem>
#include <mutex>
#include <string>
#include <vector>

#include "pointillist/core/error.hpp"
#include "pointillist/viewer/sdl_window.hpp"

namespace pointillist {
namespace {

OpenSdlWindowFn load_window_library() {
  static std::mutex mutex;
  static OpenSdlWindowFn open = nullptr;
  const std::lock_guard lock(mutex);
  if (open) return open;
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  const std::filesystem::path dir = ec ? std::filesystem::current_path() : exe.parent_path();
  const std::vector<std::filesystem::path> places = {
      dir / kSdlWindowLibrary, dir / ".." / "lib" / "pointillist" / kSdlWindowLibrary};
  std::string tried;
  for (const auto& place : places) {
    if (void* handle = ::dlopen(place.c_str(), RTLD_NOW | RTLD_LOCAL)) {
      // Never closed: the window's code must outlive every window.
      open = reinterpret_cast<OpenSdlWindowFn>(::dlsym(handle, "pointillist_open_sdl_window"));
      if (open) return open;
      tried += "\n  " + place.string() + ": has no entry point pointillist_open_sdl_window";
      continue;
    }
    const char* why = ::dlerror();  // names the file
    tried += "\n  " + (why ? std::string(why) : place.string() + ": not loadable");
  }
  throw IoError("cannot open a window: the viewer's window library " +
                std::string(kSdlWindowLibrary) + " did not load from beside the program or " +
                "from ../lib/pointillist:" + tried +
                "\nbuild it with the program (cmake --build), install both with cmake --install, "
                "and install SDL 2 (scripts/setup.sh); `pointillist render` draws images without "
                "a window");
}

}  // namespace

std::unique_ptr<Window> open_sdl_window(const std::string& title, int width, int height) {
  const OpenSdlWindowFn open = load_window_library();
  std::string error;
  Window* window = open(title.c_str(), width, height, &error);
  if (!window) throw IoError(error);
  return std::unique_ptr<Window>(window);
}

}  // namespace pointillist
