#pragma once
// The "maneuver" class of helicopter policy files (policy_file.hpp): a ManeuverPolicy (maneuver_policy.hpp)
// with its weights, flying the manoeuvre its options name.
//
//   "class": "maneuver"
//   "parameters": the ManeuverPolicy's parameters in order (34 hover weights, the two couplings, then
//   "z_delay"
//                 and "feedforward" when options.learn_delay / options.feedforward)
//   "target":     the start of the manoeuvre (its x, y, z; yaw must be 0: the manoeuvres are flown nose
//   north) "trim":       the trim the couplings act about "options":    {"name": "III.1" | "III.2" | "III.3",
//   "learn_delay": bool, "feedforward": bool, "max_delay_s",
//                  "speed", "accel", "yaw_rate", "yaw_accel", "triangle_base", "circle_radius", "pause_s",
//                  "rectangle_width", "rectangle_height", "hold_start_s", "hold_end_s"}; missing sizes and
//                  limits
//                 take the defaults of trajectory.hpp
// The controller's time is the time since the manoeuvre began; after the trajectory's end it holds the end
// point.
#include <memory>
#include <nlohmann/json.hpp>
#include <span>
#include <string>

#include "pegasus/heli/maneuver_policy.hpp"
#include "pegasus/heli/policy_file.hpp"

namespace pegasus::heli {

struct ManeuverFileOptions {
  std::string name = "III.1";
  ManeuverSize size{};
  TrajectoryLimits limits{};
  ManeuverPolicyOptions policy{};
};
nlohmann::json maneuver_options_json(const ManeuverFileOptions& o);
// InputError "FILE: options.FIELD: expected ..." for a bad field.
ManeuverFileOptions maneuver_options_from_json(const nlohmann::json& j, const std::string& file);

PolicyFile maneuver_policy_file(const ManeuverFileOptions& options, const ManeuverPolicy& policy,
                                std::span<const double> theta, const Controls& trim);
// The manoeuvre policy of a "maneuver" file (its trajectory from the options and target) and its checked
// weights; InputError "FILE: FIELD: ..." as make_maneuver_controller.
struct CheckedManeuverPolicy {
  ManeuverPolicy policy;
  Theta theta;
};
CheckedManeuverPolicy checked_maneuver_policy(const PolicyFile& policy, const std::string& file);
// The factory of the built-in "maneuver" class of policy files (policy_file.cpp lists it).
std::unique_ptr<HeliController> make_maneuver_controller(const PolicyFile& policy, const std::string& file);

}  // namespace pegasus::heli
