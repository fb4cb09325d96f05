// `pegasus pomdp-gridworld`: the POMDP gridworld experiment of thesis §4.6 (Fig 4.5b).
#include "experiment_commands.hpp"
#include "pegasus/runs/pomdp_gridworld_run.hpp"

namespace pegasus::cli {
namespace {

void declare(ConfigSchema& s) {
  const PomdpGridworldOptions d;
  s.add_int_list("scenarios", std::vector<std::int64_t>(d.scenarios.begin(), d.scenarios.end()),
                 "the numbers of scenarios m to try")
      .min(1)
      .max(100000)
      .min_size(1);
  s.add_int("trials", d.trials, "independent scenario sets per m (the thesis averaged 10000)")
      .min(1)
      .max(1000000);
  s.add_int("montecarlo_max_m", d.montecarlo_max_m, "naive Monte Carlo runs only for m up to this (0: never)")
      .min(0)
      .max(100000);
  s.add_double("gamma", d.gamma, "discount factor").range(0.0, 1.0);
  s.add_int("horizon", d.horizon, "steps per rollout H").min(1).max(3000);
  s.add_bool("hashed", d.hashed, "also run PEGASUS on the hashed model g'(s,a,p) = g(s,a,h_sa(p))");
  s.add_bool("montecarlo", d.montecarlo, "also run naive Monte Carlo with fresh randomness per evaluation");
  s.add_string("variant", to_string(d.variant), "scenario variant").choices(scenario_variant_names());
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
  RunSink sink = ctx.sink();
  run_pomdp_gridworld_study(o, sink);
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
