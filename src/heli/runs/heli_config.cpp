// The helicopter experiments' config sections (heli/runs/heli_config.hpp).
#include "pegasus/heli/runs/heli_config.hpp"

#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "pegasus/core/error.hpp"
#include "pegasus/core/reward_limits.hpp"
#include "pegasus/heli/hover_task.hpp"
#include "pegasus/heli/simulators.hpp"
#include "pegasus/runs/optimizer_config.hpp"
#include "vehicle_cost_config.hpp"

namespace pegasus::heli {

using sysid::BandwidthFloor;
using sysid::IdentifyOptions;

namespace {

// A field a section takes from the vehicle file when the user set none: the field, the file's key, the value.
struct VehicleFill {
  std::string field, key;
  FieldValue (*value)(const logs::Vehicle& v);
};

const std::vector<VehicleFill>& identify_fills() {
  static const std::vector<VehicleFill> fills = {
      {"rate_hz", "log.model_rate_hz",
       [](const logs::Vehicle& v) { return FieldValue(v.log.model_rate_hz); }},
      {"extra_states", "vehicle.latent_states",
       [](const logs::Vehicle& v) { return FieldValue(v.xcell_latent_states); }},
      {"templates", "model.templates",
       [](const logs::Vehicle& v) { return FieldValue(v.kinematic_templates); }},
      {"control_rate_hz", "control.rate_hz",
       [](const logs::Vehicle& v) { return FieldValue(v.control_rate_hz); }},
  };
  return fills;
}

// And each key of the file's [hover.reward] to the field `reward.KEY`.
const std::vector<VehicleFill>& hover_fills() {
  static const std::vector<VehicleFill> fills = {
      {"control_rate_hz", "control.rate_hz",
       [](const logs::Vehicle& v) { return FieldValue(v.control_rate_hz); }},
      {"starting_gains", "hover.starting_gains",
       [](const logs::Vehicle& v) { return FieldValue(v.starting_gains); }},
      {"integral_seconds", "hover.integral_seconds",
       [](const logs::Vehicle& v) { return FieldValue(v.integral_seconds); }},
      {"target", "hover.target",
       [](const logs::Vehicle& v) {
         return FieldValue(std::vector<double>(v.target.begin(), v.target.end()));
       }},
      {"max_tilt_rad", "envelope.max_tilt_rad",
       [](const logs::Vehicle& v) { return FieldValue(v.max_tilt_rad); }},
  };
  return fills;
}
constexpr const char* kHoverRewardKeys = "hover.reward.*";

// "A, B and C": the fills' keys (and `more`), for the `vehicle` field's help.
std::string fills_help(const std::vector<VehicleFill>& fills, const std::string& more = {}) {
  std::vector<std::string> keys;
  for (const auto& f : fills) keys.push_back(f.key);
  if (!more.empty()) keys.push_back(more);
  std::string list = keys.front();
  for (std::size_t i = 1; i < keys.size(); ++i) list += (i + 1 == keys.size() ? " and " : ", ") + keys[i];
  return list;
}

void apply_fills(ConfigSchema& s, const logs::Vehicle& v, const std::vector<VehicleFill>& fills) {
  for (const auto& f : fills) set_from_vehicle(s, v, f.field, f.value(v), f.key);
}

}  // namespace

void declare_vehicle(ConfigSchema& s, const std::string& fills) {
  s.add_string(
       "vehicle", "",
       "vehicle file (README: Vehicle files; experiments/vehicles/): the aircraft's log layout, "
       "channels, rates and hover settings; empty: the X-Cell 60 in the project's own log layout" +
           (fills.empty() ? std::string() : "; its " + fills + " replace the defaults shown here unless set"))
      .input_file();
}

VehicleChoice vehicle_of(const ConfigSchema& c) { return VehicleChoice::read(c.get_path("vehicle")); }

// Sets `field` from the vehicle file unless the user set it (a config file or an option wins).
void set_from_vehicle(ConfigSchema& s, const logs::Vehicle& v, const std::string& field, FieldValue value,
                      const std::string& key) {
  if (s.origin(field) == "default") s.set(field, std::move(value), fmt::format("{}: {}", v.log.file, key));
}

namespace {

// Each registered ground truth's own gust sigma: "xcell 0.5, crazyflie2 0.2".
std::string own_gust_sigmas() {
  std::string list;
  for (const GroundTruthEntry& e : ground_truths())
    list += fmt::format("{}{} {}", list.empty() ? "" : ", ", e.name, e.own_gust_sigma);
  return list;
}

}  // namespace

void declare_gust_sigma(ConfigSchema& s, const std::string& help) {
  s.add_double("gust_sigma", own_gust_sigma("xcell"),
               fmt::format("{}; with a vehicle file, its ground truth's own unless set ({})", help,
                           own_gust_sigmas()))
      .range(0, 10);
}

std::optional<logs::Vehicle> vehicle_file_of(const ConfigSchema& s) {
  if (s.get_string("vehicle").empty()) return std::nullopt;
  return logs::read_vehicle(s.get_path("vehicle"));
}

void resolve_gust_sigma(ConfigSchema& s) {
  if (const auto v = vehicle_file_of(s); v && v->simulator != "none")
    set_from_vehicle(s, *v, "gust_sigma", own_gust_sigma(v->simulator), "vehicle.simulator");
}

void declare_bandwidth_floor(ConfigSchema& s) {
  declare_numbers(s, BandwidthFloor{}, {}, {}, sysid::kBandwidthFloorPrefix);  // BandwidthFloor::VisitFields
}

BandwidthFloor read_bandwidth_floor(const ConfigSchema& c) {
  BandwidthFloor floor;
  read_numbers(c, floor, sysid::kBandwidthFloorPrefix);
  return floor;
}

void declare_identify_config(ConfigSchema& s) {
  const IdentifyRunOptions d;
  const IdentifyOptions& id = d.identify;
  declare_vehicle(s, fills_help(identify_fills()));
  s.add_string("train", "", "training flight log (CSV in the vehicle's layout, see README)").input_file();
  s.add_string("test", "", "hold-out flight log (CSV)").input_file();
  s.add_string_list(
       "noise_check_logs", {},
       "more hold-out flight logs (CSV, the test log's layout) whose steps the noise check pools "
       "with the test log's: one flight of some minutes puts an honest band outside 3-7% by chance "
       "in a few cells of every hundred (README, Calibrated noise)")
      .input_file();
  declare_numbers(s, id.structure);  // ModelStructure::VisitFields: rate_hz
  s.add_bool("local", id.local,
             "locally weighted regression (false: globally linear); unset: the class that predicts the test "
             "log better as hover training runs it (model_choice in summary.json)");
  declare_flags(s, id.structure);  // ModelStructure::VisitFlags: extra_states, intercept, templates
  declare_numbers(s, id);          // IdentifyOptions::VisitFields
  s.add_double_list("scale_grid", id.scale_grid, "bandwidths tried, in input standard deviations")
      .min(1e-6)
      .min_size(1);
  declare_bandwidth_floor(s);
  s.add_string(
       "noise", sysid::to_string(id.noise),
       "the model's noise: white per model step (Eqs 5.5-5.6) or ar1 (each output's noise a white part "
       "plus a first-order autoregressive part fitted to the residuals' autocorrelation up to 2 s) or "
       "ar1+measurement (ar1 plus an error of the logged states themselves, which the model does not fly); "
       "with neither noise nor calibrate_noise set: ar1+measurement calibrated when the training log holds "
       "at "
       "least 120 s, white otherwise")
      .choices({"white", "ar1", "ar1+measurement"});
  s.add_bool(
      "calibrate_noise", id.calibrate_noise,
      "scale each output's noise, the part the model flies and (ar1+measurement) the log's own error apart, "
      "adding a white error of the log where it fits, so that the training log's own noise check (each "
      "window predicted without its data) has about 4.55% "
      "of its steps outside +-2 sd at each model step after a reset");
  s.add_bool(
      "horizon_sd_factors", id.horizon_sd_factors,
      "with calibrate_noise, also measure a factor on each output's sd at each model step after a reset "
      "for what the scaled noise still misstates there; the bands the model reports carry it, the noise "
      "it flies does not");
  declare_numbers(s, d);  // IdentifyRunOptions::VisitFields
  s.add_bool("whitened_gains", d.whitened_gains,
             "move the control gains closed-loop data biases to the fit that whitens the correlated noise "
             "(closed_loop_bias in summary.json); unset: whichever predicts the test log better as hover "
             "training runs it");
  s.add_bool("variants", d.variants, "also report the model-selection variants of Fig 5.2");
}

void resolve_identify_config(ConfigSchema& s) {
  if (const auto v = vehicle_file_of(s)) apply_fills(s, *v, identify_fills());
}

IdentifyRunOptions read_identify_config(const ConfigSchema& c) {
  IdentifyRunOptions o;
  o.aircraft = vehicle_of(c);
  o.train_log = c.get_path("train");
  o.test_log = c.get_path("test");
  o.noise_check_logs = c.get_path_list("noise_check_logs");
  read_numbers(c, o);  // IdentifyRunOptions::VisitFields
  o.variants = c.get_bool("variants");
  o.whitened_gains = c.get_bool("whitened_gains");
  o.choose_gains = c.origin("whitened_gains") == "default";
  IdentifyOptions& id = o.identify;
  read_numbers(c, id.structure);
  read_flags(c, id.structure);
  id.local = c.get_bool("local");
  o.choose_class = c.origin("local") == "default";
  read_numbers(c, id);
  id.scale_grid = c.get_double_list("scale_grid");
  id.min_bandwidth = read_bandwidth_floor(c);
  id.noise = sysid::parse_noise_model(c.get_string("noise"));
  id.calibrate_noise = c.get_bool("calibrate_noise");
  o.choose_noise = c.origin("noise") == "default" && c.origin("calibrate_noise") == "default";
  id.horizon_sd_factors = c.get_bool("horizon_sd_factors");
  return o;
}

void declare_pilot_config(ConfigSchema& s) {
  const PilotRunOptions d;
  declare_vehicle(s);
  s.add_double("seconds", d.seconds, "flight length, s (the thesis used 339 s to train, 140 s to test)")
      .range(1, 36000);
  s.add_double("hover_seconds", d.hover_seconds, "plain hover before the sweeps, s").range(0, 36000);
  s.add_bool("sweeps", d.sweeps,
             "fly a frequency sweep (0.1 to 3 Hz) in each channel in turn after the hover");
  s.add_double("sweep_scale", d.sweep_scale,
               "multiplies the vehicle pilot's sweep amplitudes (larger sweeps excite the aircraft more than "
               "the pilot's own corrections do, which lessens closed-loop bias)")
      .range(0, 5);
  declare_gust_sigma(s, "turbulence standard deviation per axis, m/s");
  declare_flags(s, d.settings);  // GroundTruthSettings::VisitFlags: estimate_noise
}

PilotRunOptions read_pilot_config(const ConfigSchema& c, std::uint64_t seed) {
  PilotRunOptions o{.aircraft = vehicle_of(c)};
  o.settings.gust_sigma = c.get_double("gust_sigma");
  read_flags(c, o.settings);
  o.seconds = c.get_double("seconds");
  o.hover_seconds = c.get_double("hover_seconds");
  o.sweeps = c.get_bool("sweeps");
  o.sweep_scale = c.get_double("sweep_scale");
  o.seed = seed;
  return o;
}

namespace {

// The policy's start gains and the set point (the numbers are HoverTrainingOptions's own list).
void declare_hover_start(ConfigSchema& s, const HoverTrainingOptions& defaults) {
  s.add_string(
       "starting_gains", defaults.lqr_start ? "lqr" : "constant",
       "the policy's starting gains: the X-Cell's constants, or LQR on the identified model at the hover "
       "with the reward's weights (for an aircraft with other control signs or strengths; kept only "
       "when the hover class's share of them holds the linear model)")
      .choices({"constant", "lqr"});
  s.add_double_list("target", {defaults.target.x, defaults.target.y, defaults.target.z, defaults.target.yaw},
                    "set point x, y, z (m, NED: z < 0 is up) and yaw (rad)")
      .validate([](const FieldValue& v) {
        return std::get<std::vector<double>>(v).size() == 4 ? std::string()
                                                            : std::string("4 numbers: x, y, z, yaw");
      });
}

// The reward: the typical sizes of its terms (Eq 5.9, 5.10), the judged cost and wind, and the action centre.
void declare_hover_reward(ConfigSchema& s, const HoverTrainingOptions& defaults) {
  // Each weight is 1 / this^2 (Eq 5.9, 5.10): below kMinTypicalScale it would exceed kMaxRewardWeight, and
  // the reward's own check would then blame alpha_pos instead of the option given.
  static constexpr double kMinTypicalScale = HoverReward::kMinTypicalSize;  // 1 / sqrt(kMaxRewardWeight)
  // 0 or at least kMinTypicalScale: 0 leaves the term out.
  const auto zero_or_typical = [](const FieldValue& v) {
    const double x = std::get<double>(v);
    return x == 0 || x >= kMinTypicalScale ? std::string()
                                           : fmt::format("0 or at least {}", kMinTypicalScale);
  };
  // One option per size HoverReward describes (its key, default and help).
  for (const HoverRewardSize& size : HoverReward::sizes()) {
    ConfigField& f = s.add_double(std::string("reward.") + size.key, size.typical, size.help);
    if (size.may_be_zero)
      f.min(0).validate(zero_or_typical);
    else
      f.min(kMinTypicalScale);
  }
  declare_hover_cost_and_wind(s);
  s.add_string("reward.action_centre", defaults.centre_at_trim ? "trim" : "zero",
               "controls the action cost is taken about: the logs' mean (trim) or 0 (Eq 5.10 as printed)")
      .choices({"trim", "zero"});
}

}  // namespace

void declare_hover_number(ConfigSchema& s, const std::string& key, const std::string& prefix) {
  declare_numbers(s, HoverTrainingOptions{}, key, prefix);
}

void declare_hover_config(ConfigSchema& s) {
  declare_vehicle(s, fills_help(hover_fills(), kHoverRewardKeys));
  s.add_string("model", "", "identified model (model.json of pegasus heli identify)").input_file();
  const HoverTrainingOptions defaults;
  declare_numbers(s, defaults);
  declare_hover_start(s, defaults);
  declare_hover_reward(s, defaults);
  // Gradient ascent by default (thesis 5.3), then hill climbing from its result (then_hill_climb).
  declare_optimizer_options(s, "optimizer", defaults.optimizer, continuous_class_methods(false));
  s.add_bool("then_hill_climb", defaults.then_hill_climb,
             "after gradient ascent, random-walk hill climbing (optimizer.hill_climbing) from its result");
}

void resolve_hover_config(ConfigSchema& s) {
  const auto v = vehicle_file_of(s);
  if (!v) return;
  apply_fills(s, *v, hover_fills());
  for (const auto& [key, size] : v->reward)
    set_from_vehicle(s, *v, "reward." + key, size, "hover.reward." + key);
  resolve_hover_cost_and_wind(s, *v);
}

HoverRunOptions read_hover_config(const ConfigSchema& c, std::uint64_t seed) {
  HoverRunOptions run{.aircraft = vehicle_of(c), .model_file = c.get_path("model")};
  HoverTrainingOptions& o = run.training;
  read_numbers(c, o);
  o.lqr_start = c.get_string("starting_gains") == "lqr";
  const auto& t = c.get_double_list("target");
  o.target = {t[0], t[1], t[2], t[3]};
  run.judged_cost = read_hover_cost_and_wind(c, run.aircraft.vehicle, o);
  run.wind_source = hover_wind_source(c, run.aircraft);
  read_optimizer_options(c, "optimizer", &o.optimizer);
  o.then_hill_climb = c.get_bool("then_hill_climb");
  o.seed = seed;
  return run;  // run_hover checks it
}

void declare_fly_config(ConfigSchema& s) {
  const FlyRunOptions d;
  declare_vehicle(s);
  s.add_string("policy", "", "policy file (policy.json of pegasus heli hover or heli maneuver)").input_file();
  declare_flags(s, d);  // FlyRunOptions::VisitFlags: pilot, compare_pilot, baseline, compare_baseline
  declare_numbers(s, d.flights, "flights");  // FlightOptions::VisitFields
  declare_numbers(s, d.flights, "seconds");
  declare_gust_sigma(s, "turbulence standard deviation per axis, m/s");
  declare_numbers(s, d.settings);  // GroundTruthSettings::VisitFields: wind
  declare_flags(s, d.settings);    // and VisitFlags: estimate_noise
  // By default, flights start as perturbed as hover training's scenarios.
  declare_hover_number(s, "start_pos_sigma");
  declare_hover_number(s, "start_vel_sigma");
  declare_numbers(s, d.flights, "trace_flights");
}

FlyRunOptions read_fly_config(const ConfigSchema& c, std::uint64_t seed) {
  FlyRunOptions o{.aircraft = vehicle_of(c), .policy_file = c.get_path("policy")};
  read_flags(c, o);  // FlyRunOptions::VisitFlags
  o.settings.gust_sigma = c.get_double("gust_sigma");
  read_numbers(c, o.settings);  // wind
  read_flags(c, o.settings);    // estimate_noise
  o.settings.start_pos_sigma = c.get_double("start_pos_sigma");
  o.settings.start_vel_sigma = c.get_double("start_vel_sigma");
  read_numbers(c, o.flights);  // FlightOptions::VisitFields
  o.flights.seed = seed;
  return o;
}

void declare_control_config(ConfigSchema& s) {
  declare_vehicle(s);
  s.add_string("policy", "", "policy file (policy.json of pegasus heli hover)");
  s.add_int("bench_lines", ControlRunOptions{}.bench_lines,
            "0: serve stdin; N: time N synthetic lines and print lines/s")
      .range(0, 100000000);
}

void declare_pipeline_config(ConfigSchema& s) {
  const sysid::IdentifyOptions identify_defaults;
  const HoverTrainingOptions hover_defaults;
  const FlightOptions flight_defaults;
  declare_vehicle(s);
  s.add_double("train_seconds", PilotRunOptions{}.seconds, "pilot training flight, s (thesis 5.2: 339)")
      .range(30, 36000);
  s.add_double("test_seconds", 140, "pilot hold-out flight, s (thesis 5.2: 140)").range(20, 36000);
  s.add_int("noise_check_flights", 0,
            "more pilot hold-out flights, pooled with the test flight in identification's noise check "
            "(identify --noise-check-logs): more steps a cell make the check sharper")
      .range(0, 100);
  s.add_double("noise_check_seconds", 140, "each noise-check flight, s").range(20, 36000);
  declare_numbers(s, identify_defaults, "cv_points", "identification: ");
  s.add_double_list("scale_grid", identify_defaults.scale_grid,
                    "identification: bandwidths tried, in input standard deviations")
      .min(1e-6)
      .min_size(1);
  declare_numbers(s, identify_defaults, "coordinate_passes", "identification: ");
  s.add_int("scenarios", hover_defaults.scenarios, "hover training: PEGASUS scenarios").range(1, 100000);
  s.add_double("scenario_seconds", hover_defaults.seconds, "hover training: flight per scenario, s")
      .greater_than(0)
      .max(3600);
  s.add_int("gradient_iterations", hover_defaults.optimizer.gradient.max_iterations,
            "hover training: gradient ascent iterations")
      .range(0, 1000000);
  s.add_int("hill_climbing_iterations", hover_defaults.optimizer.hill_climbing.max_iterations,
            "hover training: hill-climbing iterations")
      .range(0, 1000000);
  declare_hover_number(s, "start_pos_sigma", "hover training and flights: ");
  declare_hover_number(s, "start_vel_sigma", "hover training and flights: ");
  // The flights' numbers as fly's (FlightOptions::VisitFields): flights, and seconds as flight_seconds.
  declare_numbers(s, flight_defaults, "flights", "on the ground truth (policy and pilot): ");
  declare_numbers(s, flight_defaults, "seconds", "on the ground truth: ", "flight_");
}

}  // namespace pegasus::heli
