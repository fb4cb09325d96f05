// `pegasus mujoco train` and `pegasus mujoco rollout`: PEGASUS policy search on any MJCF model (issue 18):
// the library's config sections (mujoco/runs/mujoco_config.hpp) and experiments
// (mujoco/runs/mujoco_runs.hpp). Built only with PEGASUS_MUJOCO (libmujoco-dev); without it the table has no
// mujoco commands.
#ifdef PEGASUS_HAVE_MUJOCO
#include "pegasus/cli/command.hpp"
#include "pegasus/mujoco/runs/mujoco_config.hpp"

namespace pegasus::cli {

std::vector<Command> mujoco_commands() {
  return {
      Command{.path = "mujoco train",
              .description = "PEGASUS policy search on an MJCF model and a task file (ARS by default)",
              .declare = declare_mujoco_train_config,
              .run =
                  [](RunContext& ctx) {
                    RunSink sink = ctx.sink();
                    ctx.exit_code =
                        run_mujoco_training(read_mujoco_train_config(ctx.config, ctx.seed), sink, ctx.pool());
                  }},
      Command{.path = "mujoco rollout",
              .description = "Roll out a trained MuJoCo policy: returns and a per-step CSV of positions "
                             "(--seed S with the training's seed S replays its held-out episodes)",
              .declare = declare_mujoco_rollout_config,
              .run =
                  [](RunContext& ctx) {
                    RunSink sink = ctx.sink();
                    run_mujoco_rollout(read_mujoco_rollout_config(ctx.config, ctx.seed), sink, ctx.pool());
                  }},
  };
}

}  // namespace pegasus::cli
#else
#include "pegasus/cli/command.hpp"

namespace pegasus::cli {
std::vector<Command> mujoco_commands() { return {}; }
}  // namespace pegasus::cli
#endif
