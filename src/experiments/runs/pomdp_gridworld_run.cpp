#include "pegasus/experiments/runs/pomdp_gridworld_run.hpp"

#include <string>
#include <tuple>
#include <vector>

#include "pegasus/core/error.hpp"
#include "pegasus/io/json_csv.hpp"
#include "pegasus/runs/charts.hpp"

namespace pegasus {

namespace {

// The curves of both plots, in legend order: (model, estimator, legend name).
const std::vector<std::tuple<std::string, std::string, std::string>> kSeries = {
    {"normal", "pegasus", "PEGASUS"},
    {"hashed", "pegasus", "PEGASUS, hashed model"},
    {"normal", "montecarlo", "naive Monte Carlo"}};

nlohmann::json summary_json(const PomdpGridworldResult& r, const PomdpGridworldOptions& o) {
  nlohmann::json rows = nlohmann::json::array();
  for (const auto& row : r.rows)
    rows.push_back({{"model", row.model},
                    {"estimator", row.estimator},
                    {"m", row.m},
                    {"trials", row.trials},
                    {"mean_true_value", row.mean_true_value},
                    {"stderr_true_value", row.stderr_true_value},
                    {"mean_estimate", row.mean_estimate},
                    {"mean_sup_deviation", row.mean_sup_deviation}});
  return {{"experiment", "pomdp-gridworld"},
          {"best_in_class_value", r.best_in_class_value},
          {"best_in_class_policy", r.best_in_class_policy},
          {"policies", 65536},
          {"gamma", o.gamma},
          {"horizon", o.horizon},
          {"trials", o.trials},
          {"results", rows}};
}

// Fig 4.5b and the uniform deviation against m, one curve per (model, estimator) (results.csv).
ChartSection value_section(const PomdpGridworldResult& r) {
  const ChartTrace curves{.file = "results.csv", .x = "m", .group_by = {"curve"}, .mode = "lines+markers"};
  Chart value{.title = "POMDP gridworld: value of the chosen policy (Fig 4.5b)",
              .x = {"scenarios m", AxisScale::kLog2},
              .y = {"exact value of argmax U-hat"},
              .traces = {curves},
              .references = {{.y = r.best_in_class_value, .name = "best in class", .dash = "solid"}}};
  value.traces[0].y = "mean_true_value";
  value.traces[0].error = "stderr_true_value";
  Chart deviation{.title = "Uniform convergence: mean of max over policies |U-hat - U|",
                  .x = {"scenarios m", AxisScale::kLog2},
                  .y = {"mean sup deviation"},
                  .traces = {curves}};
  deviation.traces[0].y = "mean_sup_deviation";
  return {.id = "value-vs-m",
          .title = "PEGASUS value against m (Fig 4.5b)",
          .intro =
              "Mean true value of the policy each estimator chose, with 1 s.e. bars, against the number of "
              "scenarios; the line is the best policy in the class (results.csv).",
          .charts = {value, deviation},
          .data = {"trials.csv"}};
}

std::string curve_name(const std::string& model, const std::string& estimator) {
  for (const auto& [m, e, name] : kSeries) {
    if (m == model && e == estimator) return name;
  }
  return model + " " + estimator;
}

}  // namespace

void run_pomdp_gridworld_study(const PomdpGridworldOptions& o, RunSink& sink) {
  std::string error;
  if (!o.IsValid(&error)) throw InputError(error);
  RunDirectory& dir = sink.dir;
  PomdpGridworldHooks hooks;
  hooks.resume_from = dir.load_checkpoint();
  auto bar = sink.progress("trials", static_cast<std::uint64_t>(o.trials));
  if (hooks.resume_from) bar.skip(hooks.resume_from->at("trials_done").get<std::uint64_t>());
  hooks.on_checkpoint = [&](const nlohmann::json& state) { dir.save_checkpoint(state); };
  hooks.on_trial = [&](int) { bar.advance(); };
  const PomdpGridworldResult result = run_pomdp_gridworld(o, hooks);
  bar.finish();

  CsvWriter trials(
      {"trial", "model", "estimator", "m", "chosen_policy", "true_value", "estimate", "sup_deviation"});
  for (const auto& r : result.records)
    trials.add_row({std::int64_t{r.trial}, r.model, r.estimator, std::int64_t{r.m},
                    std::int64_t{r.chosen_policy}, r.true_value, r.estimate, r.sup_deviation});
  dir.write_csv("trials.csv", trials);
  CsvWriter rows({"model", "estimator", "m", "trials", "mean_true_value", "stderr_true_value",
                  "mean_estimate", "mean_sup_deviation", "curve"});
  for (const auto& r : result.rows)
    rows.add_row({r.model, r.estimator, std::int64_t{r.m}, std::int64_t{r.trials}, r.mean_true_value,
                  r.stderr_true_value, r.mean_estimate, r.mean_sup_deviation,
                  curve_name(r.model, r.estimator)});
  dir.write_csv("results.csv", rows);
  const ChartSection charts = value_section(result);
  dir.add_charts(charts);
  dir.write_chart_svg("value_vs_m.svg", charts.charts[0]);
  dir.write_chart_svg("sup_deviation_vs_m.svg", charts.charts[1]);
  dir.write_json("summary.json", summary_json(result, o));

  sink.out << "best in class (exact): " << result.best_in_class_value << "\n";
  for (const auto& r : result.rows)
    sink.out << r.model << "/" << r.estimator << " m=" << r.m << ": value " << r.mean_true_value << " +- "
             << r.stderr_true_value << ", estimate " << r.mean_estimate << ", sup |U-hat - U| "
             << r.mean_sup_deviation << "\n";
}

void declare_pomdp_gridworld_config(ConfigSchema& s) {
  const PomdpGridworldOptions d;
  s.add_int_list("scenarios", std::vector<std::int64_t>(d.scenarios.begin(), d.scenarios.end()),
                 "the numbers of scenarios m to try")
      .min(1)
      .max(100000)
      .min_size(1);
  s.add_int("trials", d.trials, "independent scenario sets per m (the thesis averaged 10000)")
      .min(1)
      .max(1000000);
  s.add_int("montecarlo_max_m", d.montecarlo_max_m, "naive Monte Carlo runs only for m up to this (0: never)")
      .min(0)
      .max(100000);
  s.add_double("gamma", d.gamma, "discount factor").range(0.0, 1.0);
  s.add_int("horizon", d.horizon, "steps per rollout H").min(1).max(3000);
  s.add_bool("hashed", d.hashed, "also run PEGASUS on the hashed model g'(s,a,p) = g(s,a,h_sa(p))");
  s.add_bool("montecarlo", d.montecarlo, "also run naive Monte Carlo with fresh randomness per evaluation");
  s.add_string("variant", to_string(d.variant), "scenario variant").choices(scenario_variant_names());
}

PomdpGridworldOptions read_pomdp_gridworld_config(const ConfigSchema& c, std::uint64_t seed, int threads) {
  PomdpGridworldOptions o;
  o.scenarios.clear();
  for (auto m : c.get_int_list("scenarios")) o.scenarios.push_back(static_cast<int>(m));
  o.trials = static_cast<int>(c.get_int("trials"));
  o.montecarlo_max_m = static_cast<int>(c.get_int("montecarlo_max_m"));
  o.gamma = c.get_double("gamma");
  o.horizon = static_cast<int>(c.get_int("horizon"));
  o.hashed = c.get_bool("hashed");
  o.montecarlo = c.get_bool("montecarlo");
  o.variant = parse_scenario_variant(c.get_string("variant"));
  o.seed = seed;
  o.threads = threads;
  return o;
}

}  // namespace pegasus
