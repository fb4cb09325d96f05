// `pegasus pendulum train`: PEGASUS on Gymnasium's Pendulum-v1, the race against RLtools of issue 7: the
// library's config section and experiment (experiments/runs/pendulum_run.hpp).
#include "pegasus/cli/command.hpp"
#include "pegasus/experiments/runs/pendulum_run.hpp"

namespace pegasus::cli {

std::vector<Command> pendulum_commands() {
  return {
      Command{
          .path = "pendulum train",
          .description =
              "Gymnasium's Pendulum-v1: PEGASUS search of a swing-up policy, timed to a mean return of -200",
          .declare = declare_pendulum_training_config,
          .run =
              [](RunContext& ctx) {
                RunSink sink = ctx.sink();
                run_pendulum_training(read_pendulum_training_config(ctx.config, ctx.seed, ctx.threads), sink,
                                      ctx.pool());
              }},
  };
}

}  // namespace pegasus::cli
