#include "pegasus/heli/maneuver_file.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "pegasus/core/error.hpp"
#include "pegasus/io/json_input.hpp"

namespace pegasus::heli {
namespace {

class ManeuverController final : public HeliController {
 public:
  ManeuverController(ManeuverPolicy policy, Theta theta)
      : policy_(std::move(policy)), theta_(std::move(theta)) {}
  using HeliController::act;
  Controls act(const LoggedState& estimate, double time, ControllerMemory&) const override {
    return policy_.act(theta_, ManeuverObservation{estimate, time});
  }
  SetPoint target(double time) const override { return policy_.target(theta_, time); }

 private:
  ManeuverPolicy policy_;
  Theta theta_;
};

}  // namespace

nlohmann::json maneuver_options_json(const ManeuverFileOptions& o) {
  return {{"name", o.name},
          {"learn_delay", o.policy.learn_delay},
          {"feedforward", o.policy.feedforward},
          {"max_delay_s", o.policy.max_delay_s},
          {"speed", o.limits.speed},
          {"accel", o.limits.accel},
          {"yaw_rate", o.limits.yaw_rate},
          {"yaw_accel", o.limits.yaw_accel},
          {"triangle_base", o.size.triangle_base},
          {"circle_radius", o.size.circle_radius},
          {"pause_s", o.size.pause_s},
          {"rectangle_width", o.size.rectangle_width},
          {"rectangle_height", o.size.rectangle_height},
          {"hold_start_s", o.size.hold_start_s},
          {"hold_end_s", o.size.hold_end_s},
          {"figure_eight_radius", o.size.figure_eight_radius},
          {"start_z", o.size.start_W.z()}};
}

ManeuverFileOptions maneuver_options_from_json(const nlohmann::json& j, const std::string& file) {
  if (!j.is_object()) throw InputError(file + ": options: expected an object naming the manoeuvre");
  ManeuverFileOptions o;
  if (!j.contains("name") || !j.at("name").is_string())
    throw InputError(file + ": options.name: expected " + maneuver_name_list());
  o.name = j.at("name").get<std::string>();
  if (std::find(kManeuverNames.begin(), kManeuverNames.end(), o.name) == kManeuverNames.end())
    throw InputError(
        fmt::format("{}: options.name: expected {}, got \"{}\"", file, maneuver_name_list(), o.name));
  const auto number = [&](const char* name, double fallback) {
    return json_number_or(j, name, fallback, file, fmt::format("options.{}", name));
  };
  const auto flag = [&](const char* name, bool fallback) {
    return json_flag_or(j, name, fallback, file, fmt::format("options.{}", name));
  };
  o.policy.learn_delay = flag("learn_delay", o.policy.learn_delay);
  o.policy.feedforward = flag("feedforward", o.policy.feedforward);
  o.policy.max_delay_s = number("max_delay_s", o.policy.max_delay_s);
  o.limits.speed = number("speed", o.limits.speed);
  o.limits.accel = number("accel", o.limits.accel);
  o.limits.yaw_rate = number("yaw_rate", o.limits.yaw_rate);
  o.limits.yaw_accel = number("yaw_accel", o.limits.yaw_accel);
  o.size.triangle_base = number("triangle_base", o.size.triangle_base);
  o.size.circle_radius = number("circle_radius", o.size.circle_radius);
  o.size.pause_s = number("pause_s", o.size.pause_s);
  o.size.figure_eight_radius = number("figure_eight_radius", o.size.figure_eight_radius);
  o.size.start_W.z() = number("start_z", o.size.start_W.z());
  o.size.rectangle_width = number("rectangle_width", o.size.rectangle_width);
  o.size.rectangle_height = number("rectangle_height", o.size.rectangle_height);
  o.size.hold_start_s = number("hold_start_s", o.size.hold_start_s);
  o.size.hold_end_s = number("hold_end_s", o.size.hold_end_s);
  std::string error;
  if (!o.limits.IsValid(&error) || !o.size.IsValid(&error)) throw InputError(file + ": options." + error);
  if (!(o.policy.max_delay_s > 0)) throw InputError(file + ": options.max_delay_s: expected a number > 0");
  return o;
}

PolicyFile maneuver_policy_file(const ManeuverFileOptions& options, const ManeuverPolicy& policy,
                                std::span<const double> theta, const Controls& trim) {
  PolicyFile p;
  p.class_name = "maneuver";
  for (const auto& param : policy.parameters().all()) p.names.push_back(param.name);
  p.values.assign(theta.begin(), theta.end());
  const Vec3 s0 = policy.trajectory().start_W();
  p.target = {s0.x(), s0.y(), s0.z(), 0.0};
  p.trim = trim;
  p.options = maneuver_options_json(options);
  set_file_command_limits(p, policy.init().command_lower, policy.init().command_upper);
  return p;
}

CheckedManeuverPolicy checked_maneuver_policy(const PolicyFile& policy, const std::string& file) {
  ManeuverFileOptions o = maneuver_options_from_json(policy.options, file);
  if (policy.target.yaw != 0)
    throw InputError(file + ": target.yaw: expected 0 for a manoeuvre (flown nose north)");
  o.size.start_W = Vec3(policy.target.x, policy.target.y, policy.target.z);
  std::string error;
  if (!o.size.IsValid(&error)) throw InputError(file + ": target: " + error);
  auto trajectory = std::make_shared<const Trajectory>(maneuver_trajectory(o.name, o.size, o.limits));
  HoverPolicyInit init = hover_file_command_limits(policy, file);
  init.trim = policy.trim;
  ManeuverPolicy p(std::move(trajectory), init, o.policy);
  Theta theta = checked_parameters(policy, p.parameters(), file);
  return {std::move(p), std::move(theta)};
}

std::unique_ptr<HeliController> make_maneuver_controller(const PolicyFile& policy, const std::string& file) {
  CheckedManeuverPolicy checked = checked_maneuver_policy(policy, file);
  return std::make_unique<ManeuverController>(std::move(checked.policy), std::move(checked.theta));
}

}  // namespace pegasus::heli
