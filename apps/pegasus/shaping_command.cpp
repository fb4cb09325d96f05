// `pegasus shaping audit` (is a tabular shaping reward potential-based? thesis §3.3, Theorem 1: exit 0 when
// it is, 1 when it is not, with a witness and a verified counterexample), `shaping gridworld`, `shaping
// flags` (§3.4, Figs 3.2 and 3.3) and `shaping progress-bonus` (the §3.1 bug, shown by learning): the
// library's config sections (experiments/runs/shaping_config.hpp) and experiments
// (experiments/runs/shaping_runs.hpp).
#include "pegasus/cli/command.hpp"
#include "pegasus/experiments/runs/shaping_config.hpp"
#include "pegasus/experiments/runs/shaping_runs.hpp"

namespace pegasus::cli {
namespace {

Command learning_command(const char* path, const char* description, ShapingWorld world) {
  return {.path = path,
          .description = description,
          .declare = [world](ConfigSchema& s) { declare_shaping_learning_config(s, world); },
          .run =
              [world](RunContext& ctx) {
                RunSink sink = ctx.sink();
                run_shaping_learning(read_shaping_learning_config(ctx.config, world, ctx.seed, ctx.threads),
                                     sink);
              }};
}

}  // namespace

std::vector<Command> shaping_commands() {
  return {
      Command{.path = "shaping audit",
              .description = "Is a tabular shaping reward potential-based? Phi, or a witness and a verified "
                             "counterexample (exit 0 / 1)",
              .declare = declare_shaping_audit_config,
              .run =
                  [](RunContext& ctx) {
                    const bool potential_based =
                        run_shaping_audit(read_shaping_audit_config(ctx.config), ctx.out,
                                          ctx.has_run_directory() ? &ctx.run_directory() : nullptr);
                    ctx.exit_code = potential_based ? 0 : 1;
                  },
              .out = OutDir::kOptional},
      learning_command("shaping gridworld",
                       "Sarsa on the 80/20 gridworld with and without potential-based shaping (thesis 3.4, "
                       "Fig 3.2)",
                       ShapingWorld::kGridworld),
      learning_command("shaping flags",
                       "Sarsa on the flag-collecting gridworld with subgoal potentials (thesis 3.4, Fig 3.3)",
                       ShapingWorld::kFlags),
      Command{.path = "shaping progress-bonus",
              .description =
                  "The progress-bonus bug: the learned greedy policy cycles; the potential version does not",
              .declare = declare_progress_bonus_config,
              .run =
                  [](RunContext& ctx) {
                    run_shaping_progress_bonus(read_progress_bonus_config(ctx.config, ctx.seed), ctx.out,
                                               ctx.has_run_directory() ? &ctx.run_directory() : nullptr);
                  },
              .out = OutDir::kOptional},
  };
}

}  // namespace pegasus::cli
