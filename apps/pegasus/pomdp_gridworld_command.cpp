// `pegasus pomdp-gridworld`: the POMDP gridworld experiment of thesis §4.6 (Fig 4.5b).
#include <tuple>
#include <vector>

#include "experiment_commands.hpp"
#include "pegasus/core/error.hpp"
#include "pegasus/experiments/pomdp_gridworld_experiment.hpp"
#include "pegasus/io/json_csv.hpp"
#include "pegasus/runs/svg_plot.hpp"

namespace pegasus::cli {
namespace {

void declare(ConfigSchema& s) {
  s.add_int_list("scenarios", {1, 2, 4, 8, 16, 32, 64}, "the numbers of scenarios m to try")
      .min(1)
      .max(100000)
      .min_size(1);
  s.add_int("trials", 200, "independent scenario sets per m (the thesis averaged 10000)").min(1).max(1000000);
  s.add_int("montecarlo_max_m", 16, "naive Monte Carlo runs only for m up to this (0: never)")
      .min(0)
      .max(100000);
  s.add_double("gamma", 0.99, "discount factor").range(0.0, 1.0);
  s.add_int("horizon", 100, "steps per rollout H").min(1).max(3000);
  s.add_bool("hashed", true, "also run PEGASUS on the hashed model g'(s,a,p) = g(s,a,h_sa(p))");
  s.add_bool("montecarlo", true, "also run naive Monte Carlo with fresh randomness per evaluation");
  s.add_string("variant", "plain", "scenario variant")
      .choices({"plain", "antithetic", "stratified", "sobol"});
}

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

// One curve per (model, estimator) of kSeries: `field` of each summary row against m, with `band` as the
// error band when given.
void add_curves(SvgPlot& plot, const PomdpGridworldResult& r, double PomdpGridworldSummaryRow::*field,
                double PomdpGridworldSummaryRow::*band) {
  for (const auto& [model, estimator, name] : kSeries) {
    PlotSeries s{.name = name};
    for (const auto& row : r.rows)
      if (row.model == model && row.estimator == estimator) {
        s.x.push_back(row.m);
        s.y.push_back(row.*field);
        if (band) s.error.push_back(row.*band);
      }
    if (!s.x.empty()) plot.add_series(std::move(s));
  }
}

std::string value_plot(const PomdpGridworldResult& r) {
  SvgPlot plot;
  plot.title("POMDP gridworld: value of the chosen policy (Fig 4.5b)")
      .x_label("scenarios m")
      .y_label("exact value of argmax U-hat")
      .x_scale(AxisScale::kLog2);
  add_curves(plot, r, &PomdpGridworldSummaryRow::mean_true_value,
             &PomdpGridworldSummaryRow::stderr_true_value);
  plot.add_reference_line(r.best_in_class_value, "best in class");
  return plot.render();
}

std::string deviation_plot(const PomdpGridworldResult& r) {
  SvgPlot plot;
  plot.title("Uniform convergence: mean of max over policies |U-hat - U|")
      .x_label("scenarios m")
      .y_label("mean sup deviation")
      .x_scale(AxisScale::kLog2);
  add_curves(plot, r, &PomdpGridworldSummaryRow::mean_sup_deviation, nullptr);
  return plot.render();
}

void run(RunContext& ctx) {
  const auto& c = ctx.config;
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
  o.seed = ctx.seed;
  o.threads = ctx.threads;
  std::string error;
  if (!o.IsValid(&error)) throw InputError(error);

  RunDirectory& dir = ctx.run_directory();
  PomdpGridworldHooks hooks;
  hooks.resume_from = dir.load_checkpoint();
  auto bar = ctx.progress("trials", static_cast<std::uint64_t>(o.trials));
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
                  "mean_estimate", "mean_sup_deviation"});
  for (const auto& r : result.rows)
    rows.add_row({r.model, r.estimator, std::int64_t{r.m}, std::int64_t{r.trials}, r.mean_true_value,
                  r.stderr_true_value, r.mean_estimate, r.mean_sup_deviation});
  dir.write_csv("results.csv", rows);
  dir.write_text("value_vs_m.svg", value_plot(result));
  dir.write_text("sup_deviation_vs_m.svg", deviation_plot(result));
  dir.write_json("summary.json", summary_json(result, o));

  ctx.out << "best in class (exact): " << result.best_in_class_value << "\n";
  for (const auto& r : result.rows)
    ctx.out << r.model << "/" << r.estimator << " m=" << r.m << ": value " << r.mean_true_value << " +- "
            << r.stderr_true_value << ", estimate " << r.mean_estimate << ", sup |U-hat - U| "
            << r.mean_sup_deviation << "\n";
}

}  // namespace

Command pomdp_gridworld_command() {
  return Command{
      .path = "pomdp-gridworld",
      .description = "POMDP gridworld of thesis 4.6: PEGASUS vs hashed model vs naive Monte Carlo (Fig 4.5b)",
      .declare = declare,
      .run = run};
}

}  // namespace pegasus::cli
