// `pegasus heli maneuver`: PEGASUS learns to fly an AMA Class III competition manoeuvre on the identified
// model, then flies it on the ground-truth aircraft with gusts (thesis §5.4, Figs 5.8-5.10). Also trains the
// two ablations the issue asks for (no learned z delay, no shaping reward) with the same budget, and
// registers the "maneuver" policy class so that `pegasus heli fly --policy` and `pegasus heli control` fly
// its policy files.
#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "experiment_commands.hpp"
#include "pegasus/core/error.hpp"
#include "pegasus/evaluators/monte_carlo.hpp"
#include "pegasus/heli/hover_task.hpp"
#include "pegasus/heli/maneuver_file.hpp"
#include "pegasus/heli/maneuver_policy.hpp"
#include "pegasus/heli/maneuver_task.hpp"
#include "pegasus/heli/policy_file.hpp"
#include "pegasus/heli/simulators.hpp"
#include "pegasus/io/json_csv.hpp"
#include "pegasus/logs/vehicle.hpp"
#include "pegasus/runs/charts.hpp"
#include "pegasus/runs/flight_charts.hpp"
#include "pegasus/runs/optimizer_config.hpp"
#include "pegasus/sysid/flight_log.hpp"
#include "pegasus/sysid/identify.hpp"

namespace pegasus::cli {
namespace {

using namespace pegasus::heli;

std::vector<std::string> maneuver_choices() {
  return std::vector<std::string>(kManeuverNames.begin(), kManeuverNames.end());
}

// Where the manoeuvres start and what size the figure-eight is (both commands).
void declare_size(ConfigSchema& s) {
  s.add_double("altitude_m", -ManeuverSize{}.start_W.z(), "height of the start hover above the ground, m")
      .greater_than(0)
      .max(1000);
  s.add_double("figure_eight_radius", ManeuverSize{}.figure_eight_radius, "figure8: radius of each circle, m")
      .range(0.1, 100);
}

void read_size(const ConfigSchema& c, ManeuverSize& size) {
  size.start_W = Vec3(0, 0, -c.get_double("altitude_m"));
  size.figure_eight_radius = c.get_double("figure_eight_radius");
}

// The vehicle's ground truth flies the manoeuvres: one it has (bad input otherwise).
std::string simulator_of(const logs::Vehicle& v) {
  if (v.simulator == "none")
    throw InputError(fmt::format(
        "{}: vehicle.simulator: 'none': the project has no ground truth of {} to fly", v.log.file, v.name()));
  return v.simulator;
}

void declare(ConfigSchema& s) {
  declare_vehicle(s);
  s.add_string("name", "III.1", "manoeuvre: AMA Class III (thesis 5.4) or a figure-eight (figure8)")
      .choices(maneuver_choices());
  declare_size(s);
  s.add_string("model", "", "identified model file (model.json of `pegasus heli identify`)");
  s.add_string(
      "hover_policy", "",
      "optional: a trained hover policy file to start from (else the model's trim and default gains)");
  // Trajectory
  s.add_double("speed", 2.5, "set-point speed limit along the path, m/s").range(0.1, 20);
  s.add_double("accel", 1.0, "set-point acceleration limit, m/s^2").range(0.1, 20);
  s.add_double("yaw_rate", 1.0, "pirouette rate limit, rad/s").range(0.1, 10);
  s.add_double("yaw_accel", 1.0, "pirouette acceleration limit, rad/s^2").range(0.1, 20);
  s.add_double("triangle_base", 20, "III.1: base of the triangle, m (apex at half of it above)")
      .range(1, 200);
  s.add_double("circle_radius", 10, "III.2: radius of the circle, m").range(1, 100);
  s.add_double("pause_s", 2, "III.2: pause on the circle before circling, s").range(0, 60);
  s.add_double("rectangle_width", 20, "III.3: width of the rectangle, m").range(1, 200);
  s.add_double("rectangle_height", 10, "III.3: height of the rectangle, m").range(1, 100);
  s.add_double("hold_end_s", 3, "hover after the last leg, s").range(0, 60);
  // Training
  s.add_int("scenarios", 30, "PEGASUS scenarios m").range(1, 100000);
  s.add_double("gamma", 0.9995, "discount per 50 Hz step").greater_than(0).max(1);
  s.add_int("refit_every", 5, "learned model: 50 Hz steps between local-regression refits").range(1, 1000);
  s.add_double("start_pos_sigma", 0.5, "start position perturbation per axis, m").range(0, 10);
  s.add_double("start_vel_sigma", 0.2, "start velocity perturbation per axis, m/s").range(0, 10);
  s.add_double("reward.alpha_pos", 4, "per m^2 of distance to the path's projection").min(0);
  s.add_double("reward.alpha_yaw", 4, "per rad^2 of yaw error to the projection").min(0);
  s.add_double("reward.alpha_vel", 1, "per (m/s)^2 of velocity minus the path's velocity at the projection")
      .min(0);
  s.add_double("reward.alpha_action", 4, "per unit^2 of each control about the trim").min(0);
  s.add_bool("shaping", true, "potential-based shaping reward growing along the path");
  s.add_double("shaping_per_metre", 5, "shaping potential per m of progress along the path").min(0);
  s.add_bool("learn_delay", true,
             "learn the delay t of the vertical set point in angled climbs and descents");
  s.add_bool("feedforward", true,
             "the hover networks see the velocity relative to the set point's (learned gain)");
  declare_optimizer_options(s, "optimizer", heli::ManeuverTrainingOptions::default_optimizer(),
                            {"gradient", "hill-climb", "bobyqa", "sbplx", "crs2", "esch", "cmaes", "ars"});
  s.add_bool("ablations", true,
             "also train without the learned delay and without shaping (same budget) and fly them");
  // Flights on the ground truth
  s.add_int("flights", 20, "flights on the ground-truth aircraft per policy").range(1, 100000);
  s.add_double("gust_sigma", 0.5, "turbulence per axis on the ground truth, m/s").range(0, 10);
  s.add_double("flight_start_sigma", 0.5, "start position perturbation of the flights, m").range(0, 10);
  s.add_int("trace_flights", 20, "flights written to flights.csv").range(0, 100000);
  s.add_bool(
      "compare_pilot", false,
      "also fly the vehicle's scripted pilot along the same set points, from the same starts and gusts");
}

struct Variant {
  std::string key;    // "full", "no_delay", "no_shaping"
  std::string label;  // for plots
  ManeuverTrainingOptions options;
};

ManeuverTrainingOptions training_options(const RunContext& ctx) {
  const auto& c = ctx.config;
  ManeuverTrainingOptions o;
  o.name = c.get_string("name");
  o.limits = {.speed = c.get_double("speed"),
              .accel = c.get_double("accel"),
              .yaw_rate = c.get_double("yaw_rate"),
              .yaw_accel = c.get_double("yaw_accel")};
  o.size.triangle_base = c.get_double("triangle_base");
  o.size.circle_radius = c.get_double("circle_radius");
  o.size.pause_s = c.get_double("pause_s");
  o.size.rectangle_width = c.get_double("rectangle_width");
  o.size.rectangle_height = c.get_double("rectangle_height");
  o.size.hold_end_s = c.get_double("hold_end_s");
  read_size(c, o.size);
  o.scenarios = static_cast<int>(c.get_int("scenarios"));
  o.gamma = c.get_double("gamma");
  o.refit_every = static_cast<int>(c.get_int("refit_every"));
  o.start_pos_sigma = c.get_double("start_pos_sigma");
  o.start_vel_sigma = c.get_double("start_vel_sigma");
  o.reward.alpha_pos = c.get_double("reward.alpha_pos");
  o.reward.alpha_yaw = c.get_double("reward.alpha_yaw");
  o.reward.alpha_vel = c.get_double("reward.alpha_vel");
  o.reward.alpha_action.fill(c.get_double("reward.alpha_action"));
  o.shaping = c.get_bool("shaping");
  o.shaping_per_metre = c.get_double("shaping_per_metre");
  o.policy.learn_delay = c.get_bool("learn_delay");
  o.policy.feedforward = c.get_bool("feedforward");
  read_optimizer_options(c, "optimizer", &o.optimizer);
  o.seed = ctx.seed;
  std::string error;
  if (!o.IsValid(&error)) throw InputError(error);
  return o;
}

ManeuverFileOptions file_options(const ManeuverTrainingOptions& o) {
  return {.name = o.name, .size = o.size, .limits = o.limits, .policy = o.policy};
}

// The flights against the ideal path (Fig 5.10): from above, from the side, altitude and distance to the path
// against time, and the 3-D replay; the SVGs are drawn from the same charts.
void add_path_charts(const RunDirectory& dir, const std::string& maneuver) {
  const ChartTrace ideal{.file = "ideal_path.csv", .name = "ideal path", .dash = "dash", .color = "#000000"};
  const ChartTrace flown{
      .file = "flights.csv", .group_by = {"flight"}, .name = "flight", .max_groups = 10, .width = 1};
  auto along = [](ChartTrace t, std::string x, std::string y, double y_factor = 1.0) {
    t.x = std::move(x);
    t.y = std::move(y);
    t.y_factor = y_factor;
    return t;
  };
  const Chart top{.title = maneuver + ": seen from above",
                  .x = {"y, east (m)"},
                  .y = {"x, north (m)"},
                  .traces = {along(ideal, "y", "x"), along(flown, "y", "x")},
                  .equal_aspect = true};
  const Chart side{.title = maneuver + ": side view",
                   .x = {"x, north (m)"},
                   .y = {"altitude -z (m)"},
                   .traces = {along(ideal, "x", "z", -1), along(flown, "x", "z", -1)},
                   .equal_aspect = true};
  const Chart altitude{.title = "Altitude against time",
                       .x = {"time (s)"},
                       .y = {"altitude -z (m)"},
                       .traces = {along(ideal, "t", "z", -1), along(flown, "t", "z", -1)}};
  const Chart deviation{.title = maneuver + ": distance to the ideal path (ground truth, gusts)",
                        .x = {"time (s)"},
                        .y = {"distance to the path (m)"},
                        .traces = {{.file = "path_deviation.csv",
                                    .x = "t",
                                    .y = "path_deviation_m",
                                    .group_by = {"flight"},
                                    .name = "flight",
                                    .max_groups = 5,
                                    .width = 1.2}},
                        .size = "wide"};
  dir.add_charts(ChartSection{
      .id = "replay",
      .title = "3-D replay against the ideal path (Fig 5.10)",
      .intro =
          "Drag to turn the view, scroll to zoom; Play runs the flight in real time (speed adjustable), the "
          "slider moves through it. Coloured lines: the flights; black dashed: the ideal path.",
      .charts = {flight_replay_chart({{.file = "flights.csv", .label = "policy flight"}}, "ideal_path.csv"),
                 top, side, altitude, deviation}});
  dir.write_chart_svg("paths_top.svg", top);
  dir.write_chart_svg("paths_side.svg", side);
  dir.write_chart_svg("deviation.svg", deviation);
}

std::string progress_file(const std::string& variant) {
  return variant == "full" ? std::string("progress.csv") : "progress_" + variant + ".csv";
}

void run(RunContext& ctx) {
  const auto& c = ctx.config;
  if (c.get_string("model").empty())
    throw InputError("--model: an identified model file is required (heli identify)");
  const ManeuverTrainingOptions base = training_options(ctx);
  const heli::VehicleChoice aircraft = aircraft_of(c);
  const logs::Vehicle& vehicle = aircraft.vehicle;
  const std::string simulator = simulator_of(vehicle);  // before training: the flights need a ground truth
  const auto model = aircraft.load_model(c.get_string("model"));

  // Starting point: the hover weights (a trained hover policy, or the model's trim with default gains).
  HoverPolicyInit init = hover_init_from_model(*model);
  Theta hover_theta;
  if (!c.get_string("hover_policy").empty()) {
    const std::string file = c.get_string("hover_policy");
    const PolicyFile hover = read_policy_file(file);
    if (hover.class_name != "hover")
      throw InputError(file + ": class: expected \"hover\", got \"" + hover.class_name + "\"");
    // The manoeuvre class has no integral term: a hover policy with one starts it from its networks.
    hover_theta = checked_hover_parameters(hover, file);
    if (hover_theta.size() > HoverPolicy::kParameters) {
      hover_theta.resize(HoverPolicy::kParameters);
      ctx.out << "note: " << file
              << " has the integral term; the manoeuvre class has none and starts from its networks\n";
    }
    init.trim = hover.trim;
  }

  // The delay acts only on angled climbs and descents (III.1's upper edges); without such legs the parameter
  // would do nothing, so the class leaves it out and the no-delay ablation is the trained policy itself.
  bool angled = false;
  const auto base_trajectory = maneuver_trajectory_for(base);  // kept alive while its legs are read
  for (const auto& leg : base_trajectory->legs()) angled = angled || leg.angled();
  ManeuverTrainingOptions full_options = base;
  full_options.policy.learn_delay = base.policy.learn_delay && angled;
  std::vector<Variant> variants{{"full", "learned delay, shaping", full_options}};
  if (c.get_bool("ablations")) {
    Variant nd{"no_delay", "no delay", full_options};
    nd.options.policy.learn_delay = false;
    Variant ns{"no_shaping", "no shaping", full_options};
    ns.options.shaping = false;
    if (full_options.policy.learn_delay) variants.push_back(nd);
    variants.push_back(ns);
  }
  for (auto& v : variants)
    if (v.options.centre_at_trim) v.options.reward.centre = init.trim;

  RunDirectory& dir = ctx.run_directory();
  ThreadPool& pool = ctx.pool();
  std::optional<nlohmann::json> state = dir.load_checkpoint();
  nlohmann::json done = state ? state->value("done", nlohmann::json::object()) : nlohmann::json::object();
  auto bar = ctx.progress("trainings", variants.size());
  bar.skip(done.size());

  struct Trained {
    Theta theta;
    OptimizerSummary summary;
    std::shared_ptr<const Trajectory> trajectory;
    std::unique_ptr<ManeuverPolicy> policy;
  };
  std::map<std::string, Trained> trained;
  for (const auto& v : variants) {
    Trained t;
    t.trajectory = maneuver_trajectory_for(v.options);
    t.policy = std::make_unique<ManeuverPolicy>(t.trajectory, init, v.options.policy);
    const Theta start =
        hover_theta.empty() ? t.policy->parameters().initial() : t.policy->from_hover(hover_theta);
    if (done.contains(v.key)) {
      t.theta = VectorFromJson(done[v.key].at("theta"), "checkpoint theta");
      t.summary.initial_value = DoubleFromJson(done[v.key].at("initial_uhat"), "initial_uhat");
      t.summary.best_value = DoubleFromJson(done[v.key].at("final_uhat"), "final_uhat");
      t.summary.iterations = done[v.key].at("iterations").get<std::int64_t>();
      t.summary.evaluations = done[v.key].at("evaluations").get<std::int64_t>();
      for (const auto& r : done[v.key].at("history"))
        t.summary.history.push_back({.iteration = r.at(0).get<std::int64_t>(),
                                     .evaluations = r.at(1).get<std::int64_t>(),
                                     .value = DoubleFromJson(r.at(2), "history"),
                                     .seconds = r.at(3).get<double>()});
    } else {
      ManeuverTrainingHooks hooks;
      hooks.checkpoint_every = 1;
      hooks.on_checkpoint = [&](const nlohmann::json& ck) {
        dir.save_checkpoint({{"done", done}, {"current", v.key}, {"optimizer", ck}});
      };
      if (state && state->value("current", "") == v.key && state->contains("optimizer"))
        hooks.resume_from = state->at("optimizer");
      ManeuverTrainingResult r = train_maneuver(model, v.options, *t.policy, start, hooks, pool);
      t.theta = r.theta;
      t.summary = std::move(r.summary);
      nlohmann::json history = nlohmann::json::array();
      for (const auto& h : t.summary.history)
        history.push_back({h.iteration, h.evaluations, DoubleToJson(h.value), h.seconds});
      done[v.key] = {{"theta", VectorToJson(t.theta)},
                     {"initial_uhat", DoubleToJson(t.summary.initial_value)},
                     {"final_uhat", DoubleToJson(t.summary.best_value)},
                     {"iterations", t.summary.iterations},
                     {"evaluations", t.summary.evaluations},
                     {"history", history}};
      dir.save_checkpoint({{"done", done}});
      state.reset();
    }
    bar.advance();
    trained.emplace(v.key, std::move(t));
  }
  bar.finish();

  // ---- Flights on the ground truth, the ideal path, the policy files.
  ManeuverFlightOptions fo;
  fo.flights = static_cast<int>(c.get_int("flights"));
  fo.gust_sigma = c.get_double("gust_sigma");
  fo.start_pos_sigma = c.get_double("flight_start_sigma");
  fo.seed = mix_seed(ctx.seed, 0x666c79);  // apart from the training scenarios
  fo.simulator = simulator;
  nlohmann::json summary = {{"maneuver", base.name}};
  if (!c.get_string("vehicle").empty()) summary["vehicle"] = vehicle.name();
  aircraft.keep(dir);
  std::map<std::string, ManeuverFlightSummary> scores;
  std::vector<ManeuverFlight> main_flights;
  for (const auto& v : variants) {
    const Trained& t = trained.at(v.key);
    const PathObserver observer(*t.trajectory, v.options.observer);
    std::vector<ManeuverFlight> flights = fly_maneuver(*t.policy, t.theta, observer, fo, &pool);
    scores[v.key] = summarize_maneuver_flights(flights, observer.length());
    PolicyFile file = maneuver_policy_file(file_options(v.options), *t.policy, t.theta, init.trim);
    file.provenance = {{"command", "pegasus heli maneuver"},
                       {"variant", v.key},
                       {"uhat", DoubleToJson(t.summary.best_value)},
                       {"seed", ctx.seed}};
    write_policy_file(
        dir.path() / (v.key == "full" ? std::string("policy.json") : "policy_" + v.key + ".json"), file);

    dir.write_csv(progress_file(v.key), optimizer_progress_csv(t.summary.history));
    if (v.key == "full") {
      // Untrained yardstick: the starting weights on the same flights.
      const Theta start =
          hover_theta.empty() ? t.policy->parameters().initial() : t.policy->from_hover(hover_theta);
      const auto untrained =
          summarize_maneuver_flights(fly_maneuver(*t.policy, start, observer, fo, &pool), observer.length());
      summary["rms_path_deviation_untrained_m"] = untrained.rms_path_deviation_m;
      summary["crashes_untrained"] = untrained.crashes;
      if (c.get_bool("compare_pilot")) {
        // The vehicle's scripted pilot on the same set points, starts and gusts.
        const auto pilot = summarize_maneuver_flights(
            fly_pilot_maneuver(*t.trajectory, pilot_options_for(fo.simulator), observer, fo, &pool),
            observer.length());
        summary["pilot"] = {{"crashes", pilot.crashes},
                            {"completed", pilot.completed},
                            {"rms_path_deviation_m", pilot.rms_path_deviation_m},
                            {"max_path_deviation_m", pilot.max_path_deviation_m}};
      }
      summary["initial_uhat"] = DoubleToJson(t.summary.initial_value);
      summary["final_uhat"] = DoubleToJson(t.summary.best_value);
      summary["iterations"] = t.summary.iterations;
      summary["evaluations"] = t.summary.evaluations;
      summary["z_delay_s"] = t.policy->z_delay(t.theta);
      summary["feedforward"] = t.policy->feedforward(t.theta);
      summary["trajectory_seconds"] = t.trajectory->duration();
      summary["path_length_m"] = observer.length();
      main_flights = std::move(flights);
    }
  }
  const Trained& full = trained.at("full");
  const auto ideal = full.trajectory->sample(0.02);
  CsvWriter ideal_csv({"t", "x", "y", "z", "yaw"});
  for (const auto& r : ideal) ideal_csv.add_row({r[0], r[1], r[2], r[3], r[4]});
  dir.write_csv("ideal_path.csv", ideal_csv);

  FlightsCsv flights_csv;
  // The distance to the path per step, apart from flights.csv (whose columns are shared by every heli
  // command).
  CsvWriter deviation_csv({"flight", "t", "path_deviation_m", "progress_m"});
  const auto trace = static_cast<std::size_t>(c.get_int("trace_flights"));
  for (std::size_t i = 0; i < main_flights.size() && i < trace; ++i) {
    const auto& f = main_flights[i];
    for (std::size_t k = 0; k < f.truth.size(); ++k) {
      flights_csv.add(static_cast<std::int64_t>(i), {.time = static_cast<double>(k) * 0.02,
                                                     .truth = f.truth[k],
                                                     .controls = f.controls[k],
                                                     .target = f.targets[k]});
      deviation_csv.add_row(
          {static_cast<std::int64_t>(i), static_cast<double>(k) * 0.02, f.deviation[k], f.progress[k]});
    }
  }
  dir.write_csv("flights.csv", flights_csv.csv());
  dir.write_csv("path_deviation.csv", deviation_csv);
  {
    std::vector<std::pair<std::string, std::string>> files;
    for (const auto& v : variants) files.emplace_back(v.label, progress_file(v.key));
    const ChartSection progress = optimizer_progress_section(
        files,
        "U-hat of the best policy so far against optimizer iterations, evaluations and time, for each "
        "variant trained.");
    dir.add_charts(progress);
    dir.write_chart_svg("progress.svg", progress.charts.front());
  }

  add_path_charts(dir, base.name);

  const auto& m = scores.at("full");
  summary["flights"] = m.flights;
  summary["crashes"] = m.crashes;
  summary["completed"] = m.completed;
  summary["rms_path_deviation_m"] = m.rms_path_deviation_m;
  summary["max_path_deviation_m"] = m.max_path_deviation_m;
  summary["target_met"] = m.crashes == 0 && m.rms_path_deviation_m < 1.0;
  summary["z_delay_acts"] = angled;
  if (c.get_bool("ablations") && !scores.contains("no_delay")) {
    // No angled legs: the policy without the delay is the trained one.
    scores["no_delay"] = m;
  }
  for (const char* key : {"no_delay", "no_shaping"}) {
    if (!scores.contains(key)) continue;
    summary[fmt::format("rms_path_deviation_{}_m", key)] = scores.at(key).rms_path_deviation_m;
    summary[fmt::format("crashes_{}", key)] = scores.at(key).crashes;
    const std::string trained_key = trained.contains(key) ? key : "full";
    summary[fmt::format("final_uhat_{}", key)] = DoubleToJson(trained.at(trained_key).summary.best_value);
  }
  summary["gust_sigma"] = fo.gust_sigma;
  summary["policy"] = "policy.json";
  dir.write_json("summary.json", summary);
  ctx.out << fmt::format(
      "{}: {} flights on the ground truth, {} crashes, RMS deviation from the path {:.3f} m (max {:.2f} m)\n",
      base.name, m.flights, m.crashes, m.rms_path_deviation_m, m.max_path_deviation_m);
  for (const char* key : {"no_delay", "no_shaping"})
    if (scores.contains(key))
      ctx.out << fmt::format("  {}: {} crashes, RMS deviation {:.3f} m\n", key, scores.at(key).crashes,
                             scores.at(key).rms_path_deviation_m);
  ctx.out << "policy: " << (dir.final_path() / "policy.json").string() << "\n";
}

// ---- heli maneuver-pilot: identification data covering the manoeuvres

void declare_pilot(ConfigSchema& s) {
  declare_vehicle(s);
  s.add_string("maneuvers", "III.1,III.2,III.3",
               "the manoeuvres flown after the sweeps, comma-separated (III.1, III.2, III.3, figure8)");
  declare_size(s);
  s.add_double("seconds", 339, "hover and sweeps before the manoeuvres, s (as heli pilot)").range(1, 36000);
  s.add_double("hover_seconds", 10, "plain hover before the sweeps, s").range(0, 36000);
  s.add_double("sweep_scale", 1,
               "multiplies the vehicle pilot's sweep amplitudes (larger sweeps excite the aircraft more than "
               "the pilot's own corrections do, which lessens closed-loop bias)")
      .range(0, 5);
  s.add_int("repeats", 2, "times the three manoeuvres are flown, one after another").range(1, 100);
  s.add_double("speed", 2.5, "set-point speed limit along the path, m/s").range(0.1, 20);
  s.add_double("accel", 1.0, "set-point acceleration limit, m/s^2").range(0.1, 20);
  s.add_double("yaw_rate", 1.0, "pirouette rate limit, rad/s").range(0.1, 10);
  s.add_double("yaw_accel", 1.0, "pirouette acceleration limit, rad/s^2").range(0.1, 20);
  s.add_double("gust_sigma", 0.5, "turbulence standard deviation per axis, m/s").range(0, 10);
}

void run_pilot(RunContext& ctx) {
  const auto& c = ctx.config;
  const heli::VehicleChoice aircraft_file = aircraft_of(c);
  const logs::Vehicle& vehicle = aircraft_file.vehicle;
  ManeuverSize size;
  read_size(c, size);
  GroundTruthSettings settings;
  settings.gust_sigma = c.get_double("gust_sigma");
  settings.set_start = true;
  settings.start_p_W = size.start_W;
  std::unique_ptr<GroundTruth> aircraft;
  try {
    aircraft = make_ground_truth(simulator_of(vehicle), settings);
  } catch (const std::invalid_argument& e) {
    throw InputError(e.what());
  }
  PilotOptions o = pilot_options_for(vehicle.simulator);
  o.hover_seconds = c.get_double("hover_seconds");
  for (double& amplitude : o.sweep_amplitude) amplitude *= c.get_double("sweep_scale");
  std::vector<std::string> names;
  for (std::string_view rest = c.get_string("maneuvers"); !rest.empty();) {
    const auto comma = rest.find(',');
    const std::string name(rest.substr(0, comma));
    if (std::find(kManeuverNames.begin(), kManeuverNames.end(), name) == kManeuverNames.end())
      throw InputError(
          fmt::format("maneuvers: expected names among {}, got \"{}\"", maneuver_name_list(), name));
    names.push_back(name);
    rest = comma == std::string_view::npos ? std::string_view() : rest.substr(comma + 1);
  }
  if (names.empty()) throw InputError("maneuvers: expected at least one manoeuvre name");
  const TrajectoryLimits limits{.speed = c.get_double("speed"),
                                .accel = c.get_double("accel"),
                                .yaw_rate = c.get_double("yaw_rate"),
                                .yaw_accel = c.get_double("yaw_accel")};
  std::vector<Trajectory> trajectories;
  for (std::int64_t r = 0; r < c.get_int("repeats"); ++r)
    for (const auto& name : names) trajectories.push_back(maneuver_trajectory(name, size, limits));
  const PilotFlight f = fly_pilot_maneuvers(*aircraft, o, c.get_double("seconds"), trajectories, ctx.seed);
  RunDirectory& dir = ctx.run_directory();
  aircraft_file.keep(dir);
  dir.write_text("log.csv", sysid::flight_log_csv(f.log));
  dir.add_charts(flight_log_sections("log.csv", "",
                                     {sysid::kLogControlColumns.begin(), sysid::kLogControlColumns.end()}));
  const double seconds = static_cast<double>(f.log.rows()) * aircraft->step_seconds();
  nlohmann::json summary = {{"seconds", seconds},
                            {"rows", f.log.rows()},
                            {"crashed", f.crash != CrashReason::kNone},
                            {"crash_reason", crash_reason_name(f.crash)},
                            {"crash_time", f.crash_time},
                            {"log", "log.csv"}};
  if (!c.get_string("vehicle").empty()) summary["vehicle"] = vehicle.name();
  dir.write_json("summary.json", summary);
  ctx.out << fmt::format("flew {:.1f} s (sweeps, then the manoeuvres {} times){}; log: {}\n", seconds,
                         c.get_int("repeats"),
                         f.crash != CrashReason::kNone ? ", CRASHED: " + crash_reason_name(f.crash) : "",
                         (dir.final_path() / "log.csv").string());
  if (f.crash != CrashReason::kNone)
    throw std::runtime_error(
        fmt::format("the pilot crashed ({}) at {} s", crash_reason_name(f.crash), f.crash_time));
}

}  // namespace

std::vector<Command> heli_maneuver_commands() {
  std::vector<Command> commands = {
      Command{.path = "heli maneuver",
              .description = "Learn an AMA Class III manoeuvre (III.1, III.2, III.3) with PEGASUS and "
                             "fly it on the ground truth (thesis 5.4)",
              .declare = declare,
              .run = run},
      Command{.path = "heli maneuver-pilot",
              .description = "Fly the scripted pilot through hover, sweeps and the three manoeuvres: "
                             "identification data that covers them",
              .declare = declare_pilot,
              .run = run_pilot}};
  // The same for any vehicle with a ground truth (--vehicle V.toml); the `heli` ones fly the X-Cell 60.
  Command maneuver = commands[0], pilot = commands[1];
  maneuver.path = "maneuver";
  maneuver.description =
      "Learn a manoeuvre or a figure-eight on a vehicle's identified model and fly it on its "
      "ground truth (--vehicle V.toml)";
  pilot.path = "maneuver-pilot";
  pilot.description =
      "Fly a vehicle's scripted pilot through hover, sweeps and manoeuvres (--vehicle V.toml, --maneuvers)";
  commands.push_back(std::move(maneuver));
  commands.push_back(std::move(pilot));
  return commands;
}

}  // namespace pegasus::cli
