#pragma once
// The experiment commands, one function each; commands.cpp puts them in the command table.
#include "command.hpp"
#include "pegasus/sysid/identify.hpp"

namespace pegasus::cli {

Command pomdp_gridworld_command();
std::vector<Command> bicycle_commands();        // bicycle experiment, train, ride, variance
std::vector<Command> heli_commands();           // heli pilot, identify
std::vector<Command> heli_maneuver_commands();  // heli maneuver (heli_maneuver_command.cpp)
std::vector<Command> log_commands();            // log import (log_command.cpp)
std::vector<Command> pendulum_commands();       // pendulum train (Pendulum-v1, the RLtools race)
std::vector<Command> mujoco_commands();         // mujoco train, rollout (empty without PEGASUS_MUJOCO)
Command shaping_audit_command();
std::vector<Command> shaping_commands();  // shaping audit, gridworld, flags, progress-bonus
Command report_command();                 // report RUN_DIR (report_command.cpp)
Command export_command();                 // export --policy P.json --lang c (export_command.cpp)

// The identification's bandwidth floors, `bandwidth_floor.*`, for every command that identifies
// (heli_command.cpp); defaults from sysid::BandwidthFloor.
void declare_bandwidth_floor(ConfigSchema& s);
sysid::BandwidthFloor read_bandwidth_floor(const ConfigSchema& c);

}  // namespace pegasus::cli
