#pragma once
// What the command files share: the helicopter config sections (the vehicle, gust and bandwidth-floor
// fields), and the commands one command file lists from another. The command groups themselves are declared
// beside the table (commands.cpp).
#include "command.hpp"
#include "pegasus/core/reward_limits.hpp"
#include "pegasus/logs/vehicle.hpp"
#include "pegasus/runs/heli_config.hpp"
#include "pegasus/runs/heli_runs.hpp"
#include "pegasus/sysid/identify.hpp"

namespace pegasus::cli {

// `heli pipeline` / `pipeline` (heli_pipeline_command.cpp), listed by heli_commands().
void run_pipeline(RunContext& ctx);
std::vector<Command> heli_commands();

}  // namespace pegasus::cli
