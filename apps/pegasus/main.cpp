#include <iostream>
#include <ostream>
#include <streambuf>

#include "command.hpp"
#include "pegasus/parallel/mpi.hpp"

namespace {

// Where the printed results of ranks other than 0 go (parallel/mpi.hpp).
class NullBuffer final : public std::streambuf {
 protected:
  int overflow(int c) override { return c == traits_type::eof() ? 0 : c; }
};

}  // namespace

int main(int argc, char** argv) {
  // Under mpirun every rank runs the command; rank 0 alone prints and writes the run directory.
  const pegasus::mpi::Session mpi(&argc, &argv);
  NullBuffer null_buffer;
  std::ostream null_stream(&null_buffer);
  const bool root = pegasus::mpi::is_root();
  return pegasus::cli::run_cli(argc, argv, pegasus::cli::command_groups(), pegasus::cli::commands(),
                               root ? std::cout : null_stream, root ? std::cerr : null_stream);
}
