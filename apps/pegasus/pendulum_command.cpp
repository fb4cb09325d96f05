// `pegasus pendulum train`: PEGASUS on Gymnasium's Pendulum-v1, the race against RLtools of issue 7.
#include <fmt/format.h>

#include <cmath>

#include "experiment_commands.hpp"
#include "pegasus/core/error.hpp"
#include "pegasus/experiments/pendulum_experiment.hpp"
#include "pegasus/runs/output.hpp"
#include "pegasus/runs/svg_plot.hpp"

namespace pegasus::cli {
namespace {

nlohmann::json number_or_null(double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); }

void declare_training(ConfigSchema& s) {
  s.add_int("scenarios", 32, "PEGASUS scenarios m (training start states)").min(1).max(1000000);
  s.add_string("variant", "plain", "scenario variant").choices({"plain", "antithetic", "stratified", "sobol"});
  s.add_int("iterations", 150, "hill-climbing iterations at most").min(0).max(1000000);
  s.add_int("proposals", 8, "hill-climbing proposals per iteration (evaluated in parallel)").min(1).max(100000);
  s.add_double("initial_step", 1.0, "first perturbation size (scaled units)").greater_than(0).max(4);
  s.add_int("evaluation_episodes", 100, "fresh starts for the bar and the final mean return").min(1).max(1000000);
  s.add_double("bar", -200.0, "mean return over the evaluation episodes that counts as solved").max(0);
}

PendulumTrainingOptions training_options(const RunContext& ctx) {
  const auto& c = ctx.config;
  PendulumTrainingOptions o;
  o.scenarios = static_cast<int>(c.get_int("scenarios"));
  o.variant = parse_scenario_variant(c.get_string("variant"));
  o.optimizer.hill_climbing.max_iterations = c.get_int("iterations");
  o.optimizer.hill_climbing.proposals_per_iteration = static_cast<int>(c.get_int("proposals"));
  o.optimizer.hill_climbing.initial_step = c.get_double("initial_step");
  o.evaluation_episodes = static_cast<int>(c.get_int("evaluation_episodes"));
  o.bar = c.get_double("bar");
  o.seed = ctx.seed;
  o.threads = ctx.threads;
  return o;
}

void run_train(RunContext& ctx) {
  const PendulumTrainingOptions o = training_options(ctx);
  std::string error;
  if (!o.IsValid(&error)) throw InputError(error);
  RunDirectory& dir = ctx.run_directory();
  PendulumTrainingHooks hooks;
  hooks.checkpoint_every = 10;
  hooks.on_checkpoint = [&](const nlohmann::json& state) { dir.save_checkpoint(state); };
  hooks.resume_from = dir.load_checkpoint();
  auto bar = ctx.progress("training", 1);
  const PendulumTrainingResult r = train_pendulum(o, hooks, &ctx.pool());
  bar.advance();
  bar.finish();
  const OptimizerSummary& s = r.summary;

  CsvWriter curve({"iteration", "evaluations", "seconds", "uhat"});
  PlotSeries uhat{.name = "U-hat (training scenarios)"};
  for (const auto& h : s.history) {
    curve.add_row({h.iteration, h.evaluations, h.seconds, h.value});
    uhat.x.push_back(static_cast<double>(h.evaluations));
    uhat.y.push_back(h.value);
  }
  CsvWriter checks({"seconds", "evaluations", "uhat", "mean_return"});
  PlotSeries fresh{.name = fmt::format("mean return, {} fresh starts", o.evaluation_episodes)};
  for (const auto& c : r.checks) {
    checks.add_row({c.seconds, c.evaluations, c.uhat, c.mean_return});
    fresh.x.push_back(static_cast<double>(c.evaluations));
    fresh.y.push_back(c.mean_return);
  }
  CsvWriter episodes({"episode", "return"});
  const auto returns = pendulum_episode_returns(r.theta, o.evaluation_episodes, pendulum_evaluation_seed(o.seed), &ctx.pool());
  for (std::size_t i = 0; i < returns.size(); ++i) episodes.add_row({static_cast<std::int64_t>(i), returns[i]});
  SvgPlot plot;
  plot.title("Pendulum-v1: PEGASUS swing-up search").x_label("U-hat evaluations").y_label("return (200 steps)");
  plot.add_series(std::move(uhat));
  plot.add_series(std::move(fresh));
  plot.add_series({.name = "bar", .x = {1.0, static_cast<double>(std::max<std::int64_t>(2, s.evaluations))},
                   .y = {o.bar, o.bar}, .line = true, .markers = false});
  dir.write_csv("learning_curve.csv", curve);
  dir.write_csv("bar_checks.csv", checks);
  dir.write_csv("episode_returns.csv", episodes);
  dir.write_text("learning_curve.svg", plot.render());
  dir.write_json("policy.json", pendulum_policy_json(r.theta));
  dir.write_json("summary.json", {{"experiment", "pendulum train"},
                                  {"mean_return_100", r.mean_return_100},
                                  {"evaluation_episodes", o.evaluation_episodes},
                                  {"bar", o.bar},
                                  {"seconds_to_bar", number_or_null(r.seconds_to_bar)},
                                  {"cpu_seconds_to_bar", number_or_null(r.cpu_seconds_to_bar)},
                                  {"evaluations_to_bar", r.evaluations_to_bar},
                                  {"training_seconds", s.wall_seconds},
                                  {"initial_uhat", number_or_null(s.initial_value)},
                                  {"final_uhat", s.best_value},
                                  {"iterations", s.iterations},
                                  {"evaluations", s.evaluations},
                                  {"scenarios", o.scenarios},
                                  {"termination", std::string(TerminationTypeName(s.termination_type))},
                                  {"message", s.message}});
  ctx.out << s.BriefReport() << "\n";
  ctx.out << fmt::format("mean return over {} fresh starts: {:.2f}; bar {} reached after {} s ({} evaluations)\n",
                         o.evaluation_episodes, r.mean_return_100, o.bar, number_or_null(r.seconds_to_bar).dump(),
                         r.evaluations_to_bar);
}

}  // namespace

std::vector<Command> pendulum_commands() {
  return {
      Command{.path = "pendulum train",
              .description = "Gymnasium's Pendulum-v1: PEGASUS search of a swing-up policy, timed to a mean return of -200",
              .declare = declare_training,
              .run = run_train},
  };
}

}  // namespace pegasus::cli
