#pragma once
// A PX4 ULog flight turned into the project's CSV flight log (vehicle/flight_log.hpp): the topics a vehicle
// file's [log] section names are aligned on one time grid at a constant rate, resampled, converted to the
// log's frames (world NED position and velocity, Z-Y-X Euler angles, Euler-angle rates) and its four
// control columns. The README's "Vehicle files: the [log] section" documents the schema.
//
//   const VehicleLogSpec spec = read_vehicle_log_spec(  // heli/vehicle_file.hpp
//       "experiments/vehicles/px4-quadrotor.toml");
//   const logs::UlogFile ulog = logs::read_ulog(file, {.topics = spec.topic_names()});
//   ImportProvenance provenance;
//   const sysid::FlightLog log = import_ulog(ulog, spec, file.string(), &provenance);
#include <array>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "pegasus/logs/ulog.hpp"
#include "pegasus/vehicle/flight_log.hpp"
#include "pegasus/vehicle/vehicle.hpp"

namespace pegasus::logs {

struct ImportOptions {
  double start_s = 0;  // cut: seconds after the first common timestamp
  double end_s = 0;    // cut: seconds after the first common timestamp; 0 = to the end
};

// What the import used and found, for provenance.json.
struct ImportProvenance {
  nlohmann::json json;
};

// The flight log on the grid t_k = t0 + k / rate_hz inside the time range every used topic covers (cut by
// options). Positions, velocities and rates are interpolated linearly, the attitude quaternion by normalised
// linear interpolation, controls held from their last record (what the actuators had). InputError naming the
// file, topic and field for a missing topic or field, a timestamp that goes back, a gap over max_gap_s, a
// control outside [-1, 1] after scaling, or fewer than 2 rows.
sysid::FlightLog import_ulog(const UlogFile& ulog, const VehicleLogSpec& spec, const std::string& file,
                             const ImportOptions& options = {}, ImportProvenance* provenance = nullptr);

}  // namespace pegasus::logs
