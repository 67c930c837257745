// The viewer's input: events from the window or from a scripted input file (--events FILE), in
// one form, so a script drives the viewer exactly as a person does.
//
// Script files (one event a line; '#' starts a comment; coordinates in window pixels):
//   wait MS                        let MS milliseconds pass (frames keep coming)
//   settle                         wait until the view is at full detail with every page loaded
//   key NAME                       press a key: a-z, 0-9, plus, minus, escape, f1-f12
//   drag left|right|middle X0 Y0 X1 Y1 [FRAMES]
//                                  press at (X0, Y0), move to (X1, Y1) over FRAMES frames
//                                  (default 10), release
//   wheel X Y CLICKS               turn the wheel at (X, Y); positive CLICKS zoom in
//   click left|right|middle X Y [COUNT]   COUNT = 2 is a double click
//   resize W H                     resize the window
//   screenshot FILE                write the frame on screen as PNG, print its render command
//   quit                           close the window (the end of the file quits too)
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace pointillist {

struct InputEvent {
  enum class Type { Key, Press, Release, Motion, Wheel, Resize, Quit };
  Type type = Type::Quit;
  std::string key;     // Key: the key's name as in script files
  int button = 0;      // Press/Release: 1 left, 2 middle, 3 right
  int clicks = 1;      // Press: 2 for a double click
  float x = 0, y = 0;  // Press/Release/Motion/Wheel: cursor position
  float wheel = 0;     // Wheel: clicks, positive away from the user (zoom in)
  int width = 0, height = 0;  // Resize
};

// One line of a script file.
struct ScriptStep {
  enum class Type { Wait, Settle, Events, Screenshot, Quit };
  Type type = Type::Quit;
  double wait_ms = 0;               // Wait
  std::vector<InputEvent> events;   // Events: delivered one per frame (a drag's motion steps)
  std::string file;                 // Screenshot
  int line = 0;
};

// Reads a script file. Throws IoError when it cannot be read, FormatError naming the file, the
// line and what was expected for a line that is not one of the forms above (or a file over
// 1 MiB, or a drag of more than 10,000 frames).
std::vector<ScriptStep> read_event_script(const std::string& path);

// Whether `name` is a key name of script files.
bool is_key_name(const std::string& name);

}  // namespace pointillist
