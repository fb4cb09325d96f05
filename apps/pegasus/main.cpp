#include <iostream>

#include "command.hpp"

int main(int argc, char** argv) {
  return pegasus::cli::run_cli(argc, argv, pegasus::cli::command_groups(), pegasus::cli::commands(),
                               std::cout, std::cerr);
}
