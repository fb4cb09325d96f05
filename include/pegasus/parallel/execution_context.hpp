#pragma once
// Where the work of an evaluation runs: the threads of this process (ThreadPool) and the MPI ranks that split
// it (mpi::Communicator; the collectives themselves are in parallel/mpi.hpp).
#include "pegasus/parallel/thread_pool.hpp"

namespace pegasus::mpi {

// The ranks that split an evaluation's work: the job's (every rank mpirun started, which all make the same
// calls) or this process alone (no collective: this rank computes every item, for work that only this rank
// does, e.g. a different seed on each rank). With one rank both are the same.
class Communicator {
 public:
  static Communicator job() { return Communicator(true); }
  static Communicator this_process() { return Communicator(false); }
  int rank() const;
  int size() const;
  bool operator==(const Communicator&) const = default;

 private:
  explicit Communicator(bool job) : job_(job) {}
  bool job_;
};

}  // namespace pegasus::mpi

namespace pegasus {

// Where the work of an evaluation runs (issue 14: passed to objectives and evaluators, not read from process
// globals): the threads of this process and the MPI ranks that split it. A pool alone converts to a context
// on the job's ranks, which is what every command runs. Results never depend on either (parallel/mpi.hpp).
struct ExecutionContext {
  ThreadPool* pool = nullptr;  // nullptr: the calling thread alone
  mpi::Communicator ranks = mpi::Communicator::job();

  ExecutionContext() = default;
  ExecutionContext(ThreadPool* threads) : pool(threads) {}  // NOLINT(google-explicit-constructor)
  ExecutionContext(ThreadPool* threads, mpi::Communicator among) : pool(threads), ranks(among) {}
};

}  // namespace pegasus
