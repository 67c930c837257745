// The processes that share a chunked conversion (see convert.hpp, ConvertOptions::jobs): this
// process alone, or the ranks of an MPI job (`mpirun -n N pointillist convert ...`). Rank 0
// reads the inputs, plans the chunks, writes the chunk files and lays out and finishes the
// output; every rank prepares, builds and writes into the output the subtrees of the chunks c
// with c % size == rank. The ranks share the output's folder, with the chunk folder and the
// output's temporary file (on a cluster it must be on a file system every rank sees), and
// exchange only small messages: the plan, orientation votes and flips, subtree summaries.
#pragma once

#include <exception>
#include <memory>
#include <vector>

#include "pointillist/core/error.hpp"

namespace pointillist {

// What ChunkJobs::settle throws on the ranks that did not fail themselves (the failing rank
// reports the error; the others may stay quiet).
class PeerFailed : public Error {
 public:
  using Error::Error;
};

class ChunkJobs {
 public:
  virtual ~ChunkJobs() = default;
  virtual int rank() const = 0;
  virtual int size() const = 0;
  // Every rank calls this at the same step with its own failure, or null: when any rank failed,
  // every rank throws (the failing rank its own exception, the others a PeerFailed that quotes
  // the first failing rank's message).
  virtual void settle(std::exception_ptr error) = 0;
  // Rank 0's `bytes` to every rank.
  virtual void broadcast(std::vector<char>& bytes) = 0;
  // Every rank's `bytes`, in rank order, at rank 0 (empty at the others).
  virtual std::vector<std::vector<char>> gather(const std::vector<char>& bytes) = 0;

  // This process alone (the default).
  static ChunkJobs& single();
};

// Whether this build can run chunk jobs on MPI ranks (CMake's POINTILLIST_MPI with OpenMPI).
bool mpi_built();
// Whether this process was started by mpirun in a job of several processes (its environment
// says so; a job of one process runs as if alone).
bool started_by_mpirun();
// Joins the MPI job this process was started in (MPI_Init; MPI_Finalize when destroyed). Throws
// Error when this build has no MPI.
std::unique_ptr<ChunkJobs> join_mpi_job(int* argc, char*** argv);

}  // namespace pointillist
