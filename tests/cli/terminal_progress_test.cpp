// The terminal progress bar: the overall bar with throughput and time left, a phase's detail,
// and lines cut to the terminal's width (read back from a file standing for the terminal).
#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

#include "terminal_progress.hpp"

namespace pointillist::cli {
namespace {

// The lines drawn: the text between carriage returns and newlines, without the erase sequence.
std::vector<std::string> drawn_lines(std::FILE* f) {
  std::fflush(f);
  std::rewind(f);
  std::string all;
  for (int c; (c = std::fgetc(f)) != EOF;) all += char(c);
  std::vector<std::string> lines;
  std::string line;
  for (std::size_t i = 0; i < all.size(); ++i) {
    if (all.compare(i, 3, "\033[K") == 0) {
      i += 2;
      continue;
    }
    if (all[i] == '\r' || all[i] == '\n') {
      if (!line.empty()) lines.push_back(line);
      line.clear();
      if (all[i] == '\n') lines.push_back("<newline>");
      continue;
    }
    line += all[i];
  }
  if (!line.empty()) lines.push_back(line);
  return lines;
}

TEST(TerminalProgress, ShowsTheWholeJobWithItsRateAndTimeLeftAndThePhaseDetail) {
  std::FILE* f = std::tmpfile();
  ASSERT_NE(f, nullptr);
  {
    TerminalProgress p(true, f, 200);
    p.begin_phase("distribute", 1000);
    p.detail("tile_0007.las (7/200)");
    p.overall(300, 1000);
    p.advance(500);  // the first advance draws
    p.end_phase();
  }
  const std::vector<std::string> lines = drawn_lines(f);
  std::fclose(f);
  ASSERT_GE(lines.size(), 3u);
  const std::string& live = lines[0];
  EXPECT_NE(live.find("distribute"), std::string::npos) << live;
  EXPECT_NE(live.find(" 50%"), std::string::npos) << live;      // the phase
  EXPECT_NE(live.find("all ["), std::string::npos) << live;     // the whole job
  EXPECT_NE(live.find(" 30%"), std::string::npos) << live;
  EXPECT_NE(live.find("M points/s"), std::string::npos) << live;
  EXPECT_NE(live.find("left"), std::string::npos) << live;
  EXPECT_NE(live.find("tile_0007.las (7/200)"), std::string::npos) << live;
  // The phase's last line: complete, on its own line, without the live parts.
  EXPECT_NE(lines[lines.size() - 2].find("100%"), std::string::npos);
  EXPECT_EQ(lines[lines.size() - 2].find("tile_0007"), std::string::npos);
  EXPECT_EQ(lines.back(), "<newline>");
}

TEST(TerminalProgress, CutsLinesToTheTerminalWidth) {
  for (const int width : {40, 72}) {
    std::FILE* f = std::tmpfile();
    ASSERT_NE(f, nullptr);
    {
      TerminalProgress p(true, f, width);
      p.begin_phase("prepare", 10);
      p.overall(1, 100);
      p.detail("a_very_long_file_name_from_a_survey_of_many_tiles.las (123/4567)");
      p.advance(1);
      p.end_phase();
    }
    for (const std::string& line : drawn_lines(f)) {
      EXPECT_LE(int(line.size()), width - 1) << line;
    }
    std::fclose(f);
  }
}

TEST(TerminalProgress, DisabledDrawsNothing) {
  std::FILE* f = std::tmpfile();
  ASSERT_NE(f, nullptr);
  {
    TerminalProgress p(false, f, 80);
    p.begin_phase("scan", 10);
    p.overall(5, 10);
    p.advance(10);
    p.end_phase();
  }
  EXPECT_TRUE(drawn_lines(f).empty());
  std::fclose(f);
}

}  // namespace
}  // namespace pointillist::cli
