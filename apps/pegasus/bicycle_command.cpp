// `pegasus bicycle ...`: Randlov and Alstrom's bicycle ridden to a goal 1 km away by PEGASUS (thesis §4.6).
#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <numbers>

#include "experiment_commands.hpp"
#include "pegasus/core/error.hpp"
#include "pegasus/experiments/bicycle_experiment.hpp"
#include "pegasus/io/json_csv.hpp"
#include "pegasus/runs/charts.hpp"
#include "pegasus/runs/optimizer_config.hpp"

namespace pegasus::cli {
namespace {

// ---- Config fields shared by the commands ------------------------------------------------------------

void declare_training(ConfigSchema& s) {
  s.add_int("scenarios", 30, "PEGASUS scenarios m").min(1).max(100000);
  s.add_double("gamma", 0.998, "discount per 0.01 s step").greater_than(0).max(1);
  s.add_int("horizon", 500, "training rollout length H (steps of 0.01 s)").min(1).max(1000000);
  s.add_double("shaping_per_metre", 1.0, "shaping potential per metre of progress towards the goal").min(0);
  s.add_double("fall_reward", -100.0, "reward of falling over (absorbing)").max(0);
  s.add_string("variant", "plain", "scenario variant")
      .choices({"plain", "antithetic", "stratified", "sobol"});
  s.add_string("initial_policy", "balance",
               "starting weights: a crude hand-set balancing feedback, or all zero")
      .choices({"balance", "zero"});
  // Bounded-step gradient ascent (thesis 4.6) by default; every method for a continuous class.
  declare_optimizer_options(s, "optimizer", BicycleTrainingOptions::default_optimizer(),
                            {"gradient", "hill-climb", "bobyqa", "sbplx", "crs2", "esch", "cmaes", "ars"});
}

void declare_riding(ConfigSchema& s, std::int64_t rides) {
  s.add_int("rides", rides, "rides of each policy, from the initial-state distribution with fresh noise")
      .min(0)
      .max(1000000);
  s.add_double("max_km", 10.0, "a ride that has not reached the goal stops after this distance")
      .greater_than(0)
      .max(1000);
  s.add_double("goal_km", 1.0, "distance of the goal from the start").greater_than(0).max(100);
  s.add_double("goal_radius", 10.0, "radius of the goal circle (m)").greater_than(0);
}

BicycleTrainingOptions training_options(const RunContext& ctx) {
  const auto& c = ctx.config;
  BicycleTrainingOptions o;
  o.scenarios = static_cast<int>(c.get_int("scenarios"));
  o.gamma = c.get_double("gamma");
  o.horizon = static_cast<int>(c.get_int("horizon"));
  o.shaping_per_metre = c.get_double("shaping_per_metre");
  o.bicycle.fall_reward = c.get_double("fall_reward");
  o.variant = parse_scenario_variant(c.get_string("variant"));
  o.initial_policy = c.get_string("initial_policy");
  read_optimizer_options(c, "optimizer", &o.optimizer);
  o.seed = ctx.seed;
  o.threads = ctx.threads;
  return o;
}

BicycleRideOptions ride_options(const RunContext& ctx) {
  const auto& c = ctx.config;
  BicycleRideOptions o;
  o.rides = static_cast<int>(std::max<std::int64_t>(1, c.get_int("rides")));
  o.max_km = c.get_double("max_km");
  o.bicycle.goal = BicycleGoal::circle(1000.0 * c.get_double("goal_km"), 0.0, c.get_double("goal_radius"));
  o.bicycle.fall_reward = c.get_double("fall_reward");
  o.seed = bicycle_ride_seed(ctx.seed, 0);  // apart from the training scenarios
  return o;
}

// ---- Output -------------------------------------------------------------------------------------------

nlohmann::json number_or_null(double x) {
  return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr);
}

nlohmann::json ride_summary_json(const BicycleRideSummary& s) {
  return {{"median_distance_km", number_or_null(s.median_distance_km)},
          {"worst_distance_km", number_or_null(s.worst_distance_km)},
          {"falls", s.falls},
          {"reached", s.reached},
          {"rides", s.rides}};
}

void add_ride_rows(CsvWriter& csv, const std::string& method, int trial,
                   const std::vector<BicycleRide>& rides) {
  for (std::size_t i = 0; i < rides.size(); ++i)
    csv.add_row({method, std::int64_t{trial}, static_cast<std::int64_t>(i), rides[i].distance_km,
                 std::int64_t{rides[i].reached ? 1 : 0}, std::int64_t{rides[i].fell ? 1 : 0}});
}

// The rides seen from above (ride_paths.csv) and the goal circle (goal.csv), as a chart and its SVG.
void write_rides_from_above(const RunDirectory& dir, const std::vector<BicycleRide>& rides,
                            const BicycleGoal& goal, const std::string& title, const std::string& svg) {
  CsvWriter paths({"ride", "x", "y"});
  for (std::size_t i = 0; i < rides.size(); ++i)
    for (std::size_t k = 0; k < rides[i].x.size(); ++k)
      paths.add_row({static_cast<std::int64_t>(i), rides[i].x[k], rides[i].y[k]});
  dir.write_csv("ride_paths.csv", paths);
  CsvWriter circle({"x", "y"});
  for (int k = 0; k <= 64; ++k) {
    const double a = 2.0 * std::numbers::pi * k / 64;
    circle.add_row({goal.x + goal.radius * std::cos(a), goal.y + goal.radius * std::sin(a)});
  }
  dir.write_csv("goal.csv", circle);
  const Chart from_above{
      .title = title,
      .x = {"x (m)"},
      .y = {"y (m)"},
      .traces = {{.file = "ride_paths.csv",
                  .x = "x",
                  .y = "y",
                  .group_by = {"ride"},
                  .name = "front tyre",
                  .one_trace = true,
                  .width = 1},
                 {.file = "goal.csv", .x = "x", .y = "y", .name = "goal", .color = "#000000"}},
      .equal_aspect = true};
  dir.add_charts(ChartSection{.id = "rides-from-above",
                              .title = "Rides seen from above",
                              .intro = "The path of the front tyre on each ride, and the goal.",
                              .charts = {from_above}});
  dir.write_chart_svg(svg, from_above);
}

// Distances ridden, a box per policy (rides.csv).
void add_distance_chart(const RunDirectory& dir) {
  dir.add_charts(ChartSection{
      .id = "rides",
      .title = "Rides",
      .intro = "Each policy ridden from the initial-state distribution with fresh noise (rides.csv).",
      .charts = {{.kind = ChartKind::kBox,
                  .title = "Distance ridden to the goal",
                  .y = {"distance ridden (km)"},
                  .traces = {{.file = "rides.csv", .y = "distance_km", .group_by = {"method", "trial"}}}}}});
}

// Rides of one policy with their paths, for the plot.
std::vector<BicycleRide> rides_with_paths(const Theta& theta, BicycleRideOptions o, ThreadPool& pool) {
  o.path_every = 25;
  return ride_bicycle(theta, o, &pool);
}

// ---- pegasus bicycle experiment -----------------------------------------------------------------------

void run_experiment(RunContext& ctx) {
  const auto& c = ctx.config;
  BicycleExperimentOptions o;
  o.trials = static_cast<int>(c.get_int("trials"));
  o.lesson_trials = static_cast<int>(std::min(c.get_int("lesson_trials"), c.get_int("trials")));
  o.training = training_options(ctx);
  o.riding = ride_options(ctx);
  o.seed = ctx.seed;
  o.threads = ctx.threads;
  std::string error;
  if (!o.IsValid(&error)) throw InputError(error);

  RunDirectory& dir = ctx.run_directory();
  BicycleExperimentHooks hooks;
  hooks.resume_from = dir.load_checkpoint();
  const std::size_t jobs = static_cast<std::size_t>(o.trials + 2 * o.lesson_trials);
  auto bar = ctx.progress("trainings", jobs);
  if (hooks.resume_from) bar.skip(hooks.resume_from->at("trials").size());
  hooks.on_checkpoint = [&](const nlohmann::json& state) { dir.save_checkpoint(state); };
  hooks.on_trial = [&](const BicycleTrial&) { bar.advance(); };
  const BicycleExperimentResult result = run_bicycle_experiment(o, hooks);
  bar.finish();

  CsvWriter rides({"method", "trial", "ride", "distance_km", "reached", "fell"});
  CsvWriter curves({"method", "trial", "iteration", "uhat"});
  CsvWriter trials({"method", "trial", "initial_uhat", "final_uhat", "pegasus_uhat", "iterations",
                    "evaluations", "median_distance_km", "worst_distance_km", "reached", "falls"});
  nlohmann::json policies = nlohmann::json::array(), lessons = nlohmann::json::array();
  for (const auto& t : result.trials) {
    add_ride_rows(rides, t.method, t.trial, t.rides);
    for (std::size_t k = 0; k < t.curve.size(); ++k)
      curves.add_row({t.method, std::int64_t{t.trial}, static_cast<std::int64_t>(k + 1), t.curve[k]});
    trials.add_row({t.method, std::int64_t{t.trial}, t.initial_uhat, t.final_uhat, t.pegasus_uhat,
                    t.iterations, t.evaluations, t.summary.median_distance_km, t.summary.worst_distance_km,
                    std::int64_t{t.summary.reached}, std::int64_t{t.summary.falls}});
    nlohmann::json row = ride_summary_json(t.summary);
    if (t.method == "pegasus") {
      row.erase("rides");
      policies.push_back(row);
      dir.write_json(fmt::format("policies/trial-{}.json", t.trial), bicycle_policy_json(t.theta));
    } else {
      row["method"] = t.method;
      row["trial"] = t.trial;
      row["pegasus_uhat"] = t.pegasus_uhat;
      lessons.push_back(row);
    }
  }
  dir.write_csv("rides.csv", rides);
  dir.write_csv("learning_curves.csv", curves);
  dir.write_csv("trials.csv", trials);
  const Chart curves_chart{
      .title = "Bicycle: U-hat against optimizer iterations",
      .x = {"iteration"},
      .y = {"U-hat (training scenarios)"},
      .traces = {
          {.file = "learning_curves.csv", .x = "iteration", .y = "uhat", .group_by = {"method", "trial"}}}};
  dir.add_charts({{.id = "learning-curves",
                   .title = "Learning curves",
                   .intro = "U-hat of each training on its own scenario set, by optimizer iteration.",
                   .charts = {curves_chart}},
                  {.id = "trials",
                   .title = "Trainings",
                   .intro = "One row per training (trials.csv).",
                   .charts = {{.kind = ChartKind::kTable, .traces = {{.file = "trials.csv"}}}}}});
  dir.write_chart_svg("learning_curves.svg", curves_chart);
  add_distance_chart(dir);
  const BicycleTrial& first = result.trials.front();
  BicycleRideOptions riding = o.riding;
  riding.seed = bicycle_ride_seed(o.seed, first.trial);
  write_rides_from_above(dir, rides_with_paths(first.theta, riding, ctx.pool()), riding.bicycle.goal,
                         "The rides of the trial-0 policy, seen from above", "rides_trial0.svg");
  dir.write_json("summary.json", {{"experiment", "bicycle"},
                                  {"policies", policies},
                                  {"median_of_medians_km", number_or_null(result.median_of_medians_km)},
                                  {"lessons", lessons},
                                  {"trials", o.trials},
                                  {"rides", o.riding.rides}});
  for (std::size_t k = 0; k < policies.size(); ++k)
    ctx.out << fmt::format("policy {}: median {} km, worst {} km, {} falls, {} of {} reached\n", k,
                           policies[k]["median_distance_km"].dump(), policies[k]["worst_distance_km"].dump(),
                           policies[k]["falls"].dump(), policies[k]["reached"].dump(), o.riding.rides);
  for (const auto& l : lessons)
    ctx.out << fmt::format("lesson {} {}: median {} km, worst {} km, {} falls, {} reached\n",
                           l["method"].get<std::string>(), l["trial"].dump(), l["median_distance_km"].dump(),
                           l["worst_distance_km"].dump(), l["falls"].dump(), l["reached"].dump());
  ctx.out << "median of medians: " << number_or_null(result.median_of_medians_km).dump() << " km\n";
}

// ---- pegasus bicycle train ----------------------------------------------------------------------------

void run_train(RunContext& ctx) {
  BicycleTrainingOptions o = training_options(ctx);
  std::string error;
  if (!o.IsValid(&error)) throw InputError(error);
  RunDirectory& dir = ctx.run_directory();
  BicycleTrainingHooks hooks;
  hooks.checkpoint_every = 5;
  hooks.on_checkpoint = [&](const nlohmann::json& c) { dir.save_checkpoint({{"optimizer", c}}); };
  if (auto state = dir.load_checkpoint()) hooks.resume_from = state->at("optimizer");
  auto bar = ctx.progress("training", 1);
  const BicycleTrainingResult trained = train_bicycle(o, hooks, &ctx.pool());
  bar.advance();
  bar.finish();
  const OptimizerSummary& s = trained.summary;

  CsvWriter curve({"iteration", "evaluations", "uhat"});
  for (const auto& h : s.history) curve.add_row({h.iteration, h.evaluations, h.value});
  dir.write_csv("learning_curve.csv", curve);
  const ChartSection progress =
      optimizer_progress_section({{"PEGASUS", "learning_curve.csv"}},
                                 "U-hat of the current policy on the training scenarios, by iteration and by "
                                 "evaluations.",
                                 "uhat", {"iteration", "evaluations"});
  dir.add_charts(progress);
  dir.write_chart_svg("learning_curve.svg", progress.charts.front());
  dir.write_json("policy.json", bicycle_policy_json(trained.theta));
  nlohmann::json summary = {
      {"experiment", "bicycle train"}, {"initial_uhat", s.initial_value},
      {"final_uhat", s.best_value},    {"iterations", s.iterations},
      {"evaluations", s.evaluations},  {"termination", std::string(TerminationTypeName(s.termination_type))},
      {"message", s.message}};
  ctx.out << s.BriefReport() << "\n";
  if (ctx.config.get_int("rides") > 0) {
    const BicycleRideOptions riding = ride_options(ctx);
    const auto rides = rides_with_paths(trained.theta, riding, ctx.pool());
    const BicycleRideSummary rs = summarize_rides(rides);
    summary["rides"] = ride_summary_json(rs);
    CsvWriter csv({"method", "trial", "ride", "distance_km", "reached", "fell"});
    add_ride_rows(csv, "pegasus", 0, rides);
    dir.write_csv("rides.csv", csv);
    add_distance_chart(dir);
    write_rides_from_above(dir, rides, riding.bicycle.goal, "Rides of the trained policy, seen from above",
                           "rides.svg");
    ctx.out << fmt::format("rides: median {} km, worst {} km, {} falls, {} of {} reached\n",
                           number_or_null(rs.median_distance_km).dump(),
                           number_or_null(rs.worst_distance_km).dump(), rs.falls, rs.reached, rs.rides);
  }
  dir.write_json("summary.json", summary);
}

// ---- pegasus bicycle ride -----------------------------------------------------------------------------

Theta policy_argument(const RunContext& ctx) {
  const std::string& file = ctx.config.get_string("policy");
  if (file.empty())
    throw InputError("--policy: expected a policy file (policy.json of pegasus bicycle train)");
  return read_bicycle_policy(file);
}

void run_ride(RunContext& ctx) {
  const Theta theta = policy_argument(ctx);
  const BicycleRideOptions riding = ride_options(ctx);
  std::string error;
  if (!riding.IsValid(&error)) throw InputError(error);
  const auto rides = rides_with_paths(theta, riding, ctx.pool());
  const BicycleRideSummary rs = summarize_rides(rides);
  RunDirectory& dir = ctx.run_directory();
  CsvWriter csv({"method", "trial", "ride", "distance_km", "reached", "fell"});
  add_ride_rows(csv, "policy", 0, rides);
  dir.write_csv("rides.csv", csv);
  add_distance_chart(dir);
  write_rides_from_above(dir, rides, riding.bicycle.goal, "Rides seen from above", "rides.svg");
  dir.write_json("summary.json", ride_summary_json(rs));
  ctx.out << fmt::format("median {} km, worst {} km, {} falls, {} of {} reached\n",
                         number_or_null(rs.median_distance_km).dump(),
                         number_or_null(rs.worst_distance_km).dump(), rs.falls, rs.reached, rs.rides);
}

// ---- pegasus bicycle variance -------------------------------------------------------------------------

void run_variance(RunContext& ctx) {
  const Theta theta = policy_argument(ctx);
  const int sets = static_cast<int>(ctx.config.get_int("sets"));
  BicycleTrainingOptions o = training_options(ctx);
  std::string error;
  if (!o.IsValid(&error)) throw InputError(error);
  CsvWriter csv({"variant", "set", "uhat"});
  nlohmann::json stds = nlohmann::json::object(), means = nlohmann::json::object();
  auto bar = ctx.progress("scenario sets", static_cast<std::uint64_t>(4 * sets));
  for (const char* name : {"plain", "antithetic", "stratified", "sobol"}) {
    o.variant = parse_scenario_variant(name);
    std::vector<double> values;
    for (int k = 0; k < sets; ++k) {
      o.seed = bicycle_training_seed(ctx.seed, k);
      values.push_back(bicycle_uhat(o, theta, &ctx.pool()));
      csv.add_row({std::string(name), std::int64_t{k}, values.back()});
      bar.advance();
    }
    double mean = 0.0;
    for (double v : values) mean += v;
    mean /= static_cast<double>(values.size());
    double ss = 0.0;
    for (double v : values) ss += (v - mean) * (v - mean);
    const double sd = values.size() > 1 ? std::sqrt(ss / static_cast<double>(values.size() - 1)) : 0.0;
    stds[name] = sd;
    means[name] = mean;
    ctx.out << fmt::format("{:<10} mean U-hat {:.6f}  std {:.6f}\n", name, mean, sd);
  }
  bar.finish();
  RunDirectory& dir = ctx.run_directory();
  dir.write_csv("uhat.csv", csv);
  dir.add_charts(ChartSection{
      .id = "variance",
      .title = "U-hat by scenario variant",
      .intro = "The spread of U-hat across scenario sets is the noise the optimizer sees (uhat.csv).",
      .charts = {{.kind = ChartKind::kBox,
                  .title = "U-hat of one policy over independent scenario sets",
                  .y = {"U-hat"},
                  .traces = {{.file = "uhat.csv", .y = "uhat", .group_by = {"variant"}}}}}});
  dir.write_json("summary.json",
                 {{"uhat_std", stds}, {"uhat_mean", means}, {"sets", sets}, {"scenarios", o.scenarios}});
}

}  // namespace

std::vector<Command> bicycle_commands() {
  return {
      Command{.path = "bicycle experiment",
              .description =
                  "Thesis 4.6: train PEGASUS policies (trials) and ride each to a goal 1 km away (rides)",
              .declare =
                  [](ConfigSchema& s) {
                    s.add_int("trials", 10, "independent trainings (scenario sets)").min(1).max(100000);
                    s.add_int(
                         "lesson_trials", 2,
                         "scenario sets on which the progress bonus and naive Monte Carlo are also trained")
                        .min(0)
                        .max(100000);
                    declare_training(s);
                    declare_riding(s, 50);
                  },
              .run = run_experiment},
      Command{.path = "bicycle train",
              .description = "Train one bicycle policy with PEGASUS and write policy.json",
              .declare =
                  [](ConfigSchema& s) {
                    declare_training(s);
                    declare_riding(s, 20);
                  },
              .run = run_train},
      Command{.path = "bicycle ride",
              .description = "Ride a bicycle policy file to the goal and report the distances",
              .declare =
                  [](ConfigSchema& s) {
                    s.add_string("policy", "", "policy file (JSON with parameter names and values)");
                    s.add_double("fall_reward", -100.0, "reward of falling over (absorbing)").max(0);
                    declare_riding(s, 50);
                  },
              .run = run_ride},
      Command{
          .path = "bicycle variance",
          .description = "Thesis 4.7: spread of U-hat over scenario sets, plain/antithetic/stratified/Sobol",
          .declare =
              [](ConfigSchema& s) {
                s.add_string("policy", "", "policy file (JSON with parameter names and values)");
                s.add_int("sets", 100, "independent scenario sets per method").min(2).max(1000000);
                declare_training(s);
              },
          .run = run_variance},
  };
}

}  // namespace pegasus::cli
