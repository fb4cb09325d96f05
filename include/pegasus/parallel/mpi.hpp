#pragma once
// Distributed evaluation on MPI (Open MPI), hidden behind the evaluators (thesis §5.3: the scenarios of one
// evaluation run on different computers and the results are aggregated).
//
// `mpirun -np N pegasus <command> ...` starts N copies of the same program. Every rank runs the whole command
// redundantly (the optimizer included) on identical numbers; only the work that dominates, the (theta,
// scenario) rollouts, is split. Item k of a collective fill belongs to rank k mod N (a fixed ownership that
// does not depend on timing); each rank computes its items on its own thread pool, an allgather copies every
// item's double to every rank bit for bit, and every rank then reduces in item order exactly as one process
// does. So results are bit-identical for any N and any thread count, and resuming with another N is
// resuming the same computation. Only rank 0 writes the run directory and draws progress bars
// (runs/run_directory.cpp, runs/progress.cpp); the other ranks' stdout and stderr are silent except for
// their own failures.
//
//   std::vector<double> returns(thetas.size() * m);
//   mpi::distributed_fill(returns, pool, [&](std::size_t k) { return rollout(k / m, k % m); });
//   // every rank now holds all returns; sum them in order
//
// The ranks an evaluation is split among are its ExecutionContext's (parallel/execution_context.hpp): the
// job's, or this process alone (no collective), which a rank uses for work that only it does.
//
// Collectives must be entered by every rank in the same order. distributed_fill only communicates when
// called on the main thread outside any ThreadPool::parallel_for body; elsewhere (a worker thread, a nested
// call) it computes every item locally, which gives the same numbers.
//
// The ranks talk through a Transport: Open MPI's comes in the pegasus::mpi component
// (pegasus/parallel/open_mpi.hpp), which a program hands to its Session. Without one (pegasus::core alone, a
// build with PEGASUS_MPI=OFF, or a process not started by mpirun) there is one rank and nothing here
// communicates; the same code paths run.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "pegasus/parallel/execution_context.hpp"
#include "pegasus/parallel/thread_pool.hpp"

namespace pegasus::mpi {

// How the ranks of a job exchange data. The collectives below call it only when the job has several ranks, on
// the main thread; every rank makes the same calls in the same order.
class Transport {
 public:
  virtual ~Transport() = default;
  virtual int rank() const = 0;
  virtual int size() const = 0;
  // Every rank's `mine`, concatenated in rank order into `all`; counts[r] values of rank r start at
  // displacements[r].
  virtual void allgatherv(std::span<const double> mine, std::span<double> all, std::span<const int> counts,
                          std::span<const int> displacements) = 0;
  // Rank 0's bytes on every rank (`bytes` is sized alike on every rank).
  virtual void broadcast(std::span<char> bytes) = 0;
  virtual void broadcast(std::uint64_t& value) = 0;
  // Every rank's value, indexed by rank.
  virtual void allgather(int value, std::span<int> all) = 0;
  virtual void barrier() = 0;
  // Stops every rank of the job with exit status `code`.
  [[noreturn]] virtual void abort(int code) = 0;
};

// Joins the job a launcher started this process in (open_mpi::join, from the pegasus::mpi component).
using TransportStart = std::unique_ptr<Transport> (*)(int* argc, char*** argv);

// Joins the job when the process was launched by mpirun (or srun), through `join`, and leaves it when
// destroyed. Make one, at the top of main. Without a launcher nothing is started (no start-up cost). Without
// a way to join (join == nullptr: pegasus::core alone, or a build without MPI), a process started by `mpirun
// -np N` with N > 1 prints one line on the first rank and exits(2): N independent copies would each run the
// whole job into the same run directory.
class Session {
 public:
  Session(int* argc, char*** argv, TransportStart join);
  ~Session();
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;
};

int rank();
int size();
inline bool is_root() { return rank() == 0; }

// The items of n that one rank owns: rank, rank + size, rank + 2 size, ...
struct Share {
  int rank = 0;
  int size = 1;
  std::size_t count(std::size_t n) const {
    const auto r = static_cast<std::size_t>(rank), s = static_cast<std::size_t>(size);
    return n > r ? (n - r + s - 1) / s : 0;
  }
  std::size_t item(std::size_t j) const {
    return static_cast<std::size_t>(rank) + j * static_cast<std::size_t>(size);
  }
};

// This rank's share of `ranks`' work when a collective may run here (more than one rank, the main thread,
// outside any parallel_for body); otherwise the whole, {0, 1}.
Share collective_share(const Communicator& ranks);

// Collective over all ranks: on entry every rank has filled values[k] for the k of its share; on return every
// rank holds every value, bit for bit. No-op when share.size == 1.
void allgather_shares(std::span<double> values, const Share& share);

// out[k] = value(k) for every k, on every rank of where.ranks: each rank computes its share (on where.pool
// when given), then allgather_shares. value must be deterministic in k.
template <class Value>
void distributed_fill(std::span<double> out, const ExecutionContext& where, Value&& value) {
  const Share share = collective_share(where.ranks);
  ThreadPool* pool = where.pool;
  const std::size_t owned = share.count(out.size());
  auto body = [&](std::size_t j) {
    const std::size_t k = share.item(j);
    out[k] = value(k);
  };
  if (pool) {
    pool->parallel_for(owned, body);
  } else {
    for (std::size_t j = 0; j < owned; ++j) body(j);
  }
  allgather_shares(out, share);
}

// Collective: rank 0's text on every rank (returns `text` itself with one rank).
std::string broadcast_from_root(const std::string& text);

// Collective: every rank's value, indexed by rank (with one rank: {value}).
std::vector<int> allgather_int(int value);

// Collective: returns once every rank has called it (nothing with one rank).
void barrier();

// Ends the whole job at once with exit status `code` (MPI_Abort: every rank is stopped). Only meaningful with
// size() > 1; with one rank it is std::exit(code).
[[noreturn]] void abort_job(int code);

// The line rank 0 writes to stderr when the job is stopped from outside (another rank died, or mpirun was
// interrupted): mpirun then sends it SIGTERM. Set by the CLI to name the run directory to resume.
void set_stop_message(const std::string& line);
// Rank 0 has said why the job ends: when mpirun then stops it (another rank exited first), no second line.
void stop_message_said();
// For a Transport whose collective failed (a peer died before the launcher's SIGTERM arrived): rank 0 writes
// the stop line, and the process ends; the launcher ends the rest.
[[noreturn]] void stop_after_failed_collective();

// Time and volume of the allgathers of this process, for benchmarks.
struct CommStats {
  std::int64_t calls = 0;
  std::int64_t bytes = 0;     // bytes received per rank (all ranks' doubles)
  double seconds = 0.0;       // in MPI_Allgatherv (after the barrier when measure_wait is on)
  double wait_seconds = 0.0;  // in the barrier before it (load imbalance), when measure_wait is on
};
CommStats comm_stats();
void reset_comm_stats();
// When on, every allgather is preceded by a timed barrier, so that `seconds` is the transfer alone and
// `wait_seconds` the waiting for the slowest rank. Benchmarks only: the barrier costs a round trip.
void set_measure_wait(bool on);

}  // namespace pegasus::mpi
