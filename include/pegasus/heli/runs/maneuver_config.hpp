#pragma once
// The config sections of the manoeuvre experiments (heli/runs/maneuver_runs.hpp), as
// heli/runs/heli_config.hpp has the hover's: each one's fields with help, bounds and the Options structs'
// defaults, and their reading. The `maneuver` and `maneuver-pilot` commands and their `heli` aliases are
// these sections and a call.
#include <cstdint>

#include "pegasus/heli/runs/maneuver_runs.hpp"
#include "pegasus/runs/config.hpp"

namespace pegasus::heli {

// `maneuver`: a manoeuvre or figure-eight learned on the identified model and flown on the ground truth
// (resolve with resolve_maneuver_config).
void declare_maneuver_config(ConfigSchema& s);
// A vehicle file's gust_sigma and [hover.wind] into the fields not set.
void resolve_maneuver_config(ConfigSchema& s);
ManeuverRunOptions read_maneuver_config(const ConfigSchema& c, std::uint64_t seed);

// `maneuver-pilot`: the scripted pilot through hover, sweeps and the manoeuvres (resolve with
// resolve_gust_sigma).
void declare_maneuver_pilot_config(ConfigSchema& s);
ManeuverPilotRunOptions read_maneuver_pilot_config(const ConfigSchema& c, std::uint64_t seed);

}  // namespace pegasus::heli
