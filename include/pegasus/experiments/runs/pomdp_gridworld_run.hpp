#pragma once
// `pomdp-gridworld` as a library function: the POMDP gridworld experiment of thesis §4.6 (Fig 4.5b;
// experiments/pomdp_gridworld_experiment.hpp) written to a run directory: trials.csv, results.csv, the value
// and uniform-deviation charts, summary.json; checkpointed after every trial and resumed from it.
#include "pegasus/experiments/pomdp_gridworld_experiment.hpp"
#include "pegasus/runs/config.hpp"
#include "pegasus/runs/run_sink.hpp"

namespace pegasus {

void run_pomdp_gridworld_study(const PomdpGridworldOptions& options, RunSink& sink);

// Its config section (the `pomdp-gridworld` command's fields).
void declare_pomdp_gridworld_config(ConfigSchema& s);
PomdpGridworldOptions read_pomdp_gridworld_config(const ConfigSchema& c, std::uint64_t seed, int threads);

}  // namespace pegasus
