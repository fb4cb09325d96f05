#pragma once
// Vehicle files read, and the logs, costs and control lines they describe. The aircraft's description itself,
// the typed Vehicle, is the vehicle layer's (vehicle/vehicle.hpp), below heli/ and sysid/; what is here
// needs heli/: the reader checks a file against heli's registries and hover's settings, and the judged cost
// becomes a hover reward. (Its namespace, logs::, is the one it had in logs/, so callers are unchanged.)
#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "pegasus/heli/control_loop.hpp"
#include "pegasus/heli/hover_task.hpp"
#include "pegasus/vehicle/flight_log.hpp"
#include "pegasus/vehicle/vehicle.hpp"

namespace pegasus::logs {

// The hover reward that is the vehicle's judged cost, exactly (vehicle.cost must be set): every weight
// converted to the pipeline's frames and units (NED, FRD, rad, rad/s, the axes a1..a4), every other term 0.
// Its centre is the file's controls_about when not about the trim.
heli::HoverReward judged_reward(const Vehicle& vehicle);

// The X-Cell 60 as the `heli` commands have always assumed it: logs in the pipeline's own layout at 50 Hz,
// a 10 Hz model with the flapping and gyro states, a 50 Hz controller, the tuned constant starting gains.
// experiments/vehicles/xcell60.toml says the same in a file.
Vehicle xcell_vehicle();
// Reads a vehicle file's [vehicle] name and [log] section; InputError "FILE:LINE: key: expected ..." on a
// missing or bad entry.
VehicleLogSpec read_vehicle_log_spec(const std::filesystem::path& file);
// The same for text already read; `name` stands for the file in messages.
VehicleLogSpec parse_vehicle_log_spec(std::string_view text, const std::filesystem::path& name);

// Reads a vehicle file; InputError naming the file, line and key on any problem.
Vehicle read_vehicle(const std::filesystem::path& file);
Vehicle parse_vehicle(std::string_view text, const std::filesystem::path& name);

// A flight log as the vehicle's [log] section describes it (a CSV with a header, any column order, extra
// columns ignored), in the pipeline's layout. InputError "FILE:LINE:COLUMN: ..." as read_flight_log says it,
// naming the aircraft's columns; its time steps must match log.rate_hz within options.rate_tolerance.
sysid::FlightLog read_vehicle_log(const std::filesystem::path& file, const Vehicle& vehicle,
                                  const sysid::LogReadOptions& options = {});
sysid::FlightLog parse_vehicle_log(const std::string& text, const std::string& name, const Vehicle& vehicle,
                                   const sysid::LogReadOptions& options = {});

// Whether the vehicle's logs are the pipeline's own CSV layout (sysid::flight_log_csv: the columns time, x,
// y, z, roll, pitch, yaw, xdot, ..., yaw_rate, a1..a4 as they are, in any order), as the shipped X-Cell and
// Crazyflie files say; the rate aside.
bool logs_in_pipeline_layout(const Vehicle& vehicle);
// A flight log in the pipeline's layout written as the vehicle's logs come (the inverse of
// parse_vehicle_log): its time column, its state fields (quaternion or Euler attitude, world or body
// velocity, body or Euler rates) and its channels in its order, ranges and signs; every `every`-th row from
// the first.
std::string vehicle_log_csv(const sysid::FlightLog& log, const Vehicle& vehicle, std::size_t every = 1);
// Its header; InputError when two quantities of the file name the same field (of different topics): a CSV
// log cannot hold both.
std::vector<std::string> vehicle_log_columns(const Vehicle& vehicle);

// The `pegasus control` line format of the vehicle: state lines in its fields (its column names in a
// header), the answer in its channels' order, names and units.
heli::ControlLineFormat control_line_format(const Vehicle& vehicle);

}  // namespace pegasus::logs
