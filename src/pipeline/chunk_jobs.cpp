// ChunkJobs (see chunk_jobs.hpp): this process alone, and the ranks of an MPI job when built
// with MPI (POINTILLIST_HAVE_MPI).
#include "pointillist/pipeline/chunk_jobs.hpp"

#include <algorithm>
#include <climits>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "pointillist/core/error.hpp"

#ifdef POINTILLIST_HAVE_MPI
#include <mpi.h>
#endif

namespace pointillist {
namespace {

class SingleProcess final : public ChunkJobs {
 public:
  int rank() const override { return 0; }
  int size() const override { return 1; }
  void settle(std::exception_ptr error) override {
    if (error) std::rethrow_exception(error);
  }
  void broadcast(std::vector<char>&) override {}
  std::vector<std::vector<char>> gather(const std::vector<char>& bytes) override {
    return {bytes};
  }
};

#ifdef POINTILLIST_HAVE_MPI

void check(int code, const char* what) {
  if (code != MPI_SUCCESS) {
    char text[MPI_MAX_ERROR_STRING];
    int length = 0;
    MPI_Error_string(code, text, &length);
    throw Error(std::string("MPI: ") + what + " failed: " + std::string(text, std::size_t(length)) +
                "; check that every rank is running and can reach the others");
  }
}

class MpiJob final : public ChunkJobs {
 public:
  MpiJob(int* argc, char*** argv) {
    int initialized = 0;
    MPI_Initialized(&initialized);
    if (!initialized) {
      check(MPI_Init(argc, argv), "MPI_Init");
      owns_ = true;
    }
    // Errors come back as codes (and become exceptions), not aborts.
    MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
    piece_ = std::uint64_t(INT_MAX / size_);
    // Tests make the gather's rounds small with POINTILLIST_MPI_PIECE_BYTES (every rank must
    // see the same value; mpirun -x passes it on).
    if (const char* v = std::getenv("POINTILLIST_MPI_PIECE_BYTES")) {
      const long long bytes = std::atoll(v);
      if (bytes > 0) piece_ = std::min(piece_, std::uint64_t(bytes));
    }
  }
  ~MpiJob() override {
    if (owns_) MPI_Finalize();
  }
  int rank() const override { return rank_; }
  int size() const override { return size_; }

  void settle(std::exception_ptr error) override {
    const int failed = error ? 1 : 0;
    std::vector<int> flags(std::size_t(size_), 0);
    check(MPI_Allgather(&failed, 1, MPI_INT, flags.data(), 1, MPI_INT, MPI_COMM_WORLD),
          "MPI_Allgather");
    int first = -1;
    for (int r = 0; r < size_ && first < 0; ++r) {
      if (flags[std::size_t(r)]) first = r;
    }
    if (first < 0) return;
    std::vector<char> message;
    if (rank_ == first) {
      try {
        std::rethrow_exception(error);
      } catch (const std::exception& e) {
        const std::string what = e.what();
        message.assign(what.begin(), what.end());
      } catch (...) {
        const std::string what = "an unknown failure";
        message.assign(what.begin(), what.end());
      }
    }
    broadcast_from(first, message);
    if (error) std::rethrow_exception(error);
    throw PeerFailed("rank " + std::to_string(first) + " of the MPI job failed: " +
                std::string(message.begin(), message.end()));
  }

  void broadcast(std::vector<char>& bytes) override { broadcast_from(0, bytes); }

  std::vector<std::vector<char>> gather(const std::vector<char>& bytes) override {
    // Every rank learns every size, then all take part in the same rounds of at most
    // INT_MAX / size bytes a rank (MPI counts and offsets are int), so no message size makes
    // one rank leave the collectives the others wait in.
    const std::uint64_t size = bytes.size();
    std::vector<std::uint64_t> sizes(std::size_t(size_), 0);
    check(MPI_Allgather(&size, 1, MPI_UINT64_T, sizes.data(), 1, MPI_UINT64_T, MPI_COMM_WORLD),
          "MPI_Allgather");
    const std::uint64_t piece = piece_;
    const std::uint64_t largest = *std::max_element(sizes.begin(), sizes.end());
    std::vector<std::vector<char>> out;
    if (rank_ == 0) {
      out.resize(std::size_t(size_));
      for (int r = 0; r < size_; ++r) out[std::size_t(r)].resize(sizes[std::size_t(r)]);
    }
    std::vector<int> counts(std::size_t(size_), 0), offsets(std::size_t(size_), 0);
    std::vector<char> round;
    const auto part = [&](std::uint64_t total, std::uint64_t at) {
      return int(std::min(piece, total - std::min(total, at)));
    };
    for (std::uint64_t at = 0; at < largest; at += piece) {
      int total = 0;
      for (int r = 0; r < size_; ++r) {
        counts[std::size_t(r)] = part(sizes[std::size_t(r)], at);
        offsets[std::size_t(r)] = total;
        total += counts[std::size_t(r)];
      }
      if (rank_ == 0) round.resize(std::size_t(total));
      check(MPI_Gatherv(bytes.data() + std::min(size, at), part(size, at), MPI_CHAR, round.data(),
                        counts.data(), offsets.data(), MPI_CHAR, 0, MPI_COMM_WORLD),
            "MPI_Gatherv");
      if (rank_ != 0) continue;
      for (int r = 0; r < size_; ++r) {
        if (counts[std::size_t(r)] == 0) continue;
        const char* begin = round.data() + offsets[std::size_t(r)];
        std::copy(begin, begin + counts[std::size_t(r)], out[std::size_t(r)].data() + at);
      }
    }
    return out;
  }

 private:
  void broadcast_from(int root, std::vector<char>& bytes) {
    std::uint64_t size = bytes.size();
    check(MPI_Bcast(&size, 1, MPI_UINT64_T, root, MPI_COMM_WORLD), "MPI_Bcast");
    bytes.resize(std::size_t(size));
    for (std::uint64_t at = 0; at < size;) {
      const int part = int(std::min<std::uint64_t>(size - at, std::uint64_t{1} << 30));
      check(MPI_Bcast(bytes.data() + at, part, MPI_CHAR, root, MPI_COMM_WORLD), "MPI_Bcast");
      at += std::uint64_t(part);
    }
  }

  int rank_ = 0, size_ = 1;
  std::uint64_t piece_ = 0;  // bytes a rank sends in one round of gather()
  bool owns_ = false;
};

#endif

}  // namespace

ChunkJobs& ChunkJobs::single() {
  static SingleProcess single;
  return single;
}

bool mpi_built() {
#ifdef POINTILLIST_HAVE_MPI
  return true;
#else
  return false;
#endif
}

bool started_by_mpirun() {
  if (const char* size = std::getenv("OMPI_COMM_WORLD_SIZE")) return std::string(size) != "1";
  return std::getenv("PMIX_RANK") != nullptr || std::getenv("PMI_RANK") != nullptr;
}

std::unique_ptr<ChunkJobs> join_mpi_job([[maybe_unused]] int* argc,
                                        [[maybe_unused]] char*** argv) {
#ifdef POINTILLIST_HAVE_MPI
  return std::make_unique<MpiJob>(argc, argv);
#else
  throw Error("this pointillist was built without MPI; install OpenMPI (scripts/setup.sh) and "
              "rebuild to run convert under mpirun");
#endif
}

}  // namespace pointillist
