// `pegasus pendulum train`: PEGASUS on Gymnasium's Pendulum-v1, the race against RLtools of issue 7.
#include "experiment_commands.hpp"
#include "pegasus/runs/optimizer_config.hpp"
#include "pegasus/runs/pendulum_run.hpp"

namespace pegasus::cli {
namespace {

void declare_training(ConfigSchema& s) {
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

PendulumTrainingOptions training_options(const RunContext& ctx) {
  const auto& c = ctx.config;
  PendulumTrainingOptions o;
  o.scenarios = static_cast<int>(c.get_int("scenarios"));
  o.variant = parse_scenario_variant(c.get_string("variant"));
  read_optimizer_options(c, "optimizer", &o.optimizer);
  o.refine_scenarios = static_cast<int>(c.get_int("refine_scenarios"));
  read_optimizer_options(c, "refine", &o.refine_optimizer);
  o.evaluation_episodes = static_cast<int>(c.get_int("evaluation_episodes"));
  o.bar = c.get_double("bar");
  o.seed = ctx.seed;
  o.threads = ctx.threads;
  return o;
}

void run_train(RunContext& ctx) {
  RunSink sink = ctx.sink();
  run_pendulum_training(training_options(ctx), sink, ctx.pool());
}

}  // namespace

std::vector<Command> pendulum_commands() {
  return {
      Command{
          .path = "pendulum train",
          .description =
              "Gymnasium's Pendulum-v1: PEGASUS search of a swing-up policy, timed to a mean return of -200",
          .declare = declare_training,
          .run = run_train},
  };
}

}  // namespace pegasus::cli
