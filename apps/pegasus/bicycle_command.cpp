// `pegasus bicycle ...`: Randlov and Alstrom's bicycle ridden to a goal 1 km away by PEGASUS (thesis §4.6):
// the library's config sections (experiments/runs/bicycle_config.hpp) and experiments
// (experiments/runs/bicycle_runs.hpp).
#include <optional>

#include "pegasus/cli/command.hpp"
#include "pegasus/experiments/runs/bicycle_config.hpp"
#include "pegasus/experiments/runs/bicycle_runs.hpp"

namespace pegasus::cli {
namespace {

void run_experiment(RunContext& ctx) {
  RunSink sink = ctx.sink();
  run_bicycle_study(read_bicycle_experiment_config(ctx.config, ctx.seed, ctx.threads), sink, ctx.pool());
}

void run_train(RunContext& ctx) {
  const BicycleTrainingOptions o = read_bicycle_training_config(ctx.config, ctx.seed, ctx.threads);
  const std::optional<BicycleRideOptions> riding =
      ctx.config.get_int("rides") > 0 ? std::optional(read_bicycle_ride_config(ctx.config, ctx.seed))
                                      : std::nullopt;
  RunSink sink = ctx.sink();
  run_bicycle_training(o, riding ? &*riding : nullptr, sink, ctx.pool());
}

void run_ride(RunContext& ctx) {
  const Theta theta = read_bicycle_policy_config(ctx.config);
  RunSink sink = ctx.sink();
  run_bicycle_rides(theta, read_bicycle_ride_config(ctx.config, ctx.seed), sink, ctx.pool());
}

void run_variance(RunContext& ctx) {
  const Theta theta = read_bicycle_policy_config(ctx.config);
  RunSink sink = ctx.sink();
  run_bicycle_variance(theta, read_bicycle_objective_config(ctx.config, ctx.seed, ctx.threads),
                       static_cast<int>(ctx.config.get_int("sets")), ctx.seed, sink, ctx.pool());
}

}  // namespace

std::vector<Command> bicycle_commands() {
  return {
      Command{.path = "bicycle experiment",
              .description =
                  "Thesis 4.6: train PEGASUS policies (trials) and ride each to a goal 1 km away (rides)",
              .declare = declare_bicycle_experiment_config,
              .run = run_experiment},
      Command{.path = "bicycle train",
              .description = "Train one bicycle policy with PEGASUS and write policy.json",
              .declare = declare_bicycle_train_config,
              .run = run_train},
      Command{.path = "bicycle ride",
              .description = "Ride a bicycle policy file to the goal and report the distances",
              .declare = declare_bicycle_ride_config,
              .run = run_ride},
      Command{
          .path = "bicycle variance",
          .description = "Thesis 4.7: spread of U-hat over scenario sets, plain/antithetic/stratified/Sobol",
          .declare = declare_bicycle_variance_config,
          .run = run_variance},
  };
}

}  // namespace pegasus::cli
