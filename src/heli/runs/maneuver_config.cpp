// The manoeuvre experiments' config sections (heli/runs/maneuver_config.hpp).
#include "pegasus/heli/runs/maneuver_config.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <string>
#include <string_view>
#include <vector>

#include "pegasus/core/reward_limits.hpp"
#include "pegasus/heli/maneuver_task.hpp"
#include "pegasus/heli/runs/heli_config.hpp"
#include "pegasus/runs/optimizer_config.hpp"
#include "vehicle_cost_config.hpp"

namespace pegasus::heli {
namespace {

std::vector<std::string> maneuver_choices() {
  return std::vector<std::string>(kManeuverNames.begin(), kManeuverNames.end());
}

// Where the manoeuvres start and what size the figure-eight is (both commands).
void declare_size(ConfigSchema& s) {
  const ManeuverSize d;
  s.add_double("altitude_m", -d.start_W.z(), "height of the start hover above the ground, m")
      .greater_than(0)
      .max(1000);
  s.add_double("figure_eight_radius", d.figure_eight_radius, "figure8: radius of each circle, m")
      .range(0.1, 100);
}

void read_size(const ConfigSchema& c, ManeuverSize& size) {
  size.start_W = Vec3(0, 0, -c.get_double("altitude_m"));
  size.figure_eight_radius = c.get_double("figure_eight_radius");
}

// The set point's speed and acceleration limits (both commands).
void declare_limits(ConfigSchema& s) {
  const TrajectoryLimits d;
  s.add_double("speed", d.speed, "set-point speed limit along the path, m/s").range(0.1, 20);
  s.add_double("accel", d.accel, "set-point acceleration limit, m/s^2").range(0.1, 20);
  s.add_double("yaw_rate", d.yaw_rate, "pirouette rate limit, rad/s").range(0.1, 10);
  s.add_double("yaw_accel", d.yaw_accel, "pirouette acceleration limit, rad/s^2").range(0.1, 20);
}

TrajectoryLimits read_limits(const ConfigSchema& c) {
  return {.speed = c.get_double("speed"),
          .accel = c.get_double("accel"),
          .yaw_rate = c.get_double("yaw_rate"),
          .yaw_accel = c.get_double("yaw_accel")};
}

}  // namespace

void declare_maneuver_config(ConfigSchema& s) {
  const ManeuverRunOptions run;
  const ManeuverTrainingOptions& d = run.training;
  declare_vehicle(s);
  s.add_string("name", d.name, "manoeuvre: AMA Class III (thesis 5.4) or a figure-eight (figure8)")
      .choices(maneuver_choices());
  declare_size(s);
  s.add_string("model", "", "identified model file (model.json of `pegasus heli identify`)").input_file();
  s.add_string(
       "hover_policy", "",
       "optional: a trained hover policy file to start from (else the model's trim and default gains)")
      .input_file();
  // Trajectory
  declare_limits(s);
  s.add_double("triangle_base", d.size.triangle_base,
               "III.1: base of the triangle, m (apex at half of it above)")
      .range(1, 200);
  s.add_double("circle_radius", d.size.circle_radius, "III.2: radius of the circle, m").range(1, 100);
  s.add_double("pause_s", d.size.pause_s, "III.2: pause on the circle before circling, s").range(0, 60);
  s.add_double("rectangle_width", d.size.rectangle_width, "III.3: width of the rectangle, m").range(1, 200);
  s.add_double("rectangle_height", d.size.rectangle_height, "III.3: height of the rectangle, m")
      .range(1, 100);
  s.add_double("hold_end_s", d.size.hold_end_s, "hover after the last leg, s").range(0, 60);
  // Training
  declare_numbers(s, d);  // ManeuverTrainingOptions::VisitFields
  s.add_double("reward.alpha_pos", d.reward.alpha_pos, "per m^2 of distance to the path's projection")
      .range(0, kMaxRewardWeight);
  s.add_double("reward.alpha_yaw", d.reward.alpha_yaw, "per rad^2 of yaw error to the projection")
      .range(0, kMaxRewardWeight);
  s.add_double("reward.alpha_vel", d.reward.alpha_vel,
               "per (m/s)^2 of velocity minus the path's velocity at the projection")
      .range(0, kMaxRewardWeight);
  s.add_double("reward.alpha_action", d.reward.alpha_action[0], "per unit^2 of each control about the trim")
      .range(0, kMaxRewardWeight);
  declare_training_wind(s);
  s.add_bool("shaping", d.shaping, "potential-based shaping reward growing along the path");
  s.add_bool("learn_delay", d.policy.learn_delay,
             "learn the delay t of the vertical set point in angled climbs and descents");
  s.add_bool("feedforward", d.policy.feedforward,
             "the hover networks see the velocity relative to the set point's (learned gain)");
  declare_optimizer_options(s, "optimizer", d.optimizer, continuous_class_methods(false));
  s.add_bool("ablations", run.ablations,
             "also train without the learned delay and without shaping (same budget) and fly them");
  // Flights on the ground truth
  declare_numbers(s, run.flights, "flights");  // ManeuverFlightOptions::VisitFields
  declare_gust_sigma(s, "turbulence per axis on the ground truth, m/s");
  declare_numbers(s, run.flights, "flight_start_sigma");
  s.add_int("trace_flights", run.trace_flights, "flights written to flights.csv").range(0, 100000);
  s.add_bool(
      "compare_pilot", run.compare_pilot,
      "also fly the vehicle's scripted pilot along the same set points, from the same starts and gusts");
}

namespace {

ManeuverTrainingOptions read_training(const ConfigSchema& c, std::uint64_t seed) {
  ManeuverTrainingOptions o;
  o.name = c.get_string("name");
  o.limits = read_limits(c);
  o.size.triangle_base = c.get_double("triangle_base");
  o.size.circle_radius = c.get_double("circle_radius");
  o.size.pause_s = c.get_double("pause_s");
  o.size.rectangle_width = c.get_double("rectangle_width");
  o.size.rectangle_height = c.get_double("rectangle_height");
  o.size.hold_end_s = c.get_double("hold_end_s");
  read_size(c, o.size);
  read_numbers(c, o);
  o.reward.alpha_pos = c.get_double("reward.alpha_pos");
  o.reward.alpha_yaw = c.get_double("reward.alpha_yaw");
  o.reward.alpha_vel = c.get_double("reward.alpha_vel");
  o.reward.alpha_action.fill(c.get_double("reward.alpha_action"));
  o.disturbance = read_training_wind(c);
  o.shaping = c.get_bool("shaping");
  o.policy.learn_delay = c.get_bool("learn_delay");
  o.policy.feedforward = c.get_bool("feedforward");
  read_optimizer_options(c, "optimizer", &o.optimizer);
  o.seed = seed;
  return o;  // run_maneuver checks it
}

}  // namespace

void resolve_maneuver_config(ConfigSchema& s) {
  resolve_gust_sigma(s);
  if (const auto v = vehicle_file_of(s)) resolve_training_wind(s, *v);
}

ManeuverRunOptions read_maneuver_config(const ConfigSchema& c, std::uint64_t seed) {
  ManeuverRunOptions o{.aircraft = vehicle_of(c),
                       .model_file = c.get_path("model"),
                       .hover_policy_file = c.get_path("hover_policy"),
                       .training = read_training(c, seed),
                       .ablations = c.get_bool("ablations")};
  read_numbers(c, o.flights);  // flights, flight_start_sigma
  o.flights.gust_sigma = c.get_double("gust_sigma");
  o.trace_flights = static_cast<int>(c.get_int("trace_flights"));
  o.compare_pilot = c.get_bool("compare_pilot");
  o.wind_source = hover_wind_source(c, o.aircraft);
  return o;
}

// ---- heli maneuver-pilot: identification data covering the manoeuvres

void declare_maneuver_pilot_config(ConfigSchema& s) {
  const ManeuverPilotRunOptions p;
  declare_vehicle(s);
  s.add_string("maneuvers", fmt::format("{}", fmt::join(p.maneuvers, ",")),
               "the manoeuvres flown after the sweeps, comma-separated (III.1, III.2, III.3, figure8)");
  declare_size(s);
  s.add_double("seconds", p.seconds, "hover and sweeps before the manoeuvres, s (as heli pilot)")
      .range(1, 36000);
  s.add_double("hover_seconds", p.hover_seconds, "plain hover before the sweeps, s").range(0, 36000);
  s.add_double("sweep_scale", p.sweep_scale,
               "multiplies the vehicle pilot's sweep amplitudes (larger sweeps excite the aircraft more than "
               "the pilot's own corrections do, which lessens closed-loop bias)")
      .range(0, 5);
  s.add_int("repeats", p.repeats, "times the three manoeuvres are flown, one after another").range(1, 100);
  declare_limits(s);
  declare_gust_sigma(s, "turbulence standard deviation per axis, m/s");
}

ManeuverPilotRunOptions read_maneuver_pilot_config(const ConfigSchema& c, std::uint64_t seed) {
  ManeuverPilotRunOptions o{.aircraft = vehicle_of(c), .maneuvers = {}};
  for (std::string_view rest = c.get_string("maneuvers"); !rest.empty();) {
    const auto comma = rest.find(',');
    o.maneuvers.emplace_back(rest.substr(0, comma));
    rest = comma == std::string_view::npos ? std::string_view() : rest.substr(comma + 1);
  }
  read_size(c, o.size);
  o.limits = read_limits(c);
  o.seconds = c.get_double("seconds");
  o.hover_seconds = c.get_double("hover_seconds");
  o.sweep_scale = c.get_double("sweep_scale");
  o.repeats = static_cast<int>(c.get_int("repeats"));
  o.gust_sigma = c.get_double("gust_sigma");
  o.seed = seed;
  return o;
}

}  // namespace pegasus::heli
