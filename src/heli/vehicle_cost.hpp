#pragma once
// The vehicle file's [cost] and the rest of its [envelope] (heli/vehicle_file.hpp: JudgedCost), read beside
// the other sections by vehicle.cpp.
#include <optional>
#include <string>

#include "../io/toml_fields.hpp"
#include "pegasus/heli/vehicle_file.hpp"

namespace pegasus::logs {

// [cost] (nullopt when the file has none); InputError "FILE:LINE: cost.KEY: expected ..." on a bad entry.
std::optional<JudgedCost> read_judged_cost(const toml::table& root, const TomlFields& fields);
// [envelope] max_position_error (m), max_speed (m/s) and max_rate (the rates unit) into v (m, m/s, rad/s).
void read_envelope_limits(const toml::table& root, const TomlFields& fields, Vehicle& v);
// [hover.wind]: steady (the file's world frame, m/s), sigma, gust_sigma (m/s), gust_tau_s (s); in NED.
// nullopt when the file has no such section.
std::optional<sysid::Disturbance> read_hover_wind(const toml::table& root, const TomlFields& fields,
                                                  const VehicleLogSpec& spec);

}  // namespace pegasus::logs
