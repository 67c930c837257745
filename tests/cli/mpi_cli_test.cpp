// `mpirun -n 2 --oversubscribe pointillist convert ...`: the chunk jobs shared by two ranks give
// the file one process writes with the same options, byte for byte; a rank that fails stops the
// whole job with one message and leaves nothing behind. Skipped (with the reason) in a build
// without MPI or on a machine without mpirun.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>

#include "cli/cli_run.hpp"
#include "pointillist/io/ply.hpp"
#include "pointillist/pipeline/chunk_jobs.hpp"
#include "pointillist/scene/analytic.hpp"
#include "testing/testing.hpp"
#include "testing/torus_mesh.hpp"

namespace pointillist {
namespace {

using ::testing::HasSubstr;
using testing::CliResult;
using testing::TempDir;

std::string file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// mpirun with two ranks on this machine (as root too), the sanitizers' leak check off for
// OpenMPI's own allocations.
CliResult mpirun2(const std::string& args, const std::string& env = "") {
  return testing::run_shell(
      "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 ASAN_OPTIONS=detect_leaks=0 "
      "mpirun -n 2 --oversubscribe -x ASAN_OPTIONS " +
      (env.empty() ? std::string() : "-x " + env + " ") + std::string(POINTILLIST_CLI_PATH) +
      " " + args);
}

bool skip_without_mpi() {
  if (!mpi_built()) return true;
  return testing::run_shell("command -v mpirun").exit_code != 0;
}

std::string write_cloud(const TempDir& dir, std::size_t count) {
  PointSet p = sample_scene(demo_scene(), count, 5).points;
  for (const Vec3f& x : p.positions) {
    p.colors.push_back({std::uint8_t(128 + 60 * x.x), std::uint8_t(100 + 50 * x.y), 90});
  }
  const std::string path = dir.file("cloud.ply");
  write_ply(path, p);
  return path;
}

// Converts `input` with `options` in one process (two threads) and under mpirun (one thread a
// rank); expects both to succeed with the same bytes and no chunk folder left. Returns mpirun's
// output.
std::string expect_two_ranks_write_one_process_bytes(const TempDir& dir, const std::string& input,
                                                     const std::string& options,
                                                     const std::string& env = "") {
  const std::string one = dir.file("one.ptl"), two = dir.file("two.ptl");
  const CliResult a =
      testing::run_cli("convert " + input + " -o " + one + options + " --threads 2");
  EXPECT_EQ(a.exit_code, 0) << a.output;
  const CliResult b = mpirun2("convert " + input + " -o " + two + options + " --threads 1", env);
  EXPECT_EQ(b.exit_code, 0) << b.output;
  const std::string bytes_one = file_bytes(one);
  EXPECT_GT(bytes_one.size(), 1000u);
  EXPECT_TRUE(bytes_one == file_bytes(two)) << "the files differ";
  EXPECT_FALSE(std::filesystem::exists(two + ".chunks"));
  return b.output;
}

TEST(MpiConvert, TwoRanksWriteTheBytesOfOneProcess) {
  if (skip_without_mpi()) GTEST_SKIP() << "this build has no MPI, or mpirun is not installed";
  TempDir dir;
  const std::string output =
      expect_two_ranks_write_one_process_bytes(dir, write_cloud(dir, 40000), " --chunk-points 2000");
  // Rank 0 speaks for the job: one summary.
  EXPECT_THAT(output, HasSubstr("on 2 MPI ranks"));
  EXPECT_EQ(output.find("converted"), output.rfind("converted")) << output;
}

TEST(MpiConvert, TwoRanksConvertAMeshToTheBytesOfOneProcess) {
  // Rank 0 turns the mesh into points in the chunk folder; both ranks prepare chunks.
  if (skip_without_mpi()) GTEST_SKIP() << "this build has no MPI, or mpirun is not installed";
  TempDir dir;
  const std::string mesh = dir.file("torus.ply");
  write_ply(mesh, testing::torus_mesh(120, 60));
  const std::string output =
      expect_two_ranks_write_one_process_bytes(dir, mesh, " --chunk-points 1000");
  EXPECT_THAT(output, HasSubstr("on 2 MPI ranks"));
  EXPECT_THAT(output, HasSubstr("faces are not kept"));
}

TEST(MpiConvert, TwoRanksDropTheOutliersOfOneProcess) {
  // The outlier pass runs on both ranks and rank 0 gathers their verdicts.
  if (skip_without_mpi()) GTEST_SKIP() << "this build has no MPI, or mpirun is not installed";
  TempDir dir;
  const std::string output = expect_two_ranks_write_one_process_bytes(
      dir, write_cloud(dir, 30000), " --chunk-points 2000 --drop-outliers");
  EXPECT_THAT(output, HasSubstr("outliers of 30000 points"));
}

TEST(MpiConvert, TwoRanksFindTheSharpFeaturesOfOneProcess) {
  // Both ranks find the features of their parts of the file rank 0 wrote; rank 0 joins them.
  // Their surfaces and links reach rank 0 in rounds of at most 1000 bytes a rank (as messages
  // over 2 GB would in rounds of 1 GB).
  if (skip_without_mpi()) GTEST_SKIP() << "this build has no MPI, or mpirun is not installed";
  TempDir dir;
  const std::string output = expect_two_ranks_write_one_process_bytes(
      dir, write_cloud(dir, 30000), " --chunk-points 2000 --features",
      "POINTILLIST_MPI_PIECE_BYTES=1000");
  EXPECT_THAT(output, HasSubstr("features"));
}

TEST(MpiConvert, AFailingRankStopsEveryRankWithOneMessageAndLeavesNothing) {
  if (skip_without_mpi()) GTEST_SKIP() << "this build has no MPI, or mpirun is not installed";
  TempDir dir;
  // Rank 0 finds a non-finite position while rank 1 waits for the plan.
  PointSet p = sample_scene(demo_scene(), 20000, 5).points;
  p.positions[12345].y = std::numeric_limits<float>::quiet_NaN();
  const std::string cloud = dir.file("bad.ply");
  write_ply(cloud, p);
  const std::string out = dir.file("out.ptl");
  const CliResult r = mpirun2("convert " + cloud + " -o " + out + " --chunk-points 2000");
  EXPECT_NE(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("vertex 12345 of 20000: property y is not a finite number"));
  EXPECT_EQ(r.output.find("vertex 12345"), r.output.rfind("vertex 12345")) << r.output;
  EXPECT_FALSE(std::filesystem::exists(out));
  EXPECT_FALSE(std::filesystem::exists(out + ".chunks"));
}

TEST(MpiConvert, OtherCommandsAreRefusedUnderMpirun) {
  if (skip_without_mpi()) GTEST_SKIP() << "this build has no MPI, or mpirun is not installed";
  const CliResult r = mpirun2("info /nonexistent.ptl");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_THAT(r.output, HasSubstr("only `convert` runs under mpirun"));
}

}  // namespace
}  // namespace pointillist
