#pragma once
// What the command files share: the helicopter config sections and experiments, and the commands one
// command file lists from another. The command groups themselves are declared
// beside the table (commands.cpp).
#include <vector>

#include "pegasus/cli/command.hpp"
#include "pegasus/heli/runs/heli_config.hpp"
#include "pegasus/heli/runs/heli_runs.hpp"

namespace pegasus::cli {

// `heli pipeline` / `pipeline` (heli_pipeline_command.cpp), listed by heli_commands().
void run_pipeline(RunContext& ctx);
std::vector<Command> heli_commands();

}  // namespace pegasus::cli
