// `convert --memory`: a conversion in chunks holds its peak resident memory within the budget,
// as the system measures the process (getrusage of a child), not as the program reports it.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <string>

#include "cli/cli_run.hpp"
#include "testing/testing.hpp"

using namespace pointillist;
using pointillist::testing::run_cli;

namespace {

#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define POINTILLIST_TEST_ASAN 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__)
#define POINTILLIST_TEST_ASAN 1
#endif

// Runs `pointillist ARGS` from a forked process and returns the largest resident set (bytes) of
// the processes it waited for, with the exit code; the test's own earlier children do not count.
std::pair<long long, int> peak_of(const std::string& args, const std::string& report) {
  const pid_t child = ::fork();
  if (child == 0) {
    const int code = run_cli(args + " > " + report + ".log").exit_code;
    rusage usage{};
    ::getrusage(RUSAGE_CHILDREN, &usage);
    std::ofstream(report) << (long long)usage.ru_maxrss * 1024 << " " << code << "\n";
    ::_exit(0);
  }
  int status = 0;
  ::waitpid(child, &status, 0);
  long long peak = -1;
  int code = -1;
  std::ifstream(report) >> peak >> code;
  return {peak, code};
}

TEST(ConvertMemoryCli, AConversionInChunksStaysWithinItsBudget) {
#ifdef POINTILLIST_TEST_ASAN
  GTEST_SKIP() << "the sanitizers' shadow memory is not the program's";
#endif
  pointillist::testing::TempDir dir;
  const std::string ply = dir.file("cloud.ply");
  ASSERT_EQ(run_cli("generate --points 1000000 --colors -o " + ply).exit_code, 0);
  // One piece would take about 150 MB (148 bytes a point measured on 5 M points); before the
  // chunk buffers and read batches were sized by the budget, 64M took 82 MB (and before the
  // plan's digit counts and reads were, 24M took 47 MB).
  for (const auto& [budget, bytes] : {std::pair<std::string, long long>{"64M", 64LL << 20},
                                      std::pair<std::string, long long>{"40M", 40LL << 20}}) {
    const auto [peak, code] =
        peak_of("convert " + ply + " -o " + dir.file("a.ptl") + " --memory " + budget,
                dir.file("peak.txt"));
    ASSERT_EQ(code, 0);
    std::ifstream log(dir.file("peak.txt.log"));
    const std::string summary((std::istreambuf_iterator<char>(log)), {});
    EXPECT_NE(summary.find(" chunks"), std::string::npos) << summary;
    EXPECT_GT(peak, 0);
    EXPECT_LE(peak, bytes) << budget << ": " << summary;
    std::printf("[convert --memory %s] 1 M points: peak %.1f MB\n", budget.c_str(),
                double(peak) / 1e6);
  }
}

TEST(ConvertMemoryCli, ABudgetTooSmallToHoldIsRefusedWithTheLeastThatIs) {
  pointillist::testing::TempDir dir;
  const std::string ply = dir.file("cloud.ply");
  ASSERT_EQ(run_cli("generate --points 1000 -o " + ply).exit_code, 0);
  const auto r = run_cli("convert " + ply + " -o " + dir.file("a.ptl") + " --memory 16M");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("--memory 16M is below 40M"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("give --memory 40M or more"), std::string::npos) << r.output;
  EXPECT_FALSE(std::ifstream(dir.file("a.ptl")).good());
}

}  // namespace
