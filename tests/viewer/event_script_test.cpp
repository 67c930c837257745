// Scripted input files: every line form read into the events a person's input would give, and
// every malformed line refused with the file, the line and what was expected.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>

#include "pointillist/core/error.hpp"
#include "pointillist/viewer/input.hpp"
#include "testing/testing.hpp"

using namespace pointillist;
using ::testing::HasSubstr;

namespace {

std::vector<ScriptStep> read_text(const std::string& text) {
  pointillist::testing::TempDir dir;
  std::ofstream(dir.file("s.events"), std::ios::binary) << text;
  return read_event_script(dir.file("s.events"));
}

std::string error_of(const std::string& text) {
  try {
    read_text(text);
  } catch (const FormatError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(EventScript, ReadsEveryLineForm) {
  const auto s = read_text(
      "# a comment\n\nwait 250\nsettle\nkey m  # quality\nkey plus\n"
      "drag left 10 20 110 70 5\nwheel 5 6 -2\nclick right 7 8\nclick left 7 8 2\n"
      "resize 640 480\nscreenshot out.png\nquit\n");
  ASSERT_EQ(s.size(), 11u);
  EXPECT_EQ(s[0].type, ScriptStep::Type::Wait);
  EXPECT_EQ(s[0].wait_ms, 250);
  EXPECT_EQ(s[0].line, 3);
  EXPECT_EQ(s[1].type, ScriptStep::Type::Settle);
  ASSERT_EQ(s[2].events.size(), 1u);
  EXPECT_EQ(s[2].events[0].key, "m");
  EXPECT_EQ(s[3].events[0].key, "plus");
  // A drag: press, FRAMES motions evenly to the end point, release.
  const auto& drag = s[4].events;
  ASSERT_EQ(drag.size(), 7u);
  EXPECT_EQ(drag[0].type, InputEvent::Type::Press);
  EXPECT_EQ(drag[0].button, 1);
  EXPECT_EQ(drag[0].x, 10);
  EXPECT_EQ(drag[1].type, InputEvent::Type::Motion);
  EXPECT_FLOAT_EQ(drag[1].x, 30);
  EXPECT_FLOAT_EQ(drag[1].y, 30);
  EXPECT_FLOAT_EQ(drag[5].x, 110);
  EXPECT_EQ(drag[6].type, InputEvent::Type::Release);
  EXPECT_EQ(s[5].events[0].type, InputEvent::Type::Wheel);
  EXPECT_EQ(s[5].events[0].wheel, -2);
  EXPECT_EQ(s[6].events[0].button, 3);
  EXPECT_EQ(s[6].events[0].clicks, 1);
  EXPECT_EQ(s[7].events[0].clicks, 2);
  EXPECT_EQ(s[8].events[0].type, InputEvent::Type::Resize);
  EXPECT_EQ(s[8].events[0].width, 640);
  EXPECT_EQ(s[9].file, "out.png");
  EXPECT_EQ(s[10].type, ScriptStep::Type::Quit);
}

TEST(EventScript, RefusesMalformedLinesNamingFileAndLine) {
  EXPECT_THAT(error_of("settle\njump 3\n"), HasSubstr("s.events:2: unknown event 'jump'"));
  EXPECT_THAT(error_of("key ctrl\n"), HasSubstr(":1: unknown key 'ctrl'"));
  EXPECT_THAT(error_of("wait -5\n"), HasSubstr(":1: expected milliseconds between 0 and"));
  EXPECT_THAT(error_of("wait\n"), HasSubstr(":1: expected milliseconds"));
  EXPECT_THAT(error_of("drag up 1 2 3 4\n"), HasSubstr("expected a button"));
  EXPECT_THAT(error_of("drag left 1 2 3\n"), HasSubstr("expected Y1"));
  EXPECT_THAT(error_of("drag left 1 2 3 4 99999999\n"), HasSubstr("FRAMES between 1 and 10000"));
  EXPECT_THAT(error_of("wheel 1 2 nan\n"), HasSubstr("expected CLICKS"));
  EXPECT_THAT(error_of("settle now\n"), HasSubstr(":1: unexpected 'now'"));
  EXPECT_THAT(error_of("resize 0 10\n"), HasSubstr("expected W between 16"));
  EXPECT_THROW(read_event_script("/nonexistent/s.events"), IoError);
  EXPECT_THAT(error_of(std::string(2u << 20, '#')), HasSubstr("more than 1 MiB"));
}
