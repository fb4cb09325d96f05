#include "pegasus/experiments/runs/bicycle_runs.hpp"

#include <fmt/format.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "pegasus/core/error.hpp"
#include "pegasus/io/json_csv.hpp"
#include "pegasus/runs/charts.hpp"

namespace pegasus {

namespace {

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

}  // namespace

void run_bicycle_study(const BicycleExperimentOptions& o, RunSink& sink, ThreadPool& pool) {
  std::string error;
  if (!o.IsValid(&error)) throw InputError(error);
  RunDirectory& dir = sink.dir;
  BicycleExperimentHooks hooks;
  hooks.resume_from = dir.load_checkpoint();
  const std::size_t jobs = static_cast<std::size_t>(o.trials + 2 * o.lesson_trials);
  auto bar = sink.progress("trainings", jobs);
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
  write_rides_from_above(dir, rides_with_paths(first.theta, riding, pool), riding.bicycle.goal,
                         "The rides of the trial-0 policy, seen from above", "rides_trial0.svg");
  dir.write_json("summary.json", {{"experiment", "bicycle"},
                                  {"policies", policies},
                                  {"median_of_medians_km", number_or_null(result.median_of_medians_km)},
                                  {"lessons", lessons},
                                  {"trials", o.trials},
                                  {"rides", o.riding.rides}});
  for (std::size_t k = 0; k < policies.size(); ++k)
    sink.out << fmt::format("policy {}: median {} km, worst {} km, {} falls, {} of {} reached\n", k,
                            policies[k]["median_distance_km"].dump(), policies[k]["worst_distance_km"].dump(),
                            policies[k]["falls"].dump(), policies[k]["reached"].dump(), o.riding.rides);
  for (const auto& l : lessons)
    sink.out << fmt::format("lesson {} {}: median {} km, worst {} km, {} falls, {} reached\n",
                            l["method"].get<std::string>(), l["trial"].dump(), l["median_distance_km"].dump(),
                            l["worst_distance_km"].dump(), l["falls"].dump(), l["reached"].dump());
  sink.out << "median of medians: " << number_or_null(result.median_of_medians_km).dump() << " km\n";
}

void run_bicycle_training(const BicycleTrainingOptions& o, const BicycleRideOptions* rides_after,
                          RunSink& sink, ThreadPool& pool) {
  std::string error;
  if (!o.IsValid(&error)) throw InputError(error);
  RunDirectory& dir = sink.dir;
  BicycleTrainingHooks hooks;
  hooks.checkpoint_every = 5;
  hooks.on_checkpoint = [&](const nlohmann::json& c) { dir.save_checkpoint({{"optimizer", c}}); };
  if (auto state = dir.load_checkpoint()) hooks.resume_from = state->at("optimizer");
  auto bar = sink.progress("training", 1);
  const BicycleTrainingResult trained = train_bicycle(o, hooks, &pool);
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
  sink.out << s.BriefReport() << "\n";
  if (rides_after != nullptr) {
    const BicycleRideOptions& riding = *rides_after;
    const auto rides = rides_with_paths(trained.theta, riding, pool);
    const BicycleRideSummary rs = summarize_rides(rides);
    summary["rides"] = ride_summary_json(rs);
    CsvWriter csv({"method", "trial", "ride", "distance_km", "reached", "fell"});
    add_ride_rows(csv, "pegasus", 0, rides);
    dir.write_csv("rides.csv", csv);
    add_distance_chart(dir);
    write_rides_from_above(dir, rides, riding.bicycle.goal, "Rides of the trained policy, seen from above",
                           "rides.svg");
    sink.out << fmt::format("rides: median {} km, worst {} km, {} falls, {} of {} reached\n",
                            number_or_null(rs.median_distance_km).dump(),
                            number_or_null(rs.worst_distance_km).dump(), rs.falls, rs.reached, rs.rides);
  }
  dir.write_json("summary.json", summary);
}

void run_bicycle_rides(const Theta& theta, const BicycleRideOptions& riding, RunSink& sink,
                       ThreadPool& pool) {
  std::string error;
  if (!riding.IsValid(&error)) throw InputError(error);
  const auto rides = rides_with_paths(theta, riding, pool);
  const BicycleRideSummary rs = summarize_rides(rides);
  RunDirectory& dir = sink.dir;
  CsvWriter csv({"method", "trial", "ride", "distance_km", "reached", "fell"});
  add_ride_rows(csv, "policy", 0, rides);
  dir.write_csv("rides.csv", csv);
  add_distance_chart(dir);
  write_rides_from_above(dir, rides, riding.bicycle.goal, "Rides seen from above", "rides.svg");
  dir.write_json("summary.json", ride_summary_json(rs));
  sink.out << fmt::format("median {} km, worst {} km, {} falls, {} of {} reached\n",
                          number_or_null(rs.median_distance_km).dump(),
                          number_or_null(rs.worst_distance_km).dump(), rs.falls, rs.reached, rs.rides);
}

void run_bicycle_variance(const Theta& theta, BicycleTrainingOptions o, int sets, std::uint64_t seed,
                          RunSink& sink, ThreadPool& pool) {
  std::string error;
  if (!o.IsValid(&error)) throw InputError(error);
  CsvWriter csv({"variant", "set", "uhat"});
  nlohmann::json stds = nlohmann::json::object(), means = nlohmann::json::object();
  auto bar = sink.progress("scenario sets", static_cast<std::uint64_t>(4 * sets));
  for (const ScenarioVariant variant : kScenarioVariants) {
    const std::string name = to_string(variant);
    o.variant = variant;
    std::vector<double> values;
    for (int k = 0; k < sets; ++k) {
      o.seed = bicycle_training_seed(seed, k);
      values.push_back(bicycle_uhat(o, theta, &pool));
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
    sink.out << fmt::format("{:<10} mean U-hat {:.6f}  std {:.6f}\n", name, mean, sd);
  }
  bar.finish();
  RunDirectory& dir = sink.dir;
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

}  // namespace pegasus
