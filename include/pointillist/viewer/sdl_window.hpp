// The viewer's window on the desktop (SDL 2): frames are blitted to the window surface (no GPU
// rendering of splats), mouse, wheel, keys and resizes come back as InputEvents.
#pragma once

#include <memory>
#include <string>

#include "pointillist/viewer/viewer.hpp"

namespace pointillist {

// Opens a resizable window. Throws IoError (saying that the viewer needs a display, e.g. a
// desktop session or xvfb-run) when no window can be opened.
std::unique_ptr<Window> open_sdl_window(const std::string& title, int width, int height);

}  // namespace pointillist
