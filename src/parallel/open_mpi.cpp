#include "pegasus/parallel/open_mpi.hpp"

#ifndef OMPI_SKIP_MPICXX
#define OMPI_SKIP_MPICXX 1
#endif
#include <mpi.h>

#include <algorithm>
#include <csignal>
#include <cstdio>
#include <cstdlib>

namespace pegasus::open_mpi {

namespace {

int g_kill_rank = -1;
std::int64_t g_kill_after = 0;

void check(int rc) {
  if (rc != MPI_SUCCESS) mpi::stop_after_failed_collective();
}

class OpenMpiTransport final : public mpi::Transport {
 public:
  OpenMpiTransport(int* argc, char*** argv) {
    int provided = 0;
    if (MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS) {
      std::fprintf(stderr, "pegasus: error: MPI could not start\n");
      std::exit(1);
    }
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
    // Failures of collectives come back as codes (check) instead of Open MPI's own abort, which would end
    // rank 0 without the stop line.
    MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
  }
  ~OpenMpiTransport() override {
    int finalized = 0;
    MPI_Finalized(&finalized);
    if (!finalized) MPI_Finalize();
  }
  OpenMpiTransport(const OpenMpiTransport&) = delete;
  OpenMpiTransport& operator=(const OpenMpiTransport&) = delete;

  int rank() const override { return rank_; }
  int size() const override { return size_; }

  void allgatherv(std::span<const double> mine, std::span<double> all, std::span<const int> counts,
                  std::span<const int> displacements) override {
    if (g_kill_rank == rank_ && ++allgathers_ >= g_kill_after) std::raise(SIGKILL);
    check(MPI_Allgatherv(mine.data(), static_cast<int>(mine.size()), MPI_DOUBLE, all.data(), counts.data(),
                         displacements.data(), MPI_DOUBLE, MPI_COMM_WORLD));
  }

  void broadcast(std::span<char> bytes) override {
    // In pieces below INT_MAX bytes.
    constexpr std::size_t kPiece = std::size_t{1} << 30;
    for (std::size_t at = 0; at < bytes.size(); at += kPiece) {
      const int piece = static_cast<int>(std::min(kPiece, bytes.size() - at));
      check(MPI_Bcast(bytes.data() + at, piece, MPI_CHAR, 0, MPI_COMM_WORLD));
    }
  }

  void broadcast(std::uint64_t& value) override {
    check(MPI_Bcast(&value, 1, MPI_UINT64_T, 0, MPI_COMM_WORLD));
  }

  void allgather(int value, std::span<int> all) override {
    check(MPI_Allgather(&value, 1, MPI_INT, all.data(), 1, MPI_INT, MPI_COMM_WORLD));
  }

  void barrier() override { check(MPI_Barrier(MPI_COMM_WORLD)); }

  [[noreturn]] void abort(int code) override {
    MPI_Abort(MPI_COMM_WORLD, code);
    std::exit(code);
  }

 private:
  int rank_ = 0;
  int size_ = 1;
  std::int64_t allgathers_ = 0;
};

}  // namespace

std::unique_ptr<mpi::Transport> join(int* argc, char*** argv) {
  return std::make_unique<OpenMpiTransport>(argc, argv);
}

void kill_at_allgather(int rank, std::int64_t calls) {
  g_kill_rank = rank;
  g_kill_after = calls;
}

}  // namespace pegasus::open_mpi
