#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <ostream>

#include "pegasus/cli/command.hpp"
#include "pegasus/parallel/job_transport.hpp"

namespace {

#ifdef PEGASUS_HAVE_MPI
// The MPI tests' crashed node (tests/mpi): PEGASUS_TEST_MPI_KILL="RANK:CALLS". Not documented for users.
void read_fault_injection() {
  const char* v = std::getenv("PEGASUS_TEST_MPI_KILL");
  int rank = -1;
  long long calls = 0;
  if (v && std::sscanf(v, "%d:%lld", &rank, &calls) == 2 && calls > 0)
    pegasus::open_mpi::kill_at_allgather(rank, calls);
}
#else
void read_fault_injection() {}
#endif

}  // namespace

int main(int argc, char** argv) {
  // Under mpirun every rank runs the command; rank 0 alone prints and writes the run directory.
  const pegasus::mpi::Session mpi(&argc, &argv, pegasus::mpi::linked_transport());
  read_fault_injection();
  pegasus::cli::NullStream null_stream;  // the printed results of ranks other than 0 (parallel/mpi.hpp)
  const bool root = pegasus::mpi::is_root();
  return pegasus::cli::run_cli(argc, argv, pegasus::cli::command_groups(), pegasus::cli::commands(),
                               root ? std::cout : null_stream, root ? std::cerr : null_stream);
}
