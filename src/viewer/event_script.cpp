#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "pointillist/core/error.hpp"
#include "pointillist/viewer/input.hpp"

namespace pointillist {
namespace {

constexpr std::size_t kMaxScriptBytes = 1u << 20;
constexpr int kMaxDragFrames = 10000;
constexpr float kMaxCoordinate = 100000.0f;

int button_of(const std::string& name) {
  return name == "left" ? 1 : name == "middle" ? 2 : name == "right" ? 3 : 0;
}

// The words of one line, read in order; every failure names the file and the line.
class LineReader {
 public:
  LineReader(const std::string& path, int line, const std::string& text)
      : path_(path), line_(line) {
    std::istringstream in(text);
    for (std::string w; in >> w;) words_.push_back(w);
  }
  [[noreturn]] void fail(const std::string& what) const {
    throw FormatError(path_ + ":" + std::to_string(line_) + ": " + what +
                      " (see `pointillist view --help` for the script lines)");
  }
  bool more() const { return next_ < words_.size(); }
  std::string word(const char* what) {
    if (!more()) fail(std::string("expected ") + what);
    return words_[next_++];
  }
  double number(const char* what, double lo, double hi) {
    const std::string w = word(what);
    char* end = nullptr;
    const double v = std::strtod(w.c_str(), &end);
    if (end != w.c_str() + w.size() || !std::isfinite(v) || v < lo || v > hi) {
      char range[96];
      std::snprintf(range, sizeof range, " between %g and %g", lo, hi);
      fail(std::string("expected ") + what + range + ", found '" + w + "'");
    }
    return v;
  }
  void done() const {
    if (more()) fail("unexpected '" + words_[next_] + "' at the end of the line");
  }

 private:
  const std::string& path_;
  int line_;
  std::vector<std::string> words_;
  std::size_t next_ = 0;
};

}  // namespace

bool is_key_name(const std::string& n) {
  if (n.size() == 1) return (n[0] >= 'a' && n[0] <= 'z') || (n[0] >= '0' && n[0] <= '9');
  if (n == "plus" || n == "minus" || n == "escape") return true;
  if (n.size() >= 2 && n.size() <= 3 && n[0] == 'f') {
    const int k = std::atoi(n.c_str() + 1);
    return k >= 1 && k <= 12 && std::to_string(k) == n.substr(1);
  }
  return false;
}

std::vector<ScriptStep> read_event_script(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(errno_message("cannot open the event script " + path));
  std::string text;
  text.resize(kMaxScriptBytes + 1);
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  text.resize(static_cast<std::size_t>(in.gcount()));
  if (text.size() > kMaxScriptBytes) {
    throw FormatError(path + ": an event script of more than 1 MiB; is this the right file?");
  }
  std::vector<ScriptStep> steps;
  std::istringstream lines(text);
  std::string line;
  for (int number = 1; std::getline(lines, line); ++number) {
    if (const auto hash = line.find('#'); hash != std::string::npos) line.resize(hash);
    LineReader r(path, number, line);
    if (!r.more()) continue;
    ScriptStep s;
    s.line = number;
    const std::string verb = r.word("an event");
    const auto coordinate = [&](const char* what) {
      return static_cast<float>(r.number(what, -kMaxCoordinate, kMaxCoordinate));
    };
    const auto button = [&] {
      const std::string b = r.word("a button (left, right or middle)");
      if (!button_of(b)) r.fail("expected a button (left, right or middle), found '" + b + "'");
      return button_of(b);
    };
    if (verb == "wait") {
      s.type = ScriptStep::Type::Wait;
      s.wait_ms = r.number("milliseconds", 0, 3.6e6);
    } else if (verb == "settle") {
      s.type = ScriptStep::Type::Settle;
    } else if (verb == "quit") {
      s.type = ScriptStep::Type::Quit;
    } else if (verb == "screenshot") {
      s.type = ScriptStep::Type::Screenshot;
      s.file = r.word("a PNG file name");
    } else if (verb == "key") {
      s.type = ScriptStep::Type::Events;
      const std::string k = r.word("a key name");
      if (!is_key_name(k)) {
        r.fail("unknown key '" + k + "'; keys are a-z, 0-9, plus, minus, escape, f1-f12");
      }
      s.events.push_back({.type = InputEvent::Type::Key, .key = k});
    } else if (verb == "drag") {
      s.type = ScriptStep::Type::Events;
      const int b = button();
      const float x0 = coordinate("X0"), y0 = coordinate("Y0");
      const float x1 = coordinate("X1"), y1 = coordinate("Y1");
      const int frames = r.more() ? static_cast<int>(r.number("FRAMES", 1, kMaxDragFrames)) : 10;
      s.events.push_back({.type = InputEvent::Type::Press, .button = b, .x = x0, .y = y0});
      for (int i = 1; i <= frames; ++i) {
        const float t = static_cast<float>(i) / static_cast<float>(frames);
        s.events.push_back({.type = InputEvent::Type::Motion, .button = b,
                            .x = x0 + (x1 - x0) * t, .y = y0 + (y1 - y0) * t});
      }
      s.events.push_back({.type = InputEvent::Type::Release, .button = b, .x = x1, .y = y1});
    } else if (verb == "wheel") {
      s.type = ScriptStep::Type::Events;
      const float x = coordinate("X"), y = coordinate("Y");
      const float clicks = static_cast<float>(r.number("CLICKS", -1000, 1000));
      s.events.push_back({.type = InputEvent::Type::Wheel, .x = x, .y = y, .wheel = clicks});
    } else if (verb == "click") {
      s.type = ScriptStep::Type::Events;
      const int b = button();
      const float x = coordinate("X"), y = coordinate("Y");
      const int count = r.more() ? static_cast<int>(r.number("COUNT", 1, 2)) : 1;
      s.events.push_back({.type = InputEvent::Type::Press, .button = b, .clicks = count, .x = x, .y = y});
      s.events.push_back({.type = InputEvent::Type::Release, .button = b, .x = x, .y = y});
    } else if (verb == "resize") {
      s.type = ScriptStep::Type::Events;
      const int w = static_cast<int>(r.number("W", 16, 16384));
      const int h = static_cast<int>(r.number("H", 16, 16384));
      s.events.push_back({.type = InputEvent::Type::Resize, .width = w, .height = h});
    } else {
      r.fail("unknown event '" + verb +
             "'; events are wait, settle, key, drag, wheel, click, resize, screenshot, quit");
    }
    r.done();
    steps.push_back(std::move(s));
  }
  return steps;
}

}  // namespace pointillist
