#pragma once
// Open MPI as the ranks' transport (the pegasus::mpi component): what a program hands to its mpi::Session to
// run as one rank of `mpirun -np N`:
//
//   const pegasus::mpi::Session session(&argc, &argv, &pegasus::open_mpi::join);
#include <cstdint>
#include <memory>

#include "pegasus/parallel/mpi.hpp"

namespace pegasus::open_mpi {

// Starts MPI (MPI_Init_thread, funneled: only the main thread calls it) on MPI_COMM_WORLD, and finalizes it
// when the transport is destroyed. Failed collectives end the job with the stop line
// (mpi::stop_after_failed_collective) instead of Open MPI's own abort.
std::unique_ptr<mpi::Transport> join(int* argc, char*** argv);

// Test only: rank `rank` kills itself with SIGKILL, as a crashed node would, when it enters its calls-th
// allgather (the CLI sets it from PEGASUS_TEST_MPI_KILL="RANK:CALLS").
void kill_at_allgather(int rank, std::int64_t calls);

}  // namespace pegasus::open_mpi
