#pragma once
// The experiment commands, one function each; commands.cpp puts them in the command table.
#include "command.hpp"

namespace pegasus::cli {

Command pomdp_gridworld_command();

}  // namespace pegasus::cli
