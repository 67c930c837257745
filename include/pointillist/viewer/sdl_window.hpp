// The viewer's window on the desktop (SDL 2): frames are blitted to the window surface (no GPU
// rendering of splats), mouse, wheel, keys and resizes come back as InputEvents.
#pragma once

#include <memory>
#include <string>

#include "pointillist/viewer/viewer.hpp"

namespace pointillist {

// Opens a resizable window. Throws IoError (saying that the viewer needs a display, e.g. a
// desktop session or xvfb-run) when no window can be opened. The window lives in the shared
// library pointillist-sdl-window.so, loaded on the first call from beside the program (or from
// ../lib/pointillist when installed); IoError names both places when it is missing.
std::unique_ptr<Window> open_sdl_window(const std::string& title, int width, int height);

// The library's file name and its entry point (extern "C"; null and `error` filled on failure).
inline constexpr const char* kSdlWindowLibrary = "pointillist-sdl-window.so";
using OpenSdlWindowFn = Window* (*)(const char* title, int width, int height, std::string* error);

}  // namespace pointillist
