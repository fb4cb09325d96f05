#pragma once
// The experiment commands, one function each; commands.cpp puts them in the command table.
#include "command.hpp"
#include "pegasus/logs/vehicle.hpp"
#include "pegasus/runs/heli_runs.hpp"
#include "pegasus/sysid/identify.hpp"

namespace pegasus::cli {

Command pomdp_gridworld_command();
std::vector<Command> bicycle_commands();        // bicycle experiment, train, ride, variance
std::vector<Command> heli_commands();           // heli pilot, identify, hover, fly, control, pipeline
std::vector<Command> heli_maneuver_commands();  // heli maneuver (heli_maneuver_command.cpp)
std::vector<Command> log_commands();            // log import (log_command.cpp)
std::vector<Command> pendulum_commands();       // pendulum train (Pendulum-v1, the RLtools race)
std::vector<Command> mujoco_commands();         // mujoco train, rollout (empty without PEGASUS_MUJOCO)
Command shaping_audit_command();
std::vector<Command> shaping_commands();  // shaping audit, gridworld, flags, progress-bonus
Command report_command();                 // report RUN_DIR (report_command.cpp)
Command export_command();                 // export --policy P.json --lang c (export_command.cpp)

// The identification's bandwidth floors, `bandwidth_floor.*`, for every command that identifies
// (heli_identify_command.cpp); defaults from sysid::BandwidthFloor.
void declare_bandwidth_floor(ConfigSchema& s);
sysid::BandwidthFloor read_bandwidth_floor(const ConfigSchema& c);

// `heli identify` / `identify` (heli_identify_command.cpp), listed by heli_commands().
void declare_identify(ConfigSchema& s);
void resolve_identify(ConfigSchema& s);
void run_identify(RunContext& ctx);

// Vehicle files (logs/vehicle.hpp) for the helicopter commands (heli_command.cpp): the `vehicle` option, the
// aircraft it names (the X-Cell 60 when empty), and a field set from the vehicle unless the user set it.
void declare_vehicle(ConfigSchema& s);
heli::VehicleChoice aircraft_of(const ConfigSchema& c);
void from_vehicle(ConfigSchema& s, const logs::Vehicle& v, const std::string& field, FieldValue value,
                  const std::string& key);

}  // namespace pegasus::cli
