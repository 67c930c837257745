// AtomicFile's promises about what a killed or failed write leaves behind, and check_outputs'
// refusal of outputs that would destroy inputs. Oracles: the folder's listing and the files'
// bytes, made by the test itself.
#include <gtest/gtest.h>
#include <sys/file.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "pointillist/core/atomic_file.hpp"
#include "pointillist/core/error.hpp"
#include "testing/testing.hpp"

using namespace pointillist;
namespace fs = std::filesystem;

namespace {

std::vector<std::string> listing(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

std::string contents(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace

TEST(AtomicFile, ASignalDuringTheWriteLeavesNoTemporaryFile) {
  pointillist::testing::TempDir dir;
  const std::string out = dir.file("out.ptl");
  for (int signal : {SIGTERM, SIGINT}) {
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      remove_temporary_files_on_signals();
      AtomicFile f(out);
      f.write("half a model");
      std::raise(signal);  // as if the user pressed Ctrl-C or the job was stopped
      _exit(0);            // not reached: the handler ends the process with the signal
    }
    int status = 0;
    ASSERT_EQ(waitpid(child, &status, 0), child);
    EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == signal);
    EXPECT_TRUE(listing(dir.path()).empty()) << "signal " << signal;
  }
}

TEST(AtomicFile, AFullDiskNamesTheOutputAndLeavesNothing) {
  // The disk fills during the write: a file-size limit makes write() fail the same way (EFBIG
  // instead of ENOSPC), in a child so the limit stays there.
  pointillist::testing::TempDir dir;
  const std::string out = dir.file("model.ptl");
  int pipe_fds[2];
  ASSERT_EQ(pipe(pipe_fds), 0);
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    close(pipe_fds[0]);
    std::signal(SIGXFSZ, SIG_IGN);
    const rlimit limit{4096, 4096};
    setrlimit(RLIMIT_FSIZE, &limit);
    std::string message = "no error";
    try {
      AtomicFile f(out);
      const std::string block(1 << 16, 'x');
      for (int i = 0; i < 16; ++i) f.write(block);
      f.commit();
    } catch (const IoError& e) {
      message = e.what();
    }
    [[maybe_unused]] const auto n = ::write(pipe_fds[1], message.data(), message.size());
    _exit(0);
  }
  close(pipe_fds[1]);
  std::string message;
  char buf[512];
  for (ssize_t n; (n = read(pipe_fds[0], buf, sizeof buf)) > 0;) message.append(buf, std::size_t(n));
  close(pipe_fds[0]);
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  EXPECT_NE(message.find("cannot write " + out), std::string::npos) << message;
  EXPECT_NE(message.find(".tmp-"), std::string::npos) << message;  // and its temporary file
  EXPECT_NE(message.find("too large"), std::string::npos) << message;  // the system's reason
  EXPECT_TRUE(listing(dir.path()).empty()) << "a partial output or temporary file was left";
}

TEST(AtomicFile, TheNextWriteRemovesStaleTemporariesButNotLiveOnes) {
  pointillist::testing::TempDir dir;
  const std::string out = dir.file("out.ptl");
  // A temporary left by a process killed with -9 (nobody holds it), and one a live writer holds.
  { std::ofstream(out + ".tmp-dead01") << "stale"; }
  { std::ofstream(out + ".tmp-live01") << "in progress"; }
  { std::ofstream(dir.file("other.ptl.tmp-abcdef")) << "another output's"; }
  const int live = ::open((out + ".tmp-live01").c_str(), O_RDONLY);
  ASSERT_GE(live, 0);
  ASSERT_EQ(::flock(live, LOCK_EX), 0);
  {
    AtomicFile f(out);
    f.write("model");
    f.commit();
  }
  ::close(live);
  EXPECT_EQ(listing(dir.path()),
            (std::vector<std::string>{"other.ptl.tmp-abcdef", "out.ptl", "out.ptl.tmp-live01"}));
  EXPECT_EQ(contents(out), "model");
}

TEST(CheckOutputs, RefusesAnOutputThatNamesAnInputOrAnotherOutput) {
  pointillist::testing::TempDir dir;
  const std::string scan = dir.file("scan.ply");
  { std::ofstream(scan) << "ply"; }
  fs::create_symlink(scan, dir.file("link.ply"));
  const auto message = [&](const std::vector<std::string>& in,
                           const std::vector<std::pair<std::string, std::string>>& out) {
    try {
      check_outputs(in, out);
    } catch (const OptionError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(message({scan}, {{"-o", scan}}).find("-o " + scan + " names an input"),
            std::string::npos);
  // The same file by another name: through a link, and with "..".
  EXPECT_NE(message({scan}, {{"-o", dir.file("link.ply")}}), "");
  EXPECT_NE(message({dir.file("link.ply")}, {{"-o", scan}}), "");
  EXPECT_NE(message({scan}, {{"-o", dir.file("sub/../scan.ply")}}), "");
  // Any input of a merge.
  EXPECT_NE(message({dir.file("a.ply"), scan}, {{"-o", scan}}), "");
  // Two outputs on one path.
  EXPECT_NE(message({scan}, {{"-o", dir.file("a.png")}, {"--depth", dir.file("a.png")}})
                .find("--depth " + dir.file("a.png") + " is also the output of -o"),
            std::string::npos);
  // Distinct paths, "-" (stdout) and unset outputs are fine.
  EXPECT_EQ(message({scan}, {{"-o", dir.file("a.png")}, {"--depth", dir.file("d.png")},
                             {"--stats", "-"}, {"--json", ""}}),
            "");
  EXPECT_EQ(contents(scan), "ply");
}
