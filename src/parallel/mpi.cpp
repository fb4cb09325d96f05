#include "pegasus/parallel/mpi.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <thread>

namespace pegasus::mpi {

namespace {

// The job this process joined (Session), or none: one rank.
std::unique_ptr<Transport> g_transport;
int g_rank = 0;
int g_size = 1;
std::thread::id g_main_thread;
CommStats g_stats;
bool g_measure_wait = false;

// The stop line for SIGTERM, in static storage so that the handler only calls write(2).
char g_stop_line[1024] = "pegasus: error: the MPI job was stopped (a rank failed or the job was killed)\n";

extern "C" void on_stop_signal(int) {
  const ssize_t ignored = ::write(STDERR_FILENO, g_stop_line, std::strlen(g_stop_line));
  (void)ignored;
  ::_exit(1);
}

// Whether a launcher started this process as one rank of a job: 0 when not, else the job's size as far as
// the environment tells (1 when only a rank is given; the transport then tells the truth).
int launched_size() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE"})
    if (const char* v = std::getenv(name)) return std::max(1, std::atoi(v));
  if (std::getenv("PMIX_RANK") || std::getenv("PMI_RANK")) return 1;
  return 0;
}

int launched_rank() {
  for (const char* name : {"OMPI_COMM_WORLD_RANK", "PMI_RANK", "PMIX_RANK"})
    if (const char* v = std::getenv(name)) return std::atoi(v);
  return 0;
}

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

bool several_ranks() { return g_transport && g_size > 1; }

}  // namespace

Session::Session(int* argc, char*** argv, TransportStart join) {
  g_main_thread = std::this_thread::get_id();
  const int launched = launched_size();
  if (launched == 0) return;
  if (join) {
    g_transport = join(argc, argv);
    g_rank = g_transport->rank();
    g_size = g_transport->size();
    // mpirun stops the other ranks with SIGTERM when one fails: rank 0 says why (set_stop_message).
    if (g_size > 1 && g_rank == 0) std::signal(SIGTERM, on_stop_signal);
    return;
  }
  if (launched > 1) {
    if (launched_rank() == 0)
      std::fprintf(stderr,
                   "pegasus: this program cannot join an MPI job (built with PEGASUS_MPI=OFF or without Open "
                   "MPI, or linked without pegasus::mpi): under mpirun -np %d every process would run the "
                   "whole job alone; rebuild with Open MPI (libopenmpi-dev) or run without mpirun\n",
                   launched);
    std::exit(2);
  }
}

Session::~Session() {
  g_transport.reset();
  g_rank = 0;
  g_size = 1;
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

void allgather_shares(std::span<double> values, const Share& share) {
  if (share.size == 1) return;
  if (!g_transport || share.size != g_size || share.rank != g_rank)
    throw std::logic_error("allgather_shares: not this rank's share of a job");
  ++g_stats.calls;
  const std::size_t n = values.size();
  // Pack this rank's items, gather every rank's block, then put each item back at its index.
  std::vector<int> counts(static_cast<std::size_t>(g_size)), displacements(static_cast<std::size_t>(g_size));
  int offset = 0;
  for (int r = 0; r < g_size; ++r) {
    const Share s{r, g_size};
    counts[static_cast<std::size_t>(r)] = static_cast<int>(s.count(n));
    displacements[static_cast<std::size_t>(r)] = offset;
    offset += counts[static_cast<std::size_t>(r)];
  }
  std::vector<double> mine(share.count(n)), all(n);
  for (std::size_t j = 0; j < mine.size(); ++j) mine[j] = values[share.item(j)];
  if (g_measure_wait) {
    const double start = now_seconds();
    g_transport->barrier();
    g_stats.wait_seconds += now_seconds() - start;
  }
  const double start = now_seconds();
  g_transport->allgatherv(mine, all, counts, displacements);
  g_stats.seconds += now_seconds() - start;
  g_stats.bytes += static_cast<std::int64_t>(n * sizeof(double));
  for (int r = 0; r < g_size; ++r) {
    const Share s{r, g_size};
    const double* block = all.data() + displacements[static_cast<std::size_t>(r)];
    for (std::size_t j = 0; j < static_cast<std::size_t>(counts[static_cast<std::size_t>(r)]); ++j)
      values[s.item(j)] = block[j];
  }
}

std::string broadcast_from_root(const std::string& text) {
  if (!several_ranks()) return text;
  std::uint64_t length = text.size();
  g_transport->broadcast(length);
  std::string result = g_rank == 0 ? text : std::string(static_cast<std::size_t>(length), '\0');
  g_transport->broadcast(std::span<char>(result.data(), result.size()));
  return result;
}

std::vector<int> allgather_int(int value) {
  std::vector<int> all(static_cast<std::size_t>(g_size), value);
  if (several_ranks()) g_transport->allgather(value, all);
  return all;
}

void abort_job(int code) {
  std::fflush(stdout);
  std::fflush(stderr);
  if (several_ranks()) {
    stop_message_said();
    g_transport->abort(code);
  }
  std::exit(code);
}

void barrier() {
  if (several_ranks()) g_transport->barrier();
}

void stop_after_failed_collective() {
  if (g_rank == 0) on_stop_signal(0);
  ::_exit(1);
}

void stop_message_said() {
  if (several_ranks() && g_rank == 0) std::signal(SIGTERM, SIG_DFL);
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
