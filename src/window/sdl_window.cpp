// The viewer's SDL 2 window, built as its own shared library (pointillist-sdl-window.so) that
// `pointillist view` loads at run time (viewer/window_loader.cpp): the other commands then start
// without SDL and the ~55 desktop libraries it pulls in. Only the C entry point at the end is
// looked up by name; errors cross back as text, never as exceptions.
#include "pointillist/viewer/sdl_window.hpp"

#include <SDL.h>
#include <SDL_ttf.h>

#include <algorithm>
#include <string>
#include <vector>

#include "pointillist/core/error.hpp"

namespace pointillist {
namespace {

std::string key_name(SDL_Keycode k) {
  if (k >= SDLK_a && k <= SDLK_z) return std::string(1, static_cast<char>('a' + (k - SDLK_a)));
  if (k >= SDLK_0 && k <= SDLK_9) return std::string(1, static_cast<char>('0' + (k - SDLK_0)));
  if (k >= SDLK_KP_1 && k <= SDLK_KP_9) {
    return std::string(1, static_cast<char>('1' + (k - SDLK_KP_1)));
  }
  if (k == SDLK_KP_0) return "0";
  if (k == SDLK_PLUS || k == SDLK_EQUALS || k == SDLK_KP_PLUS) return "plus";
  if (k == SDLK_MINUS || k == SDLK_KP_MINUS) return "minus";
  if (k == SDLK_ESCAPE) return "escape";
  if (k >= SDLK_F1 && k <= SDLK_F12) {
    std::string name = "f";
    name += std::to_string(1 + (k - SDLK_F1));
    return name;
  }
  return "";
}

// Fonts tried for the overlay (Debian's fonts-dejavu-core), first found wins.
constexpr const char* kOverlayFonts[] = {"/usr/share/fonts/truetype/dejavu/DejaVuSansMono.ttf",
                                         "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf"};
constexpr int kOverlayPoints = 15;
constexpr int kOverlayPad = 10;

class SdlWindow final : public Window {
 public:
  SdlWindow(const std::string& title, int width, int height) {
    if (SDL_Init(SDL_INIT_VIDEO) != 0) {
      std::string message = "cannot open a window (";
      message += SDL_GetError();
      message += "); the viewer needs a display: run it in a desktop session, or headless under "
                 "xvfb-run; `pointillist render` draws images without one";
      throw IoError(message);
    }
    // With no display SDL falls back to drivers that show nothing: refuse them unless asked for
    // by name (SDL_VIDEODRIVER=offscreen runs the viewer with no window at all).
    const std::string driver = SDL_GetCurrentVideoDriver() ? SDL_GetCurrentVideoDriver() : "";
    if ((driver == "offscreen" || driver == "dummy") && !SDL_getenv("SDL_VIDEODRIVER")) {
      SDL_Quit();
      throw IoError("cannot open a window (no display found: DISPLAY and WAYLAND_DISPLAY are "
                    "not set); the viewer needs a display: run it in a desktop session, or "
                    "headless under xvfb-run; `pointillist render` draws images without one");
    }
    window_ = SDL_CreateWindow(title.c_str(), SDL_WINDOWPOS_UNDEFINED, SDL_WINDOWPOS_UNDEFINED,
                               width, height, SDL_WINDOW_RESIZABLE);
    if (!window_) {
      const std::string error = SDL_GetError();
      SDL_Quit();
      throw IoError("cannot open a window of " + std::to_string(width) + "x" +
                    std::to_string(height) + " (" + error + "); try a smaller --size");
    }
  }
  ~SdlWindow() override {
    if (overlay_) SDL_FreeSurface(overlay_);
    if (font_) TTF_CloseFont(font_);
    if (ttf_) TTF_Quit();
    SDL_DestroyWindow(window_);
    SDL_Quit();
  }

  bool set_overlay(const std::vector<std::string>& lines) override {
    if (overlay_) SDL_FreeSurface(overlay_);
    overlay_ = nullptr;
    if (!open_font()) return false;
    if (lines.empty()) return true;
    // The lines over a translucent dark box, composed once.
    std::vector<SDL_Surface*> rendered;
    int w = 0, h = 0;
    for (const std::string& line : lines) {
      SDL_Surface* r = TTF_RenderUTF8_Blended(font_, line.empty() ? " " : line.c_str(),
                                              SDL_Color{235, 235, 235, 255});
      if (!r) continue;
      rendered.push_back(r);
      w = std::max(w, r->w);
      h += r->h;
    }
    overlay_ = SDL_CreateRGBSurfaceWithFormat(0, w + 2 * kOverlayPad, h + 2 * kOverlayPad, 32,
                                              SDL_PIXELFORMAT_ARGB8888);
    if (overlay_) {
      SDL_FillRect(overlay_, nullptr, SDL_MapRGBA(overlay_->format, 0, 0, 0, 185));
      SDL_Rect at{kOverlayPad, kOverlayPad, 0, 0};
      for (SDL_Surface* r : rendered) {
        SDL_SetSurfaceBlendMode(r, SDL_BLENDMODE_BLEND);
        SDL_BlitSurface(r, nullptr, overlay_, &at);
        at.y += r->h;
      }
      SDL_SetSurfaceBlendMode(overlay_, SDL_BLENDMODE_BLEND);
    }
    for (SDL_Surface* r : rendered) SDL_FreeSurface(r);
    return overlay_ != nullptr;
  }

  void present(const Frame& frame) override {
    SDL_Surface* target = SDL_GetWindowSurface(window_);
    if (!target || frame.width <= 0 || frame.height <= 0) return;
    SDL_Surface* image = SDL_CreateRGBSurfaceWithFormatFrom(
        const_cast<Rgb8*>(frame.color.data()), frame.width, frame.height, 24, 3 * frame.width,
        SDL_PIXELFORMAT_RGB24);
    if (!image) return;
    SDL_BlitSurface(image, nullptr, target, nullptr);
    SDL_FreeSurface(image);
    if (overlay_) {
      SDL_Rect at{12, 12, 0, 0};
      SDL_BlitSurface(overlay_, nullptr, target, &at);
    }
    SDL_UpdateWindowSurface(window_);
  }

  bool poll(InputEvent& out) override {
    SDL_Event e;
    while (SDL_PollEvent(&e)) {
      if (translate(e, out)) return true;
    }
    return false;
  }

  void wait(int ms) override { SDL_WaitEventTimeout(nullptr, ms); }

  void set_title(const std::string& title) override { SDL_SetWindowTitle(window_, title.c_str()); }

  void resize(int width, int height) override { SDL_SetWindowSize(window_, width, height); }

 private:
  static bool translate(const SDL_Event& e, InputEvent& out) {
    using T = InputEvent::Type;
    switch (e.type) {
      case SDL_QUIT:
        out = {.type = T::Quit};
        return true;
      case SDL_WINDOWEVENT:
        if (e.window.event == SDL_WINDOWEVENT_SIZE_CHANGED) {
          out = {.type = T::Resize, .width = e.window.data1, .height = e.window.data2};
          return true;
        }
        if (e.window.event == SDL_WINDOWEVENT_CLOSE) {
          out = {.type = T::Quit};
          return true;
        }
        return false;
      case SDL_KEYDOWN: {
        const std::string k = key_name(e.key.keysym.sym);
        if (k.empty()) return false;
        out = {.type = T::Key, .key = k};
        return true;
      }
      case SDL_MOUSEBUTTONDOWN:
      case SDL_MOUSEBUTTONUP:
        if (e.button.button < 1 || e.button.button > 3) return false;
        out = {.type = e.type == SDL_MOUSEBUTTONDOWN ? T::Press : T::Release,
               .button = e.button.button,
               .clicks = e.button.clicks,
               .x = static_cast<float>(e.button.x),
               .y = static_cast<float>(e.button.y)};
        return true;
      case SDL_MOUSEMOTION:
        out = {.type = T::Motion,
               .x = static_cast<float>(e.motion.x),
               .y = static_cast<float>(e.motion.y)};
        return true;
      case SDL_MOUSEWHEEL: {
        int x = 0, y = 0;
        SDL_GetMouseState(&x, &y);
        const float clicks = e.wheel.preciseY != 0 ? e.wheel.preciseY : float(e.wheel.y);
        out = {.type = T::Wheel,
               .x = static_cast<float>(x),
               .y = static_cast<float>(y),
               .wheel = e.wheel.direction == SDL_MOUSEWHEEL_FLIPPED ? -clicks : clicks};
        return true;
      }
      default:
        return false;
    }
  }

  bool open_font() {
    if (font_) return true;
    if (!ttf_) {
      if (TTF_Init() != 0) return false;
      ttf_ = true;
    }
    for (const char* path : kOverlayFonts) {
      if ((font_ = TTF_OpenFont(path, kOverlayPoints))) return true;
    }
    return false;
  }

  SDL_Window* window_ = nullptr;
  bool ttf_ = false;
  TTF_Font* font_ = nullptr;
  SDL_Surface* overlay_ = nullptr;  // the help, drawn over every frame presented
};

}  // namespace

}  // namespace pointillist

extern "C" __attribute__((visibility("default"))) pointillist::Window*
pointillist_open_sdl_window(const char* title, int width, int height, std::string* error) {
  try {
    return new pointillist::SdlWindow(title, width, height);
  } catch (const std::exception& e) {
    *error = e.what();
  } catch (...) {
    *error = "cannot open a window (unknown error)";
  }
  return nullptr;
}
