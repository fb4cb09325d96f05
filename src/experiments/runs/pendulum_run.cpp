#include "pegasus/experiments/runs/pendulum_run.hpp"

#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <string>

#include "pegasus/core/error.hpp"
#include "pegasus/evaluators/pegasus_evaluator.hpp"
#include "pegasus/io/json_csv.hpp"
#include "pegasus/runs/charts.hpp"
#include "pegasus/runs/optimizer_config.hpp"

namespace pegasus {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// learning_curve.csv (one curve over both stages: the refinement's iterations and evaluations continue the
// race's count), bar_checks.csv and episode_returns.csv.
void write_pendulum_csvs(RunDirectory& dir, const PendulumTrainingOptions& o, const PendulumTrainingResult& r,
                         ThreadPool& pool) {
  const OptimizerSummary& s = r.summary;
  CsvWriter curve({"stage", "iteration", "evaluations", "seconds", "uhat"});
  for (const auto& h : s.history) {
    curve.add_row({std::string("race"), h.iteration, h.evaluations, h.seconds, h.value});
  }
  for (const auto& h : r.refine_summary.history) {
    curve.add_row({std::string("refine"), s.iterations + h.iteration, s.evaluations + h.evaluations,
                   s.wall_seconds + h.seconds, h.value});
  }
  CsvWriter checks({"seconds", "evaluations", "uhat", "mean_return"});
  for (const auto& c : r.checks) checks.add_row({c.seconds, c.evaluations, c.uhat, c.mean_return});
  CsvWriter episodes({"episode", "return"});
  const auto returns =
      pendulum_episode_returns(r.theta, o.evaluation_episodes, pendulum_evaluation_seed(o.seed), &pool);
  for (std::size_t i = 0; i < returns.size(); ++i)
    episodes.add_row({static_cast<std::int64_t>(i), returns[i]});
  dir.write_csv("learning_curve.csv", curve);
  dir.write_csv("bar_checks.csv", checks);
  dir.write_csv("episode_returns.csv", episodes);
}

void add_pendulum_chart(RunDirectory& dir, const PendulumTrainingOptions& o) {
  const Chart search{.title = "Pendulum-v1: PEGASUS swing-up search",
                     .x = {"U-hat evaluations"},
                     .y = {"return (200 steps)"},
                     .traces = {{.file = "learning_curve.csv",
                                 .x = "evaluations",
                                 .y = "uhat",
                                 .group_by = {"stage"},
                                 .name = fmt::format("U-hat ({} race, {} refinement scenarios)", o.scenarios,
                                                     o.refine_scenarios)},
                                {.file = "bar_checks.csv",
                                 .x = "evaluations",
                                 .y = "mean_return",
                                 .name = fmt::format("mean return, {} fresh starts", o.evaluation_episodes),
                                 .mode = "lines+markers"}},
                     .references = {{.y = o.bar, .name = "bar"}}};
  dir.add_charts(ChartSection{.id = "progress",
                              .title = "Optimizer progress",
                              .intro =
                                  "U-hat of the best policy so far on the training scenarios (race, then "
                                  "refinement) and the mean return on fresh starts at the bar checks.",
                              .charts = {search}});
  dir.write_chart_svg("learning_curve.svg", search);
}

nlohmann::json pendulum_summary(const PendulumTrainingOptions& o, const PendulumTrainingResult& r,
                                double mean_return_5000) {
  const OptimizerSummary& s = r.summary;
  const OptimizerSummary& refined = r.refine_summary;
  const bool refine = !refined.method.empty();
  return {{"experiment", "pendulum train"},
          {"mean_return_100", r.mean_return_100},
          {"race_mean_return_100", r.race_mean_return_100},
          {"mean_return_5000", mean_return_5000},
          {"evaluation_episodes", o.evaluation_episodes},
          {"bar", o.bar},
          {"evaluations_to_bar", r.evaluations_to_bar},
          {"initial_uhat", number_or_null(s.initial_value)},
          {"final_uhat", s.best_value},
          {"iterations", s.iterations},
          {"evaluations", s.evaluations},
          {"scenarios", o.scenarios},
          {"termination", std::string(TerminationTypeName(s.termination_type))},
          {"message", s.message},
          {"refine_scenarios", refine ? o.refine_scenarios : 0},
          {"refine_initial_uhat", number_or_null(refine ? refined.initial_value : kNaN)},
          {"refine_final_uhat", number_or_null(refine ? refined.best_value : kNaN)},
          {"refine_iterations", refined.iterations},
          {"refine_evaluations", refined.evaluations}};
}

}  // namespace

void run_pendulum_training(const PendulumTrainingOptions& o, RunSink& sink, ThreadPool& pool) {
  std::string error;
  if (!o.IsValid(&error)) throw InputError(error);
  RunDirectory& dir = sink.dir;
  PendulumTrainingHooks hooks;
  hooks.checkpoint_every = 10;
  hooks.on_checkpoint = [&](const nlohmann::json& state) { dir.save_checkpoint(state); };
  hooks.resume_from = dir.load_checkpoint();
  auto bar = sink.progress("training", 1);
  const PendulumTrainingResult r = train_pendulum(o, hooks, &pool);
  bar.advance();
  bar.finish();
  const OptimizerSummary& s = r.summary;
  const OptimizerSummary& refined = r.refine_summary;

  write_pendulum_csvs(dir, o, r, pool);
  add_pendulum_chart(dir, o);
  dir.write_json("policy.json", pendulum_policy_json(r.theta));
  // The final policy on many other starts: a 100-start mean carries about +-8 of sampling noise.
  const double mean_return_5000 =
      ordered_mean(pendulum_episode_returns(r.theta, 5000, pendulum_large_evaluation_seed(o.seed), &pool));
  dir.write_json("summary.json", pendulum_summary(o, r, mean_return_5000));
  sink.timings = {{"seconds_to_bar", number_or_null(r.seconds_to_bar)},
                  {"cpu_seconds_to_bar", number_or_null(r.cpu_seconds_to_bar)},
                  {"training_seconds", s.wall_seconds + refined.wall_seconds},
                  {"refine_seconds", refined.wall_seconds}};
  sink.out << "race: " << s.BriefReport() << "\n";
  if (!refined.method.empty()) sink.out << "refinement: " << refined.BriefReport() << "\n";
  sink.out << fmt::format(
      "mean return over {} fresh starts: {:.2f} (race {:.2f}), over 5000 others {:.2f}; bar {} "
      "reached after {} s ({} evaluations)\n",
      o.evaluation_episodes, r.mean_return_100, r.race_mean_return_100, mean_return_5000, o.bar,
      number_or_null(r.seconds_to_bar).dump(), r.evaluations_to_bar);
}

void declare_pendulum_training_config(ConfigSchema& s) {
  const PendulumTrainingOptions d;
  s.add_int("scenarios", d.scenarios, "PEGASUS scenarios m (training start states)").min(1).max(1000000);
  s.add_string("variant", to_string(d.variant), "scenario variant (both stages)")
      .choices(scenario_variant_names());
  // The race (thesis 4.6's hill climbing on the five numbers), then the refinement of all seven on more
  // scenarios; each stage takes every method for a continuous class (not exhaustive search).
  const std::vector<std::string> continuous = continuous_class_methods(true);
  declare_optimizer_options(s, "optimizer", d.optimizer, continuous);
  s.add_int("refine_scenarios", d.refine_scenarios,
            "scenarios of the refinement of all seven numbers (0: no refinement)")
      .min(0)
      .max(1000000);
  declare_optimizer_options(s, "refine", d.refine_optimizer, continuous);
  s.add_int("evaluation_episodes", d.evaluation_episodes,
            "fresh starts for the bar and the final mean return")
      .min(1)
      .max(1000000);
  s.add_double("bar", d.bar, "mean return over the evaluation episodes that counts as solved").max(0);
}

PendulumTrainingOptions read_pendulum_training_config(const ConfigSchema& c, std::uint64_t seed,
                                                      int threads) {
  PendulumTrainingOptions o;
  o.scenarios = static_cast<int>(c.get_int("scenarios"));
  o.variant = parse_scenario_variant(c.get_string("variant"));
  read_optimizer_options(c, "optimizer", &o.optimizer);
  o.refine_scenarios = static_cast<int>(c.get_int("refine_scenarios"));
  read_optimizer_options(c, "refine", &o.refine_optimizer);
  o.evaluation_episodes = static_cast<int>(c.get_int("evaluation_episodes"));
  o.bar = c.get_double("bar");
  o.seed = seed;
  o.threads = threads;
  return o;
}

}  // namespace pegasus
