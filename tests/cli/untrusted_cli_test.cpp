// Hostile or careless arguments (issue 15): outputs that would destroy inputs are refused before
// any work, and an absurd thread count is capped with a warning. Oracles: the files' bytes before
// and after, and the exit codes.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "cli/cli_run.hpp"
#include "testing/testing.hpp"

using pointillist::testing::run_cli;
using ::testing::HasSubstr;

namespace {

std::string contents(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace

TEST(UntrustedCli, AnOutputThatWouldReplaceAnInputIsRefusedBeforeAnyWork) {
  pointillist::testing::TempDir dir;
  const std::string a = dir.file("a.ply"), b = dir.file("b.ply");
  ASSERT_EQ(run_cli("generate --points 500 -o " + a).exit_code, 0);
  ASSERT_EQ(run_cli("generate --points 400 --seed 2 -o " + b).exit_code, 0);
  const std::string a_bytes = contents(a), b_bytes = contents(b);
  std::filesystem::create_symlink(a, dir.file("link.png"));
  const std::string png = dir.file("x.png");
  for (const std::string& args :
       {"render " + a + " -o " + a, "render " + a + " -o " + dir.file("link.png"),
        "render " + a + " " + b + " -o " + b, "convert " + a + " -o " + a,
        "convert " + a + " " + b + " -o " + b,
        "render " + a + " -o " + png + " --depth " + png,
        "render " + a + " -o " + png + " --stats " + a}) {
    const auto r = run_cli(args);
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.output;
    EXPECT_THAT(r.output, HasSubstr("pointillist: error: ")) << args;
    EXPECT_THAT(r.output, ::testing::AnyOf(HasSubstr("names an input"),
                                           HasSubstr("is also the output of")))
        << args;
  }
  EXPECT_EQ(contents(a), a_bytes);
  EXPECT_EQ(contents(b), b_bytes);
  EXPECT_FALSE(std::filesystem::exists(png));
}

TEST(UntrustedCli, AHugeThreadCountIsCappedWithAWarning) {
  pointillist::testing::TempDir dir;
  const std::string a = dir.file("a.ply");
  ASSERT_EQ(run_cli("generate --points 500 -o " + a).exit_code, 0);
  const auto r = run_cli("render " + a + " -o " + dir.file("x.png") +
                         " --size 64x48 --threads 100000");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("warning: --threads 100000 is more than 4 per core; using"));
  EXPECT_TRUE(std::filesystem::exists(dir.file("x.png")));
  EXPECT_THAT(run_cli("render --help").output, HasSubstr("4 per core"));
}

TEST(UntrustedCli, MessagesSayWhatIsWrong) {
  pointillist::testing::TempDir dir;
  const std::string a = dir.file("a.ply");
  ASSERT_EQ(run_cli("generate --points 500 -o " + a).exit_code, 0);
  struct Case {
    std::string args, says;
  };
  const Case cases[] = {
      {"frobnicate " + a, "unknown command 'frobnicate'; the commands are convert, render"},
      {"convert " + a + " --frob 3 -o " + dir.file("b.ptl"), "unknown option --frob for 'convert'"},
      {"convert " + a + " -o " + dir.file("b.ptl") + " --radius-scale -1",
       "must be a positive number, found -1"},
      {"render " + a + " -o " + dir.file("x.jpg"), "render writes PNG images"},
      {"render " + a + " -o " + dir.file("x.png") + " --depth " + dir.file("d.tif"),
       "--depth " + dir.file("d.tif") + ": the depth image is a PNG"},
  };
  for (const Case& c : cases) {
    const auto r = run_cli(c.args);
    EXPECT_EQ(r.exit_code, 2) << c.args << "\n" << r.output;
    EXPECT_THAT(r.output, HasSubstr(c.says)) << c.args;
    EXPECT_LT(r.output.size(), 400u) << "a short message, not a number printed in full";
  }
  EXPECT_FALSE(std::filesystem::exists(dir.file("x.jpg")));
  // A .ptl or .qs without its signature is reported by its reader, not as an unknown type.
  for (const char* name : {"bad.ptl", "bad.qs"}) {
    std::ofstream(dir.file(name)) << "not a model at all";
    const auto r = run_cli("info " + dir.file(name));
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_THAT(r.output, ::testing::Not(HasSubstr("unknown point file type"))) << name;
  }
}
