#pragma once
// The hover config's judged cost, envelope limits and wind (issue 53), beside heli_config.cpp's other fields.
#include "pegasus/heli/hover_task.hpp"
#include "pegasus/heli/runs/heli_config.hpp"
#include "pegasus/heli/runs/heli_runs.hpp"
#include "pegasus/heli/training_wind.hpp"
#include "pegasus/heli/vehicle_file.hpp"

namespace pegasus::heli {

// wind.steady, wind.sigma, wind.gust_sigma and wind.gust_tau_s: the wind in the training scenarios (hover and
// manoeuvre), and their value.
void declare_training_wind(ConfigSchema& s);
// Their values from the vehicle file's [hover.wind] unless set.
void resolve_training_wind(ConfigSchema& s, const logs::Vehicle& v);
sysid::Disturbance read_training_wind(const ConfigSchema& c);
// reward.judged_cost, crash_penalty, max_position_error_m, max_speed_mps, max_rate_radps and wind.*.
void declare_hover_cost_and_wind(ConfigSchema& s);
// Their values from the vehicle file's [cost], [envelope] and [hover.wind] unless set.
void resolve_hover_cost_and_wind(ConfigSchema& s, const logs::Vehicle& v);
// The reward (the judged cost, whole, or the reward.* typical sizes), crash penalty, envelope and wind into
// o; whether the reward is the judged cost. InputError for reward.* options beside a judged cost.
bool read_hover_cost_and_wind(const ConfigSchema& c, const logs::Vehicle& v, HoverTrainingOptions& o);
// Where the wind.* values came from: an option, the vehicle file's [hover.wind], or none stated (then the
// default for a vehicle file's aircraft, heli/training_wind.hpp; calm for the X-Cell without one).
WindSource hover_wind_source(const ConfigSchema& c, const VehicleChoice& aircraft);

}  // namespace pegasus::heli
