// `pegasus heli pilot`, `heli hover`, `heli fly` and `heli control`, and their generic forms with --vehicle:
// their options, mapped onto the library's helicopter experiments (runs/heli_runs.hpp: the ground truth
// flown by the scripted pilot, PEGASUS hover training on the identified model, flights on the ground truth,
// thesis §5.1-5.3), and the line-by-line controller server. The table also lists `heli identify`
// (heli_identify_command.cpp) and `heli pipeline` (heli_pipeline_command.cpp).
#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "experiment_commands.hpp"
#include "pegasus/core/error.hpp"
#include "pegasus/heli/control_loop.hpp"
#include "pegasus/heli/hover_task.hpp"
#include "pegasus/heli/policy_file.hpp"
#include "pegasus/heli/simulators.hpp"
#include "pegasus/logs/vehicle.hpp"
#include "pegasus/runs/optimizer_config.hpp"

namespace pegasus::cli {

// ------------------------------------------------------------------ vehicle files

void declare_vehicle(ConfigSchema& s, const std::string& fills) {
  s.add_string(
       "vehicle", "",
       "vehicle file (README: Vehicle files; experiments/vehicles/): the aircraft's log layout, "
       "channels, rates and hover settings; empty: the X-Cell 60 in the project's own log layout" +
           (fills.empty() ? std::string() : "; its " + fills + " replace the defaults shown here unless set"))
      .input_file();
}

heli::VehicleChoice aircraft_of(const ConfigSchema& c) {
  return heli::VehicleChoice::read(c.get_string("vehicle"));
}

// Sets `field` from the vehicle file unless the user set it (a config file or an option wins).
void from_vehicle(ConfigSchema& s, const logs::Vehicle& v, const std::string& field, FieldValue value,
                  const std::string& key) {
  if (s.origin(field) == "default") s.set(field, std::move(value), fmt::format("{}: {}", v.log.file, key));
}

void declare_gust_sigma(ConfigSchema& s, const std::string& help) {
  s.add_double(
       "gust_sigma", heli::own_gust_sigma("xcell"),
       fmt::format("{}; with a vehicle file, its ground truth's own unless set (xcell {}, crazyflie2 {})",
                   help, heli::own_gust_sigma("xcell"), heli::own_gust_sigma("crazyflie2")))
      .range(0, 10);
}

void resolve_gust_sigma(ConfigSchema& s) {
  if (s.get_string("vehicle").empty()) return;
  const logs::Vehicle v = logs::read_vehicle(s.get_string("vehicle"));
  if (v.simulator != "none")
    from_vehicle(s, v, "gust_sigma", heli::own_gust_sigma(v.simulator), "vehicle.simulator");
}

namespace {

using namespace pegasus::heli;
using namespace pegasus::sysid;

// ------------------------------------------------------------------ heli pilot

void declare_pilot(ConfigSchema& s) {
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
  s.add_bool("estimate_noise", d.settings.estimate_noise,
             "add Kalman-filter-like state-estimate errors to the log");
}

void run_pilot(RunContext& ctx) {
  const auto& c = ctx.config;
  PilotRunOptions o{.aircraft = aircraft_of(c)};
  o.settings.gust_sigma = c.get_double("gust_sigma");
  o.settings.estimate_noise = c.get_bool("estimate_noise");
  o.seconds = c.get_double("seconds");
  o.hover_seconds = c.get_double("hover_seconds");
  o.sweeps = c.get_bool("sweeps");
  o.sweep_scale = c.get_double("sweep_scale");
  o.seed = ctx.seed;
  RunSink sink = ctx.sink();
  heli::run_pilot(o, sink);
}

// ------------------------------------------------------------------ heli hover

void declare_hover(ConfigSchema& s) {
  declare_vehicle(s,
                  "[control] rate_hz, [hover] target, starting_gains, integral_seconds and reward, and "
                  "[envelope] max_tilt_rad");
  s.add_string("model", "", "identified model (model.json of pegasus heli identify)").input_file();
  const heli::HoverTrainingOptions defaults;
  s.add_int("scenarios", defaults.scenarios, "PEGASUS scenarios m (thesis 5.3: 30)").range(1, 100000);
  s.add_double("seconds", defaults.seconds, "flight per scenario, s (thesis 5.3: 35)")
      .greater_than(0)
      .max(3600);
  s.add_double(
       "control_rate_hz", defaults.control_rate_hz,
       "the controller's rate, Hz: the learned model steps at it and the policy is trained for it (thesis "
       "5.1: 50; a flight computer that runs its controller at 10 Hz: 10)")
      .range(0.1, 1000);
  s.add_string(
       "starting_gains", defaults.lqr_start ? "lqr" : "constant",
       "the policy's starting gains: the X-Cell's constants, or LQR on the identified model at the hover "
       "with the reward's weights (for an aircraft with other control signs or strengths; kept only "
       "when the hover class's share of them holds the linear model)")
      .choices({"constant", "lqr"});
  s.add_double(
       "integral_seconds", defaults.integral_seconds,
       "the hover class's integral term against steady offsets (wind): each channel's int weight starts "
       "at its error gain / this (LQR start: doubled until stable on the linear model); 0: none (the "
       "thesis's class)")
      .range(0, 3600);
  s.add_double("integral_limit_position", defaults.integral_limit_position,
               "anti-windup: the position error integral's limit per axis, m s")
      .greater_than(0)
      .max(1e6);
  s.add_double("integral_limit_yaw", defaults.integral_limit_yaw,
               "anti-windup: the yaw error integral's limit, rad s")
      .greater_than(0)
      .max(1e6);
  s.add_double(
       "gamma", defaults.gamma,
       "discount per 1/50 s (thesis 5.3: 0.9995 per 50 Hz step); per step it is gamma^(50 / control_rate_hz)")
      .greater_than(0)
      .max(1);
  s.add_int(
       "refit_every", defaults.refit_every,
       "learned model: steps between local-regression refits; 0: at the model's own rate (thesis 5.2.2: 5 "
       "steps at 50 Hz from a 10 Hz model)")
      .range(0, 1000);
  s.add_double("start_pos_sigma", defaults.start_pos_sigma, "start position perturbation per axis, m")
      .range(0, 100);
  s.add_double("start_vel_sigma", defaults.start_vel_sigma, "start velocity perturbation per axis, m/s")
      .range(0, 100);
  s.add_double("max_tilt_rad", defaults.max_tilt_rad,
               "the envelope: |roll| or |pitch| beyond this crashes the learned model, rad")
      .greater_than(0)
      .max(1.5);
  s.add_double("max_start_crash_fraction", defaults.max_start_crash_fraction,
               "stop before training when the starting policy crashes the learned model in more than this "
               "fraction of the scenarios (1: never stop)")
      .range(0, 1);
  s.add_double_list("target", {defaults.target.x, defaults.target.y, defaults.target.z, defaults.target.yaw},
                    "set point x, y, z (m, NED: z < 0 is up) and yaw (rad)")
      .validate([](const FieldValue& v) {
        return std::get<std::vector<double>>(v).size() == 4 ? std::string()
                                                            : std::string("4 numbers: x, y, z, yaw");
      });
  // Each weight is 1 / this^2 (Eq 5.9, 5.10): below kMinTypicalScale it would exceed kMaxRewardWeight, and
  // the reward's own check would then blame alpha_pos instead of the option given.
  static constexpr double kMinTypicalScale = 1e-6;  // 1 / sqrt(kMaxRewardWeight)
  s.add_double("reward.position_m", heli::HoverReward::kTypicalPosition,
               "typical position error: alpha_x,y,z = 1 / this^2 (Eq 5.9)")
      .min(kMinTypicalScale);
  s.add_double("reward.velocity_mps", heli::HoverReward::kTypicalVelocity,
               "typical velocity: alpha_xdot,ydot,zdot = 1 / this^2 (Eq 5.9)")
      .min(kMinTypicalScale);
  s.add_double("reward.yaw_rad", heli::HoverReward::kTypicalYaw,
               "typical yaw error: alpha_yaw = 1 / this^2 (Eq 5.9)")
      .min(kMinTypicalScale);
  // 0 or at least kMinTypicalScale: 0 leaves the term out.
  const auto zero_or_typical = [](const FieldValue& v) {
    const double x = std::get<double>(v);
    return x == 0 || x >= kMinTypicalScale ? std::string()
                                           : fmt::format("0 or at least {}", kMinTypicalScale);
  };
  s.add_double("reward.action", heli::HoverReward::kTypicalAction,
               "typical control departure: alpha_a = 1 / this^2 (Eq 5.10); 0: no action cost")
      .min(0)
      .validate(zero_or_typical);
  s.add_double("reward.attitude_rad", 0,
               "typical roll and pitch (about level): alpha = 1 / this^2; 0: no attitude term (as Eq 5.9)")
      .min(0)
      .validate(zero_or_typical);
  s.add_double("reward.rate_radps", 0,
               "typical roll, pitch and yaw rate: alpha = 1 / this^2; 0: no rate term (as Eq 5.9)")
      .min(0)
      .validate(zero_or_typical);
  s.add_string("reward.action_centre", defaults.centre_at_trim ? "trim" : "zero",
               "controls the action cost is taken about: the logs' mean (trim) or 0 (Eq 5.10 as printed)")
      .choices({"trim", "zero"});
  // Gradient ascent by default (thesis 5.3), then hill climbing from its result (then_hill_climb).
  declare_optimizer_options(s, "optimizer", defaults.optimizer, continuous_class_methods(false));
  s.add_bool("then_hill_climb", defaults.then_hill_climb,
             "after gradient ascent, random-walk hill climbing (optimizer.hill_climbing) from its result");
}

void resolve_hover(ConfigSchema& s) {
  if (s.get_string("vehicle").empty()) return;
  const logs::Vehicle v = logs::read_vehicle(s.get_string("vehicle"));
  from_vehicle(s, v, "control_rate_hz", v.control_rate_hz, "control.rate_hz");
  from_vehicle(s, v, "starting_gains", v.starting_gains, "hover.starting_gains");
  from_vehicle(s, v, "integral_seconds", v.integral_seconds, "hover.integral_seconds");
  from_vehicle(s, v, "target", std::vector<double>(v.target.begin(), v.target.end()), "hover.target");
  from_vehicle(s, v, "max_tilt_rad", v.max_tilt_rad, "envelope.max_tilt_rad");
  for (const auto& [key, size] : v.reward) from_vehicle(s, v, "reward." + key, size, "hover.reward." + key);
}

heli::HoverTrainingOptions hover_options(const RunContext& ctx) {
  const auto& c = ctx.config;
  heli::HoverTrainingOptions o;
  o.scenarios = static_cast<int>(c.get_int("scenarios"));
  o.seconds = c.get_double("seconds");
  o.gamma = c.get_double("gamma");
  o.refit_every = static_cast<int>(c.get_int("refit_every"));
  o.control_rate_hz = c.get_double("control_rate_hz");
  o.lqr_start = c.get_string("starting_gains") == "lqr";
  o.integral_seconds = c.get_double("integral_seconds");
  o.integral_limit_position = c.get_double("integral_limit_position");
  o.integral_limit_yaw = c.get_double("integral_limit_yaw");
  o.start_pos_sigma = c.get_double("start_pos_sigma");
  o.start_vel_sigma = c.get_double("start_vel_sigma");
  o.max_tilt_rad = c.get_double("max_tilt_rad");
  const auto& t = c.get_double_list("target");
  o.target = {t[0], t[1], t[2], t[3]};
  o.reward =
      heli::HoverReward::from_typical(c.get_double("reward.position_m"), c.get_double("reward.velocity_mps"),
                                      c.get_double("reward.yaw_rad"), c.get_double("reward.action"), {});
  o.reward.alpha_attitude.fill(heli::HoverReward::weight_of_typical(c.get_double("reward.attitude_rad")));
  o.reward.alpha_rate.fill(heli::HoverReward::weight_of_typical(c.get_double("reward.rate_radps")));
  o.centre_at_trim = c.get_string("reward.action_centre") == "trim";
  read_optimizer_options(c, "optimizer", &o.optimizer);
  o.then_hill_climb = c.get_bool("then_hill_climb");
  o.max_start_crash_fraction = c.get_double("max_start_crash_fraction");
  o.seed = ctx.seed;
  return o;  // run_hover checks it
}

void run_hover(RunContext& ctx) {
  const HoverRunOptions o{.aircraft = aircraft_of(ctx.config),
                          .model_file = ctx.config.get_string("model"),
                          .training = hover_options(ctx)};
  RunSink sink = ctx.sink();
  heli::run_hover(o, sink, ctx.pool());
}

// ------------------------------------------------------------------ heli fly

void declare_fly(ConfigSchema& s) {
  const FlyRunOptions d;
  const HoverTrainingOptions hover;  // by default, flights start as perturbed as hover training's scenarios
  declare_vehicle(s);
  s.add_string("policy", "", "policy file (policy.json of pegasus heli hover or heli maneuver)").input_file();
  s.add_bool("pilot", d.pilot_only, "fly the scripted pilot's hover instead of a policy");
  s.add_bool("compare_pilot", d.compare_pilot,
             "also fly the scripted pilot's hover from the same starts and gusts");
  s.add_int("flights", d.flights.flights, "flights from perturbed starts").range(1, 1000000);
  s.add_double("seconds", d.flights.seconds, "flight length, s").greater_than(0).max(36000);
  declare_gust_sigma(s, "turbulence standard deviation per axis, m/s");
  s.add_double_list("wind", {0, 0, 0}, "steady wind north, east, down (m/s, W), under the gusts")
      .validate([](const FieldValue& v) {
        const auto& w = std::get<std::vector<double>>(v);
        if (w.size() != 3) return std::string("3 numbers: north, east, down (m/s)");
        for (const double x : w)
          if (!(std::abs(x) <= 30)) return std::string("3 numbers in [-30, 30] m/s");
        return std::string();
      });
  s.add_bool("estimate_noise", d.settings.estimate_noise,
             "the controller sees Kalman-filter-like state-estimate errors");
  s.add_double("start_pos_sigma", hover.start_pos_sigma, "start position perturbation per axis, m")
      .range(0, 100);
  s.add_double("start_vel_sigma", hover.start_vel_sigma, "start velocity perturbation per axis, m/s")
      .range(0, 100);
  s.add_int("trace_flights", d.flights.trace_flights,
            "flights written step by step to flights.csv (the first ones)")
      .range(0, 1000000);
}

void run_fly(RunContext& ctx) {
  const auto& c = ctx.config;
  FlyRunOptions o{.aircraft = aircraft_of(c),
                  .policy_file = c.get_string("policy"),
                  .pilot_only = c.get_bool("pilot"),
                  .compare_pilot = c.get_bool("compare_pilot")};
  o.settings.gust_sigma = c.get_double("gust_sigma");
  o.settings.estimate_noise = c.get_bool("estimate_noise");
  o.settings.start_pos_sigma = c.get_double("start_pos_sigma");
  o.settings.start_vel_sigma = c.get_double("start_vel_sigma");
  const auto& wind = c.get_double_list("wind");
  o.settings.mean_wind_W = heli::Vec3(wind[0], wind[1], wind[2]);
  o.flights.flights = static_cast<int>(c.get_int("flights"));
  o.flights.seconds = c.get_double("seconds");
  o.flights.seed = ctx.seed;
  o.flights.trace_flights = static_cast<int>(c.get_int("trace_flights"));
  RunSink sink = ctx.sink();
  heli::run_fly(o, sink, ctx.pool());
}

// ------------------------------------------------------------------ heli control

void declare_control(ConfigSchema& s) {
  declare_vehicle(s);
  s.add_string("policy", "", "policy file (policy.json of pegasus heli hover)");
  s.add_int("bench_lines", 0, "0: serve stdin; N: time N synthetic lines and print lines/s")
      .range(0, 100000000);
}

void run_control(RunContext& ctx) {
  const std::string& path = ctx.config.get_string("policy");
  if (path.empty()) throw InputError("--policy: expected a policy file (policy.json of pegasus heli hover)");
  const heli::PolicyFile file = heli::read_policy_file(path);
  const auto controller = heli::make_controller(file, path);
  const auto bench = ctx.config.get_int("bench_lines");
  if (bench == 0) {
    double dt = 0.02;  // a line's time when it has none: the policy's rate
    if (const auto it = file.options.find("control_rate_hz");
        it != file.options.end() && it->is_number() && it->get<double>() > 0)
      dt = 1 / it->get<double>();
    // A policy trained for another aircraft (than --vehicle, or the X-Cell without one) still runs: the user
    // may mean it, but not silently.
    const logs::Vehicle vehicle = aircraft_of(ctx.config).vehicle;
    if (const std::string w = heli::other_vehicle_warning(heli::trained_vehicle(file), path, vehicle.name(),
                                                          "serving it in the terms of");
        !w.empty())
      std::fprintf(stderr, "%s\n", w.c_str());
    if (ctx.config.get_string("vehicle").empty())
      heli::run_control_loop(*controller, file.trim, stdin, stdout, stderr, dt);
    else
      heli::run_control_loop(*controller, file.trim, stdin, stdout, stderr, dt,
                             logs::control_line_format(vehicle));
    return;
  }
  if (!ctx.config.get_string("vehicle").empty())
    throw InputError(
        "--bench-lines: the synthetic lines are in the pipeline's own layout; time the loop "
        "without --vehicle");
  // Bench mode: `bench_lines` synthetic hover states through the same loop, output discarded.
  std::string input;
  for (std::int64_t i = 0; i < bench; ++i) {
    const double t = 0.02 * static_cast<double>(i);
    input += fmt::format("{},{},{},{},{},{},{},{},{},{},{},{}\n", 0.3 * std::sin(t), -0.2 * std::cos(t),
                         -10 + 0.1 * std::sin(0.5 * t), 0.05, -0.01, 0.02 * std::sin(t), 0.1, -0.1, 0.02,
                         0.01, 0.0, 0.01);
  }
  std::FILE* in = fmemopen(input.data(), input.size(), "r");
  std::FILE* out = std::fopen("/dev/null", "w");
  if (!in || !out) throw std::runtime_error("bench: cannot open the in-memory input or /dev/null");
  const auto start = std::chrono::steady_clock::now();
  const heli::ControlLoopStats stats = heli::run_control_loop(*controller, file.trim, in, out, stderr);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::fclose(in);
  std::fclose(out);
  ctx.out << fmt::format("{} lines in {:.3f} s: {:.0f} lines/s (each line parsed, answered and flushed)\n",
                         stats.lines, seconds, static_cast<double>(stats.lines) / seconds);
}

}  // namespace

std::vector<Command> heli_commands() {
  std::vector<Command> commands = {
      Command{.path = "heli pilot",
              .description = "Fly the ground-truth helicopter with the scripted pilot (hover, then sweeps) "
                             "and log it at 50 Hz",
              .declare = declare_pilot,
              .run = run_pilot,
              .resolve = resolve_gust_sigma},
      Command{.path = "heli identify",
              .description =
                  "Identify a helicopter model by locally weighted regression from flight logs (thesis 5.2)",
              .declare = declare_identify,
              .run = run_identify,
              .resolve = resolve_identify},
      Command{
          .path = "heli hover",
          .description = "Learn to hover (thesis 5.3): PEGASUS on the identified model, writes policy.json",
          .declare = declare_hover,
          .run = run_hover,
          .resolve = resolve_hover},
      Command{.path = "heli fly",
              .description =
                  "Fly a policy file (or the scripted pilot) on the ground-truth helicopter with gusts",
              .declare = declare_fly,
              .run = run_fly,
              .resolve = resolve_gust_sigma},
      Command{
          .path = "heli control",
          .description = "Serve a policy file: one state per line on stdin, four controls per line on stdout",
          .declare = declare_control,
          .run = run_control,
          .out = OutDir::kNone},
      Command{
          .path = "heli pipeline",
          .description =
              "The whole helicopter chain: pilot logs, identification, hover training, flights vs the pilot",
          .declare = declare_pipeline,
          .run = run_pipeline},
  };
  // The same commands for any aircraft a vehicle file describes; the `heli` ones are their aliases with the
  // X-Cell 60 as the default vehicle.
  const std::map<std::string, std::string> generic = {
      {"identify", "Identify an aircraft's model from its flight logs (--vehicle V.toml; thesis 5.2)"},
      {"hover", "Learn to hover an identified aircraft model by PEGASUS (--vehicle V.toml; thesis 5.3)"},
      {"pilot", "Fly the vehicle's ground truth with the scripted pilot (hover, then sweeps) and log it"},
      {"pipeline",
       "The whole chain for a vehicle with a ground truth (--vehicle V.toml): pilot logs, identification, "
       "hover "
       "training, flights vs the pilot"},
      {"fly", "Fly a policy on the vehicle's ground truth (vehicles with a simulator: xcell, crazyflie2)"},
      {"control",
       "Serve a policy to an aircraft in its own layout (--vehicle V.toml): a state line in, its "
       "controls out"}};
  for (std::size_t i = 0, n = commands.size(); i < n; ++i) {
    const std::string name = commands[i].path.substr(std::string("heli ").size());
    if (const auto it = generic.find(name); it != generic.end()) {
      Command c = commands[i];
      c.path = name;
      c.description = it->second;
      commands.push_back(std::move(c));
    }
  }
  return commands;
}

}  // namespace pegasus::cli
