#pragma once
// The config sections of the helicopter experiments (heli/runs/heli_runs.hpp) for any aircraft: each
// experiment's fields with their help, bounds and defaults (read from its Options struct: defaults live
// once), the step that fills fields from a vehicle file, and the reading of the resolved fields into the
// experiment's options. The `pilot`, `identify`, `hover`, `fly` and `control` commands and their `heli`
// aliases are these sections and a call; a program of one's own can offer the same settings the same way.
//
//   ConfigSchema s;
//   heli::declare_hover_config(s);
//   s.load_toml_file("hover.toml");
//   heli::resolve_hover_config(s);  // the vehicle file's settings, where the file and options set none
//   s.validate();
//   heli::run_hover(heli::read_hover_config(s, seed), sink, pool);
#include <cstdint>
#include <optional>
#include <string>

#include "pegasus/heli/runs/heli_runs.hpp"
#include "pegasus/heli/vehicle_file.hpp"
#include "pegasus/runs/config.hpp"
#include "pegasus/sysid/identify.hpp"

namespace pegasus::heli {

// The `vehicle` field: a vehicle file (heli/vehicle_file.hpp), or empty for the X-Cell 60 in the project's
// own log layout. `fills`: the vehicle file's settings that the section's resolve step takes as its defaults,
// for the help text.
void declare_vehicle(ConfigSchema& s, const std::string& fills = "");
// The aircraft the `vehicle` field names.
VehicleChoice vehicle_of(const ConfigSchema& c);
// Sets `field` to `value` from the vehicle file's `key` unless the user set it (a config file or an option
// wins); the resolved config then names the file as the value's origin.
void set_from_vehicle(ConfigSchema& s, const logs::Vehicle& v, const std::string& field, FieldValue value,
                      const std::string& key);

// The vehicle file the `vehicle` field names, or none.
std::optional<logs::Vehicle> vehicle_file_of(const ConfigSchema& s);

// The ground truth's `gust_sigma` (the X-Cell's by default), and the resolve step that gives it the vehicle's
// ground truth's own (heli/simulators.hpp) when the user set none.
void declare_gust_sigma(ConfigSchema& s, const std::string& help);
void resolve_gust_sigma(ConfigSchema& s);

// The identification's bandwidth floors, `bandwidth_floor.*` (sysid::BandwidthFloor), for every section that
// identifies.
void declare_bandwidth_floor(ConfigSchema& s);
sysid::BandwidthFloor read_bandwidth_floor(const ConfigSchema& c);

// `pilot`: the ground truth flown by its scripted pilot (resolve with resolve_gust_sigma).
void declare_pilot_config(ConfigSchema& s);
PilotRunOptions read_pilot_config(const ConfigSchema& c, std::uint64_t seed);

// `identify`: system identification from flight logs.
void declare_identify_config(ConfigSchema& s);
void resolve_identify_config(ConfigSchema& s);
IdentifyRunOptions read_identify_config(const ConfigSchema& c);

// `hover`: PEGASUS hover training on an identified model.
void declare_hover_config(ConfigSchema& s);
// One of hover training's numbers (HoverTrainingOptions::VisitFields) as an option of another command that
// uses it: its key, default, bounds, and its help after `prefix`.
void declare_hover_number(ConfigSchema& s, const std::string& key, const std::string& prefix = {});
void resolve_hover_config(ConfigSchema& s);
HoverRunOptions read_hover_config(const ConfigSchema& c, std::uint64_t seed);

// `fly`: flights of a policy file or the pilot on the ground truth (resolve with resolve_gust_sigma).
void declare_fly_config(ConfigSchema& s);
FlyRunOptions read_fly_config(const ConfigSchema& c, std::uint64_t seed);

// `control`: the line-by-line controller server's fields (`vehicle`, `policy`, `bench_lines`).
void declare_control_config(ConfigSchema& s);

// `pipeline`: the whole chain's fields (each passed on to the stage of the same meaning).
void declare_pipeline_config(ConfigSchema& s);

}  // namespace pegasus::heli
