#include "pegasus/heli/runs/maneuver_runs.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "pegasus/core/error.hpp"
#include "pegasus/core/untrusted_text.hpp"
#include "pegasus/evaluators/monte_carlo.hpp"
#include "pegasus/heli/maneuver_file.hpp"
#include "pegasus/heli/maneuver_policy.hpp"
#include "pegasus/heli/pilot.hpp"
#include "pegasus/heli/policy_file.hpp"
#include "pegasus/heli/runs/flight_charts.hpp"
#include "pegasus/io/json_csv.hpp"
#include "pegasus/random/seed.hpp"
#include "pegasus/runs/charts.hpp"
#include "pegasus/vehicle/flight_log.hpp"

namespace pegasus::heli {

namespace {

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

struct Variant {
  std::string key;    // "full", "no_delay", "no_shaping"
  std::string label;  // for plots
  ManeuverTrainingOptions options;
};

// Starting point: the hover weights (a trained hover policy, or the model's trim with default gains), and
// the command limits of the model the manoeuvre trains on (a global linear model's logged range widened by
// command_margin, as hover training's; issue 48). A hover policy's own limits are its model's, whose logs may
// not be these.
struct HoverStart {
  HoverPolicyInit init;
  Theta theta;  // empty without a hover policy
};

HoverStart hover_start(const ManeuverRunOptions& options, const sysid::IdentifiedModel& model,
                       std::ostream& out) {
  HoverStart start{.init = hover_init_from_model(model), .theta = {}};
  const HoverPolicyInit limits = hover_command_limits(model, options.training.command_margin);
  start.init.command_lower = limits.command_lower;
  start.init.command_upper = limits.command_upper;
  if (options.hover_policy_file.empty()) return start;
  const std::string& file = options.hover_policy_file;
  const logs::Vehicle& vehicle = options.aircraft.vehicle;
  const PolicyFile hover = read_policy_file(file);
  if (hover.class_name != "hover")
    throw InputError(file + ": class: expected \"hover\", got \"" + hover.class_name + "\"");
  // Its networks and trim start the manoeuvre's: another aircraft's would start it from the wrong trim.
  if (const std::string trained_for = trained_vehicle(hover); trained_for != vehicle.name())
    throw InputError(
        fmt::format("{}: vehicle: the hover policy was trained for '{}', and this manoeuvre is for "
                    "'{}'; give a hover policy trained with its vehicle file",
                    printable(file), printable(trained_for), printable(vehicle.name())));
  // The manoeuvre class has no integral term: a hover policy with one starts it from its networks.
  start.theta = checked_hover_parameters(hover, file);
  if (start.theta.size() > HoverPolicy::kParameters) {
    start.theta.resize(HoverPolicy::kParameters);
    out << "note: " << file
        << " has the integral term; the manoeuvre class has none and starts from its networks\n";
  }
  start.init.trim = hover.trim;
  return start;
}

// Whether the manoeuvre has angled climbs or descents: the delay acts only on those (III.1's upper edges).
bool has_angled_legs(const ManeuverTrainingOptions& base) {
  bool angled = false;
  const auto base_trajectory = maneuver_trajectory_for(base);  // kept alive while its legs are read
  for (const auto& leg : base_trajectory->legs()) angled = angled || leg.angled();
  return angled;
}

// The variants trained: the full class, and with ablations the one without the delay and the one without
// shaping. Without angled legs the delay parameter would do nothing, so the class leaves it out and the
// no-delay ablation is the trained policy itself.
std::vector<Variant> maneuver_variants(const ManeuverRunOptions& options, bool angled,
                                       const HoverPolicyInit& init) {
  const ManeuverTrainingOptions& base = options.training;
  ManeuverTrainingOptions full_options = base;
  full_options.policy.learn_delay = base.policy.learn_delay && angled;
  std::vector<Variant> variants{{"full", "learned delay, shaping", full_options}};
  if (options.ablations) {
    Variant nd{"no_delay", "no delay", full_options};
    nd.options.policy.learn_delay = false;
    Variant ns{"no_shaping", "no shaping", full_options};
    ns.options.shaping = false;
    if (full_options.policy.learn_delay) variants.push_back(nd);
    variants.push_back(ns);
  }
  for (auto& v : variants)
    if (v.options.centre_at_trim) v.options.reward.centre = init.trim;
  return variants;
}

struct Trained {
  Theta theta;
  OptimizerSummary summary;
  std::shared_ptr<const Trajectory> trajectory;
  std::unique_ptr<ManeuverPolicy> policy;
};

// A variant's weights and optimizer summary as the checkpoint's `done` keeps them.
nlohmann::json trained_json(const Trained& t) {
  nlohmann::json history = nlohmann::json::array();
  for (const auto& h : t.summary.history)
    history.push_back({h.iteration, h.evaluations, DoubleToJson(h.value), h.seconds});
  return {{"theta", VectorToJson(t.theta)},
          {"initial_uhat", DoubleToJson(t.summary.initial_value)},
          {"final_uhat", DoubleToJson(t.summary.best_value)},
          {"iterations", t.summary.iterations},
          {"evaluations", t.summary.evaluations},
          {"history", history}};
}

void read_trained_json(const nlohmann::json& done, Trained& t) {
  t.theta = VectorFromJson(done.at("theta"), "checkpoint theta");
  t.summary.initial_value = DoubleFromJson(done.at("initial_uhat"), "initial_uhat");
  t.summary.best_value = DoubleFromJson(done.at("final_uhat"), "final_uhat");
  t.summary.iterations = done.at("iterations").get<std::int64_t>();
  t.summary.evaluations = done.at("evaluations").get<std::int64_t>();
  for (const auto& r : done.at("history"))
    t.summary.history.push_back({.iteration = r.at(0).get<std::int64_t>(),
                                 .evaluations = r.at(1).get<std::int64_t>(),
                                 .value = DoubleFromJson(r.at(2), "history"),
                                 .seconds = r.at(3).get<double>()});
}

// The starting weights of a variant's policy: the hover policy's, or the class's own.
Theta start_weights(const ManeuverPolicy& policy, const Theta& hover_theta) {
  return hover_theta.empty() ? policy.parameters().initial() : policy.from_hover(hover_theta);
}

// Each variant trained in turn, checkpointing after every optimizer iteration; a variant the checkpoint
// holds as done is read back, the one it was training resumes.
std::map<std::string, Trained> train_variants(const std::vector<Variant>& variants,
                                              const std::shared_ptr<const sysid::IdentifiedModel>& model,
                                              const HoverStart& hover, RunSink& sink, ThreadPool& pool) {
  RunDirectory& dir = sink.dir;
  std::optional<nlohmann::json> state = dir.load_checkpoint();
  nlohmann::json done = state ? state->value("done", nlohmann::json::object()) : nlohmann::json::object();
  auto bar = sink.progress("trainings", variants.size());
  bar.skip(done.size());
  std::map<std::string, Trained> trained;
  for (const auto& v : variants) {
    Trained t;
    t.trajectory = maneuver_trajectory_for(v.options);
    t.policy = std::make_unique<ManeuverPolicy>(t.trajectory, hover.init, v.options.policy);
    const Theta start = start_weights(*t.policy, hover.theta);
    if (done.contains(v.key)) {
      read_trained_json(done[v.key], t);
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
      done[v.key] = trained_json(t);
      dir.save_checkpoint({{"done", done}});
      state.reset();
    }
    bar.advance();
    trained.emplace(v.key, std::move(t));
  }
  bar.finish();
  return trained;
}

// policy.json, or policy_<variant>.json for an ablation.
void write_variant_policy(RunDirectory& dir, const ManeuverRunOptions& options, const Variant& v,
                          const Trained& t, const HoverPolicyInit& init) {
  PolicyFile file = maneuver_policy_file(file_options(v.options), *t.policy, t.theta, init.trim);
  file.provenance = {{"command", "pegasus heli maneuver"},
                     {"variant", v.key},
                     {"uhat", DoubleToJson(t.summary.best_value)},
                     {"seed", options.training.seed}};
  // Only with a vehicle file, so that the X-Cell's policy files stay as they were.
  if (options.aircraft.from_file()) file.provenance["vehicle"] = options.aircraft.vehicle.name();
  write_policy_file(dir.path() / (v.key == "full" ? std::string("policy.json") : "policy_" + v.key + ".json"),
                    file);
}

// The full variant's figures: the untrained yardstick, the pilot on request, and the training's.
void add_full_variant_summary(nlohmann::json& summary, const ManeuverRunOptions& options, const Trained& t,
                              const Theta& hover_theta, const PathObserver& observer,
                              const ManeuverFlightOptions& fo, ThreadPool& pool) {
  // Untrained yardstick: the starting weights on the same flights.
  const Theta start = start_weights(*t.policy, hover_theta);
  const auto untrained =
      summarize_maneuver_flights(fly_maneuver(*t.policy, start, observer, fo, &pool), observer.length());
  summary["rms_path_deviation_untrained_m"] = untrained.rms_path_deviation_m;
  summary["crashes_untrained"] = untrained.crashes;
  if (options.compare_pilot) {
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
}

// ideal_path.csv, and the first `trace` flights in flights.csv and path_deviation.csv: the distance to the
// path per step, apart from flights.csv (whose columns are shared by every heli command).
void write_flight_csvs(RunDirectory& dir, const Trajectory& trajectory,
                       const std::vector<ManeuverFlight>& main_flights, std::size_t trace) {
  const auto ideal = trajectory.sample(0.02);
  CsvWriter ideal_csv({"t", "x", "y", "z", "yaw"});
  for (const auto& r : ideal) ideal_csv.add_row({r[0], r[1], r[2], r[3], r[4]});
  dir.write_csv("ideal_path.csv", ideal_csv);

  FlightsCsv flights_csv;
  CsvWriter deviation_csv({"flight", "t", "path_deviation_m", "progress_m"});
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
}

void add_variant_progress_charts(RunDirectory& dir, const std::vector<Variant>& variants) {
  std::vector<std::pair<std::string, std::string>> files;
  for (const auto& v : variants) files.emplace_back(v.label, progress_file(v.key));
  const ChartSection progress = optimizer_progress_section(
      files,
      "U-hat of the best policy so far against optimizer iterations, evaluations and time, for each "
      "variant trained.");
  dir.add_charts(progress);
  dir.write_chart_svg("progress.svg", progress.charts.front());
}

// The flights' scores in summary.json: the full variant's, and each ablation's beside it.
void add_scores(nlohmann::json& summary, std::map<std::string, ManeuverFlightSummary>& scores,
                const std::map<std::string, Trained>& trained, bool ablations, bool angled) {
  const auto& m = scores.at("full");
  summary["flights"] = m.flights;
  summary["crashes"] = m.crashes;
  summary["completed"] = m.completed;
  summary["rms_path_deviation_m"] = m.rms_path_deviation_m;
  summary["max_path_deviation_m"] = m.max_path_deviation_m;
  summary["target_met"] = m.crashes == 0 && m.rms_path_deviation_m < 1.0;
  summary["z_delay_acts"] = angled;
  if (ablations && !scores.contains("no_delay")) {
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
}

}  // namespace

void run_maneuver(const ManeuverRunOptions& stated, RunSink& sink, ThreadPool& pool) {
  std::string error;
  if (!stated.training.IsValid(&error)) throw InputError(error);
  if (stated.model_file.empty())
    throw InputError("--model: an identified model file is required (heli identify)");
  const VehicleChoice& aircraft = stated.aircraft;
  const std::string simulator = aircraft.simulator();  // before training: the flights need a ground truth
  const auto model = aircraft.load_model(stated.model_file);
  // The wind in the scenarios (issue 53): stated (--wind.* or the vehicle file's [hover.wind]), else calm:
  // the manoeuvre's flights fly in gusts only, and hover's default wind was chosen for hovering in wind.
  // One line where not the X-Cell's calm.
  const TrainingWind wind =
      stated.wind_source == WindSource::kDefault
          ? TrainingWind{.disturbance = {},
                         .by = "none stated",
                         .reason =
                             "calm, as the manoeuvre's flights fly (in --gust-sigma's turbulence); "
                             "state --wind.* or [hover.wind] to train in wind"}
          : training_wind(stated.wind_source, stated.training.disturbance, *model);
  ManeuverRunOptions options = stated;
  options.training.disturbance = wind.disturbance;
  const ManeuverTrainingOptions& base = options.training;
  if (aircraft.from_file() || !base.disturbance.calm()) sink.out << training_wind_line(wind) << "\n";
  const HoverStart hover = hover_start(options, *model, sink.out);
  // The command limits the manoeuvre keeps (issue 48): said where there are any.
  if (hover.init.has_command_limits())
    sink.out << command_limits_line(hover.init, base.command_margin) << "\n";
  const bool angled = has_angled_legs(base);
  const std::vector<Variant> variants = maneuver_variants(options, angled, hover.init);
  const std::map<std::string, Trained> trained = train_variants(variants, model, hover, sink, pool);

  // ---- Flights on the ground truth, the ideal path, the policy files.
  RunDirectory& dir = sink.dir;
  ManeuverFlightOptions fo = options.flights;
  fo.seed = mix_seed(base.seed, 0x666c79);  // apart from the training scenarios
  fo.simulator = simulator;
  nlohmann::json summary = {{"maneuver", base.name}};
  if (aircraft.from_file()) summary["vehicle"] = aircraft.vehicle.name();
  // Only where not calm, and the choice only with a vehicle file: the X-Cell's summaries stay as they were.
  if (!base.disturbance.calm()) summary["wind"] = wind_summary(base.disturbance);
  if (aircraft.from_file()) summary["choices"]["wind"] = {{"by", wind.by}, {"reason", wind.reason}};
  if (hover.init.has_command_limits())
    summary["choices"]["command_limits"] = {{"lower", hover.init.command_lower},
                                            {"upper", hover.init.command_upper},
                                            {"margin", base.command_margin},
                                            {"by", "the global linear model's logged controls"}};
  aircraft.keep(dir);
  std::map<std::string, ManeuverFlightSummary> scores;
  std::vector<ManeuverFlight> main_flights;
  for (const auto& v : variants) {
    const Trained& t = trained.at(v.key);
    const PathObserver observer(*t.trajectory, v.options.observer);
    std::vector<ManeuverFlight> flights = fly_maneuver(*t.policy, t.theta, observer, fo, &pool);
    scores[v.key] = summarize_maneuver_flights(flights, observer.length());
    write_variant_policy(dir, options, v, t, hover.init);
    dir.write_csv(progress_file(v.key), optimizer_progress_csv(t.summary.history));
    if (v.key == "full") {
      add_full_variant_summary(summary, options, t, hover.theta, observer, fo, pool);
      main_flights = std::move(flights);
    }
  }
  write_flight_csvs(dir, *trained.at("full").trajectory, main_flights,
                    static_cast<std::size_t>(options.trace_flights));
  add_variant_progress_charts(dir, variants);
  add_path_charts(dir, base.name);

  add_scores(summary, scores, trained, options.ablations, angled);
  summary["gust_sigma"] = fo.gust_sigma;
  summary["policy"] = "policy.json";
  dir.write_json("summary.json", summary);
  const auto& m = scores.at("full");
  sink.out << fmt::format(
      "{}: {} flights on the ground truth, {} crashes, RMS deviation from the path {:.3f} m (max {:.2f} m)\n",
      base.name, m.flights, m.crashes, m.rms_path_deviation_m, m.max_path_deviation_m);
  for (const char* key : {"no_delay", "no_shaping"})
    if (scores.contains(key))
      sink.out << fmt::format("  {}: {} crashes, RMS deviation {:.3f} m\n", key, scores.at(key).crashes,
                              scores.at(key).rms_path_deviation_m);
  sink.out << "policy: " << sink.named(dir.final_path() / "policy.json") << "\n";
}

void run_maneuver_pilot(const ManeuverPilotRunOptions& options, RunSink& sink) {
  if (options.maneuvers.empty()) throw InputError("maneuvers: expected at least one manoeuvre name");
  for (const auto& name : options.maneuvers)
    if (std::find(kManeuverNames.begin(), kManeuverNames.end(), name) == kManeuverNames.end())
      throw InputError(
          fmt::format("maneuvers: expected names among {}, got \"{}\"", maneuver_name_list(), name));
  GroundTruthSettings settings;
  settings.gust_sigma = options.gust_sigma;
  settings.set_start = true;
  settings.start_p_W = options.size.start_W;
  const std::unique_ptr<GroundTruth> aircraft = options.aircraft.ground_truth(settings);
  PilotOptions o = pilot_options_for(options.aircraft.vehicle.simulator);
  o.hover_seconds = options.hover_seconds;
  for (double& amplitude : o.sweep_amplitude) amplitude *= options.sweep_scale;
  std::vector<Trajectory> trajectories;
  for (int r = 0; r < options.repeats; ++r)
    for (const auto& name : options.maneuvers)
      trajectories.push_back(maneuver_trajectory(name, options.size, options.limits));
  options.aircraft.check_pilot_log(*aircraft);
  const PilotFlight f = fly_pilot_maneuvers(*aircraft, o, options.seconds, trajectories, options.seed);
  RunDirectory& dir = sink.dir;
  options.aircraft.keep(dir);
  const VehicleChoice::PilotLog written = options.aircraft.write_pilot_log(dir, f.log, *aircraft);
  dir.add_charts(flight_log_sections(written.charted, "",
                                     {sysid::kLogControlColumns.begin(), sysid::kLogControlColumns.end()}));
  const double seconds = static_cast<double>(f.log.rows()) * aircraft->step_seconds();
  nlohmann::json summary = {{"seconds", seconds},
                            {"rows", written.rows},
                            {"crashed", f.crash != CrashReason::kNone},
                            {"crash_reason", crash_reason_name(f.crash)},
                            {"crash_time", f.crash_time},
                            {"log", "log.csv"}};
  if (options.aircraft.from_file()) summary["vehicle"] = options.aircraft.vehicle.name();
  if (written.charted != "log.csv") summary["pipeline_log"] = written.charted;  // log.csv in the file's terms
  dir.write_json("summary.json", summary);
  sink.out << fmt::format("flew {:.1f} s (sweeps, then the manoeuvres {} times){}; log: {}\n", seconds,
                          options.repeats,
                          f.crash != CrashReason::kNone ? ", CRASHED: " + crash_reason_name(f.crash) : "",
                          sink.named(dir.final_path() / "log.csv"));
  if (f.crash != CrashReason::kNone)
    throw std::runtime_error(
        fmt::format("the pilot crashed ({}) at {} s", crash_reason_name(f.crash), f.crash_time));
}

}  // namespace pegasus::heli
