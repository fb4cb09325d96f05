#include "pegasus/parallel/mpi.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string_view>
#include <thread>

#ifdef PEGASUS_HAVE_MPI
#ifndef OMPI_SKIP_MPICXX
#define OMPI_SKIP_MPICXX 1
#endif
#include <mpi.h>
#endif

namespace pegasus::mpi {

namespace {

int g_rank = 0;
int g_size = 1;
[[maybe_unused]] bool g_started = false;  // MPI_Init_thread was called by this process
std::thread::id g_main_thread;
CommStats g_stats;
bool g_measure_wait = false;

// Test-only fault injection (PEGASUS_TEST_MPI_KILL="RANK:CALLS"): rank RANK kills itself with SIGKILL when it
// enters its CALLS-th allgather, as a crashed node would. Not documented for users.
int g_kill_rank = -1;
std::int64_t g_kill_after = 0;

// The stop line for SIGTERM, in static storage so that the handler only calls write(2).
char g_stop_line[1024] = "pegasus: error: the MPI job was stopped (a rank failed or the job was killed)\n";

extern "C" void on_stop_signal(int) {
  const ssize_t ignored = ::write(STDERR_FILENO, g_stop_line, std::strlen(g_stop_line));
  (void)ignored;
  ::_exit(1);
}

// Whether a launcher started this process as one rank of a job: 0 when not, else the job's size as far as
// the environment tells (1 when only a rank is given; MPI_Init then tells the truth).
int launched_size() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE"})
    if (const char* v = std::getenv(name)) return std::max(1, std::atoi(v));
  if (std::getenv("PMIX_RANK") || std::getenv("PMI_RANK")) return 1;
  return 0;
}

// A collective that failed: a peer died (its connection broke before the launcher's SIGTERM arrived). Rank 0
// says the stop line, as the SIGTERM handler would have, and every rank ends; the launcher ends the rest.
#ifdef PEGASUS_HAVE_MPI
void check_collective(int rc) {
  if (rc == MPI_SUCCESS) return;
  if (g_rank == 0) on_stop_signal(0);
  ::_exit(1);
}
#endif

[[maybe_unused]] int launched_rank() {
  for (const char* name : {"OMPI_COMM_WORLD_RANK", "PMI_RANK", "PMIX_RANK"})
    if (const char* v = std::getenv(name)) return std::atoi(v);
  return 0;
}

[[maybe_unused]] void read_fault_injection() {
  const char* v = std::getenv("PEGASUS_TEST_MPI_KILL");
  if (!v) return;
  int rank = -1;
  long long calls = 0;
  if (std::sscanf(v, "%d:%lld", &rank, &calls) == 2 && calls > 0) {
    g_kill_rank = rank;
    g_kill_after = calls;
  }
}

[[maybe_unused]] double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

#ifdef PEGASUS_HAVE_MPI
bool compiled_with_mpi() { return true; }
#else
bool compiled_with_mpi() { return false; }
#endif

Session::Session([[maybe_unused]] int* argc, [[maybe_unused]] char*** argv) {
  g_main_thread = std::this_thread::get_id();
  const int launched = launched_size();
  if (launched == 0) return;
#ifdef PEGASUS_HAVE_MPI
  int provided = 0;
  // Only the main thread calls MPI; the thread pools never do.
  if (MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS) {
    std::fprintf(stderr, "pegasus: error: MPI could not start\n");
    std::exit(1);
  }
  g_started = true;
  MPI_Comm_rank(MPI_COMM_WORLD, &g_rank);
  MPI_Comm_size(MPI_COMM_WORLD, &g_size);
  read_fault_injection();
  // Failures of collectives come back as codes (check_collective) instead of Open MPI's own abort, which
  // would end rank 0 without the stop line.
  MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
  if (g_size > 1 && g_rank == 0) std::signal(SIGTERM, on_stop_signal);
#else
  if (launched > 1) {
    if (launched_rank() == 0)
      std::fprintf(
          stderr,
          "pegasus: this build has no MPI (configured with PEGASUS_MPI=OFF or without Open MPI): under "
          "mpirun -np %d every process would run the whole job alone; rebuild with Open MPI "
          "(libopenmpi-dev) or run without mpirun\n",
          launched);
    std::exit(2);
  }
#endif
}

Session::~Session() {
#ifdef PEGASUS_HAVE_MPI
  if (g_started) {
    int finalized = 0;
    MPI_Finalized(&finalized);
    if (!finalized) MPI_Finalize();
  }
#endif
}

int rank() { return g_rank; }
int size() { return g_size; }

int Communicator::rank() const { return job_ ? g_rank : 0; }
int Communicator::size() const { return job_ ? g_size : 1; }

Share collective_share(const Communicator& ranks) {
  if (ranks.size() == 1 || std::this_thread::get_id() != g_main_thread || ThreadPool::inside_parallel_for())
    return {};
  return {g_rank, g_size};
}

void allgather_shares([[maybe_unused]] std::span<double> values, const Share& share) {
  if (share.size == 1) return;
#ifdef PEGASUS_HAVE_MPI
  if (share.size != g_size || share.rank != g_rank)
    throw std::logic_error("allgather_shares: not this rank's share");
  ++g_stats.calls;
  if (g_kill_rank == g_rank && g_stats.calls >= g_kill_after) std::raise(SIGKILL);
  const std::size_t n = values.size();
  // Pack this rank's items, gather every rank's block, then put each item back at its index.
  std::vector<int> counts(static_cast<std::size_t>(g_size)), displs(static_cast<std::size_t>(g_size));
  int offset = 0;
  for (int r = 0; r < g_size; ++r) {
    const Share s{r, g_size};
    counts[static_cast<std::size_t>(r)] = static_cast<int>(s.count(n));
    displs[static_cast<std::size_t>(r)] = offset;
    offset += counts[static_cast<std::size_t>(r)];
  }
  std::vector<double> mine(share.count(n)), all(n);
  for (std::size_t j = 0; j < mine.size(); ++j) mine[j] = values[share.item(j)];
  if (g_measure_wait) {
    const double start = now_seconds();
    check_collective(MPI_Barrier(MPI_COMM_WORLD));
    g_stats.wait_seconds += now_seconds() - start;
  }
  const double start = now_seconds();
  const int rc = MPI_Allgatherv(mine.data(), static_cast<int>(mine.size()), MPI_DOUBLE, all.data(),
                                counts.data(), displs.data(), MPI_DOUBLE, MPI_COMM_WORLD);
  g_stats.seconds += now_seconds() - start;
  g_stats.bytes += static_cast<std::int64_t>(n * sizeof(double));
  check_collective(rc);
  for (int r = 0; r < g_size; ++r) {
    const Share s{r, g_size};
    const double* block = all.data() + displs[static_cast<std::size_t>(r)];
    for (std::size_t j = 0; j < static_cast<std::size_t>(counts[static_cast<std::size_t>(r)]); ++j)
      values[s.item(j)] = block[j];
  }
#else
  throw std::logic_error("allgather_shares: a share of several ranks in a build without MPI");
#endif
}

std::string broadcast_from_root(const std::string& text) {
  if (g_size == 1) return text;
#ifdef PEGASUS_HAVE_MPI
  unsigned long long length = text.size();
  check_collective(MPI_Bcast(&length, 1, MPI_UNSIGNED_LONG_LONG, 0, MPI_COMM_WORLD));
  std::string result = g_rank == 0 ? text : std::string(static_cast<std::size_t>(length), '\0');
  // In pieces below INT_MAX bytes.
  constexpr std::size_t kPiece = std::size_t{1} << 30;
  for (std::size_t at = 0; at < result.size(); at += kPiece) {
    const int piece = static_cast<int>(std::min(kPiece, result.size() - at));
    check_collective(MPI_Bcast(result.data() + at, piece, MPI_CHAR, 0, MPI_COMM_WORLD));
  }
  return result;
#else
  return text;
#endif
}

std::vector<int> allgather_int(int value) {
  std::vector<int> all(static_cast<std::size_t>(g_size), value);
#ifdef PEGASUS_HAVE_MPI
  if (g_size > 1) check_collective(MPI_Allgather(&value, 1, MPI_INT, all.data(), 1, MPI_INT, MPI_COMM_WORLD));
#endif
  return all;
}

void abort_job(int code) {
  std::fflush(stdout);
  std::fflush(stderr);
#ifdef PEGASUS_HAVE_MPI
  if (g_started && g_size > 1) {
    stop_message_said();
    MPI_Abort(MPI_COMM_WORLD, code);
  }
#endif
  std::exit(code);
}

void barrier() {
#ifdef PEGASUS_HAVE_MPI
  if (g_started && g_size > 1) check_collective(MPI_Barrier(MPI_COMM_WORLD));
#endif
}

void stop_message_said() {
#ifdef PEGASUS_HAVE_MPI
  if (g_started && g_size > 1 && g_rank == 0) std::signal(SIGTERM, SIG_DFL);
#endif
}

void set_stop_message(const std::string& line) {
  std::string text = line;
  if (text.size() > sizeof g_stop_line - 2) text.resize(sizeof g_stop_line - 2);
  text += '\n';
  std::memcpy(g_stop_line, text.c_str(), text.size() + 1);
}

CommStats comm_stats() { return g_stats; }
void reset_comm_stats() { g_stats = {}; }
void set_measure_wait(bool on) { g_measure_wait = on; }

}  // namespace pegasus::mpi
