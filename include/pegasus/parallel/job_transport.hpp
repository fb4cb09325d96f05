#pragma once
// The transport a program links: Open MPI's when it links pegasus::mpi (which defines PEGASUS_HAVE_MPI), none
// otherwise. For a main that runs under mpirun whatever the build:
//
//   const pegasus::mpi::Session session(&argc, &argv, pegasus::mpi::linked_transport());
#include "pegasus/parallel/mpi.hpp"
#ifdef PEGASUS_HAVE_MPI
#include "pegasus/parallel/open_mpi.hpp"
#endif

namespace pegasus::mpi {

// Whether this program can run as one rank of a job of several.
constexpr bool links_a_transport() {
#ifdef PEGASUS_HAVE_MPI
  return true;
#else
  return false;
#endif
}

constexpr TransportStart linked_transport() {
#ifdef PEGASUS_HAVE_MPI
  return &open_mpi::join;
#else
  return nullptr;
#endif
}

}  // namespace pegasus::mpi
