// `pegasus shaping audit --mdp M.json --shaping F.json`: is a tabular shaping reward potential-based
// (thesis §3.3, Theorem 1)? Exit 0 when it is, 1 when it is not (with a witness and a verified
// counterexample, Lemma 4 / Appendix 3.A), 2 on bad input.
#include "experiment_commands.hpp"
#include "pegasus/runs/shaping_audit_run.hpp"

namespace pegasus::cli {
namespace {

void declare(ConfigSchema& s) {
  s.add_string("mdp", "", "the MDP, a pegasus-mdp JSON file (format: include/pegasus/mdp/mdp_json.hpp)")
      .input_file();
  s.add_string("shaping", "",
               "the shaping reward F(s, a, s'), a pegasus-shaping JSON file (shaping_table.hpp)")
      .input_file();
  s.add_double("tolerance", ShapingAuditRunOptions{}.tolerance,
               "relative tolerance: residuals below tolerance * (1 + max |F|) count as zero")
      .greater_than(0)
      .less_than(1);
  s.add_int("print_limit", ShapingAuditRunOptions{}.print_limit,
            "print Phi for at most this many states (all of them go to potential.csv)")
      .min(0);
}

void run(RunContext& ctx) {
  const ShapingAuditRunOptions o{.mdp_file = ctx.config.get_string("mdp"),
                                 .shaping_file = ctx.config.get_string("shaping"),
                                 .tolerance = ctx.config.get_double("tolerance"),
                                 .print_limit = static_cast<int>(ctx.config.get_int("print_limit"))};
  const bool potential_based =
      run_shaping_audit(o, ctx.out, ctx.has_run_directory() ? &ctx.run_directory() : nullptr);
  ctx.exit_code = potential_based ? 0 : 1;
}

}  // namespace

Command shaping_audit_command() {
  return Command{.path = "shaping audit",
                 .description =
                     "Is a tabular shaping reward potential-based? Phi, or a witness and a verified "
                     "counterexample (exit 0 / 1)",
                 .declare = declare,
                 .run = run,
                 .out = OutDir::kOptional};
}

}  // namespace pegasus::cli
