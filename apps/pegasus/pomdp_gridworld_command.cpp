// `pegasus pomdp-gridworld`: the POMDP gridworld experiment of thesis §4.6 (Fig 4.5b): the library's config
// section and experiment (experiments/runs/pomdp_gridworld_run.hpp).
#include "pegasus/cli/command.hpp"
#include "pegasus/experiments/runs/pomdp_gridworld_run.hpp"

namespace pegasus::cli {

Command pomdp_gridworld_command() {
  return Command{
      .path = "pomdp-gridworld",
      .description = "POMDP gridworld of thesis 4.6: PEGASUS vs hashed model vs naive Monte Carlo (Fig 4.5b)",
      .declare = declare_pomdp_gridworld_config,
      .run = [](RunContext& ctx) {
        RunSink sink = ctx.sink();
        run_pomdp_gridworld_study(read_pomdp_gridworld_config(ctx.config, ctx.seed, ctx.threads), sink);
      }};
}

}  // namespace pegasus::cli
