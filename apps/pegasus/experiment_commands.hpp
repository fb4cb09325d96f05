#pragma once
// What the command files share: the vehicle and bandwidth-floor options, and `heli identify`, which
// heli_commands() lists. The command groups themselves are declared beside the table (commands.cpp).
#include "command.hpp"
#include "pegasus/core/reward_limits.hpp"
#include "pegasus/logs/vehicle.hpp"
#include "pegasus/runs/heli_runs.hpp"
#include "pegasus/sysid/identify.hpp"

namespace pegasus::cli {

// `shaping audit` (shaping_command_audit.cpp), one of shaping_commands().
Command shaping_audit_command();

// The identification's bandwidth floors, `bandwidth_floor.*`, for every command that identifies
// (heli_identify_command.cpp); defaults from sysid::BandwidthFloor.
void declare_bandwidth_floor(ConfigSchema& s);
sysid::BandwidthFloor read_bandwidth_floor(const ConfigSchema& c);

// `heli identify` / `identify` (heli_identify_command.cpp), listed by heli_commands().
void declare_identify(ConfigSchema& s);
void resolve_identify(ConfigSchema& s);
void run_identify(RunContext& ctx);

// `heli pipeline` / `pipeline` (heli_pipeline_command.cpp), listed by heli_commands().
void declare_pipeline(ConfigSchema& s);
void run_pipeline(RunContext& ctx);
std::vector<Command> heli_commands();

// Vehicle files (logs/vehicle.hpp) for the helicopter commands (heli_command.cpp): the `vehicle` option, the
// aircraft it names (the X-Cell 60 when empty), and a field set from the vehicle unless the user set it.
// `fills`: the vehicle file's settings that the command's resolve step takes as its defaults, for --help.
void declare_vehicle(ConfigSchema& s, const std::string& fills = "");
heli::VehicleChoice aircraft_of(const ConfigSchema& c);
void from_vehicle(ConfigSchema& s, const logs::Vehicle& v, const std::string& field, FieldValue value,
                  const std::string& key);
// The ground truth's `gust_sigma` option (the X-Cell's by default), and the resolve step that gives it the
// vehicle's ground truth's own (heli/simulators.hpp) when the user set none.
void declare_gust_sigma(ConfigSchema& s, const std::string& help);
void resolve_gust_sigma(ConfigSchema& s);

}  // namespace pegasus::cli
